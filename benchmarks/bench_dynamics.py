"""Leg-force samples per second: the vectorised numpy model against per-sample Drake inverse dynamics.

Run by hand: ``.venv/bin/python benchmarks/bench_dynamics.py [--samples N]``. Prints rates measured in
one run and their ratios (machine-independent-ish), plus the worst force difference as a sanity check.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import stewart_drake.core.dynamics as D
import stewart_drake.drake.verify_dynamics as V
from stewart_drake.core.geometry import load_preset


def rate(fn, n, repeat=3):
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return n / best, out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=20000, help="samples for the numpy model (default 20000)")
    ap.add_argument(
        "--drake-samples", type=int, default=500, help="samples for the per-sample Drake loop (default 500)"
    )
    args = ap.parse_args(argv)
    p = load_preset("utn-dynamic")
    amp = np.array([0.02, 0.03, 0.015, 0.3, 0.3, 0.3])
    traj = lambda n: D.harmonic_trajectory(
        np.linspace(0, 10, n), [-0.02, 0.01, 0.7, 0, 0, 0], amp, [1.3, 2.1, 1.7, 3.0, 2.5, 3.5]
    )  # noqa: E731
    q, qd, qdd = traj(args.samples)
    qs, qds, qdds = traj(args.drake_samples)
    r_np, _ = rate(lambda: D.leg_forces(p, q, qd, qdd), args.samples)
    r_np_legs, _ = rate(lambda: D.leg_forces_with_legs(p, q, qd, qdd), args.samples)
    r_np_one, _ = rate(lambda: [D.leg_forces(p, qs[k], qds[k], qdds[k]) for k in range(len(qs))], len(qs), 1)
    ID = V.DrakeInverseDynamics(p)
    r_dk, F_dk = rate(lambda: np.array([ID(qs[k], qds[k], qdds[k]) for k in range(len(qs))]), len(qs))
    CL = V.ClosedLoopInverseDynamics(p)
    n_cl = min(len(qs), 200)
    r_cl, _ = rate(lambda: [CL(qs[k], qds[k], qdds[k]) for k in range(n_cl)], n_cl, 1)
    err = np.abs(D.leg_forces(p, qs, qds, qdds) - F_dk).max()
    print(f"platform {p.name}; samples: numpy {args.samples}, Drake {args.drake_samples}")
    print(f"{'method':58s} {'samples/s':>12s} {'vs Drake':>9s}")
    for name, r in (
        ("numpy leg_forces, vectorised (plate only)", r_np),
        ("numpy leg_forces_with_legs, vectorised", r_np_legs),
        ("numpy leg_forces, one call per sample", r_np_one),
        ("Drake free body CalcInverseDynamics, per sample", r_dk),
        ("Drake closed loop [B G^T][u; lambda] = tau_ID, per sample", r_cl),
    ):
        print(f"{name:58s} {r:12.0f} {r / r_dk:8.2f}x")
    print(f"worst |numpy - Drake| leg force: {err:.2e} N")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
