"""Fixed-point IK throughput: the vectorised bit-exact port of tp17.C vs the scalar (pure-Python)
emulation, measured in one run and printed as evaluations/s and ratios.

    .venv/bin/python benchmarks/bench_fixedpoint.py [--n 1000000]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.fixedpoint import fixed_point_leg_lengths, scalar, tp17_leg_lengths
from stewart_drake.fixedpoint.q15 import L_mult, mfr32Sqrt


def best_rate(fn, n, repeats=3):
    """Evaluations per second: the best of ``repeats`` timed runs of ``fn`` doing ``n`` evaluations."""
    best = np.inf
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t)
    return n / best


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=1_000_000, help="poses for the vectorised runs")
    ap.add_argument("--n-scalar", type=int, default=5_000, help="poses for the scalar emulation")
    args = ap.parse_args(argv)
    rng = np.random.default_rng(0)
    n = args.n
    q = np.c_[rng.integers(-100, 101, (n, 2)), rng.integers(50, 300, n), rng.uniform(-0.25, 0.25, (n, 3))]
    qs = q[: args.n_scalar].tolist()
    consts = scalar.tp17_constants()

    tp17_leg_lengths(q[:10])  # build the sin/cos tables outside the timing
    vec = best_rate(lambda: tp17_leg_lengths(q), n)
    sca = best_rate(lambda: [scalar.tp17_loop(*p, consts=consts) for p in qs], len(qs), repeats=1)
    assert np.array_equal(tp17_leg_lengths(q[: len(qs)]), [scalar.tp17_loop(*p, consts=consts) for p in qs])

    p = load_preset("utn-kinematic")
    qsi = q.copy()
    qsi[:, :3] *= 1e-3
    qsi[:, 3:] *= np.pi
    gen = best_rate(lambda: fixed_point_leg_lengths(p, qsi), n)
    flt = best_rate(lambda: leg_lengths(p, qsi), n)
    a = rng.integers(-32768, 32768, n)
    lm = best_rate(lambda: L_mult(a, a), n)
    sq = best_rate(lambda: mfr32Sqrt(np.abs(L_mult(a, a))), n)

    print(f"tp17 (bit-exact DSP IK), vectorised : {vec:12.4g} evaluations/s  ({n} poses)")
    print(f"tp17, scalar pure-Python emulation  : {sca:12.4g} evaluations/s  ({len(qs)} poses)")
    print(f"  ratio vectorised / scalar         : {vec / sca:12.1f} x   (same bits, checked)")
    print(f"generic fixed-point IK (16-bit, mm) : {gen:12.4g} evaluations/s")
    print(f"float IK (kinematics.leg_lengths)   : {flt:12.4g} evaluations/s")
    print(f"  ratio float / tp17 vectorised     : {flt / vec:12.1f} x")
    print(f"intrinsic L_mult                    : {lm:12.4g} elements/s")
    print(f"intrinsic mfr32Sqrt (after L_mult)  : {sq:12.4g} elements/s")
    print(f"aim >= 1e6 evaluations/s vectorised : {'met' if vec >= 1e6 else 'NOT met'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
