"""Servo hexapod throughput: vectorised arm angles + pulse widths (``servo.solve``) on 10⁶ poses vs a
per-pose loop calling the same function, as ratios measured in one run.
Usage: python benchmarks/bench_servo.py [--n 1000000] [--loop-n 20000]"""

import argparse
import time

import numpy as np

from stewart_drake.mechanisms.servo import load_servo_hexapod, solve


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--loop-n", type=int, default=20_000, help="poses for the (slow) per-pose baseline")
    args = ap.parse_args(argv)
    h = load_servo_hexapod("hobby-servo")
    rng = np.random.default_rng(0)
    poses = h.home_pose() + np.c_[rng.uniform(-0.01, 0.01, (args.n, 3)), rng.uniform(-0.15, 0.15, (args.n, 3))]
    t0 = time.perf_counter()
    sol = solve(h, poses)
    t_vec = time.perf_counter() - t0
    k = min(args.loop_n, args.n)
    t0 = time.perf_counter()
    each = [solve(h, q) for q in poses[:k]]
    t_each = time.perf_counter() - t0
    assert np.array_equal(np.array([s.pulse for s in each]), sol.pulse[:k])
    vec_rate, each_rate = args.n / t_vec, k / t_each
    print(
        f"vectorised solve (arm angles + pulses + checks): {args.n} poses, {vec_rate:.3g} poses/s "
        f"({sol.ok.mean() * 100:.0f}% reachable within travel)"
    )
    print(f"per-pose loop calling solve: {k} poses, {each_rate:.3g} poses/s -> ratio {vec_rate / each_rate:.0f}x")


if __name__ == "__main__":
    main()
