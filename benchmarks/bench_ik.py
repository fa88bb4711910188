"""IK throughput: the vectorised closed form on 10⁶ poses vs a plain per-pose Python loop of the same
formula, as a ratio measured in one run. Usage: python benchmarks/bench_ik.py [--n 1000000]"""

import argparse
import math
import time

import numpy as np

from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.sampling import random_poses


def loop_ik(platform, poses):
    """The same formula, one pose and one leg at a time in pure Python (the baseline)."""
    base = platform.base_anchors.tolist()
    top = (platform.top_anchors_per_leg - platform.rotation_centre).tolist()
    out = []
    for px, py, pz, a, b, g in poses.tolist():
        ca, sa, cb, sb, cg, sg = math.cos(a), math.sin(a), math.cos(b), math.sin(b), math.cos(g), math.sin(g)
        R = (
            (cb * cg + sa * sb * sg, -cb * sg + sa * sb * cg, ca * sb),
            (ca * sg, ca * cg, -sa),
            (-sb * cg + sa * cb * sg, sb * sg + sa * cb * cg, ca * cb),
        )
        row = []
        for (bx, by, bz), (tx, ty, tz) in zip(base, top):
            x = px + R[0][0] * tx + R[0][1] * ty + R[0][2] * tz - bx
            y = py + R[1][0] * tx + R[1][1] * ty + R[1][2] * tz - by
            z = pz + R[2][0] * tx + R[2][1] * ty + R[2][2] * tz - bz
            row.append(math.sqrt(x * x + y * y + z * z))
        out.append(row)
    return np.array(out)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--loop-n", type=int, default=50_000, help="poses for the (slow) loop baseline")
    args = ap.parse_args(argv)
    p = load_preset("utn-kinematic")
    poses = random_poses(p, args.n, seed=0, within_stroke=False)
    t0 = time.perf_counter()
    L = leg_lengths(p, poses)
    t_vec = time.perf_counter() - t0
    m = min(args.loop_n, args.n)
    t0 = time.perf_counter()
    L_loop = loop_ik(p, poses[:m])
    t_loop = time.perf_counter() - t0
    k = min(m, 20_000)
    t0 = time.perf_counter()
    L_each = np.array([leg_lengths(p, q) for q in poses[:k]])
    t_each = time.perf_counter() - t0
    assert np.allclose(L[:m], L_loop, rtol=1e-13, atol=0) and np.array_equal(L[:k], L_each)
    vec_rate, loop_rate, each_rate = args.n / t_vec, m / t_loop, k / t_each
    print(f"vectorised leg_lengths: {args.n} poses, {vec_rate:.3g} poses/s")
    print(f"per-pose loop calling leg_lengths: {k} poses, {each_rate:.3g} poses/s -> ratio {vec_rate / each_rate:.0f}x")
    print(
        f"per-pose pure-Python scalar formula: {m} poses, {loop_rate:.3g} poses/s -> ratio {vec_rate / loop_rate:.0f}x"
    )


if __name__ == "__main__":
    main()
