"""Robustness sweep of the complete FK solver: many seeded random platforms, each solved by the
homotopy (``stewart_drake.homotopy``) and by the multi-start search (``forward.assembly_modes``).

Run by hand: ``PYTHONPATH=. .venv/bin/python benchmarks/sweep_fk_homotopy.py [--planar 100] [--general 40]
[--three-six 40] [--engine auto|c|numpy]``. Prints, per family, how many results are complete, agree with the multi-start (same
real modes to 1e-8), have every mode certified, needed re-tracking or a new gamma; lists any exception.
"""

from __future__ import annotations

import argparse

import numpy as np

from stewart_drake.core.assembly_modes import assembly_modes
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.reference_platforms import general_platform, planar_platform
from stewart_drake.homotopy import solve
from stewart_drake.homotopy.track import ENGINES, TrackOptions


def same_modes(a, b, tol: float = 1e-8) -> bool:
    A = np.array([np.r_[m.position, m.rotation.ravel()] for m in a]).reshape(-1, 12)
    B = np.array([np.r_[m.position, m.rotation.ravel()] for m in b]).reshape(-1, 12)
    if len(A) != len(B):
        return False
    if len(A) == 0:
        return True
    d = np.abs(A[:, None] - B[None]).max(-1)
    return bool(np.all(d.min(1) < tol) and np.all(d.min(0) < tol))


def three_six_platform(seed: int):
    """A seeded random 3-6 platform (plate joints shared in pairs, non-planar base) and a pose's lengths."""
    rng = np.random.default_rng(1000 + seed)
    ang = np.sort(rng.uniform(0, 2 * np.pi, 6))
    base = np.c_[np.cos(ang), np.sin(ang), rng.uniform(-0.1, 0.1, 6)] * rng.uniform(0.6, 1, (6, 1))
    ta = np.sort(rng.uniform(0, 2 * np.pi, 3))
    top = np.c_[0.5 * np.cos(ta), 0.5 * np.sin(ta), rng.uniform(-0.05, 0.05, 3)]
    p = Platform(
        name=f"random-3-6-seed{seed}",
        base_anchors=base,
        top_anchors=top,
        leg_top=np.array([0, 0, 1, 1, 2, 2]),
        stroke=np.array([0.3, 2.5]),
        mass=0.0,
        com=np.zeros(3),
        inertia=np.zeros((3, 3)),
        home_height=1.0,
    )
    q = p.home_pose() + np.r_[rng.uniform(-0.1, 0.1, 3), rng.uniform(-0.3, 0.3, 3)]
    return p, leg_lengths(p, q)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--planar", type=int, default=100)
    ap.add_argument("--general", type=int, default=40)
    ap.add_argument("--three-six", type=int, default=40)
    ap.add_argument(
        "--engine", choices=ENGINES, default="auto", help="path tracker implementation (TrackOptions.engine)"
    )
    args = ap.parse_args(argv)
    options = TrackOptions(engine=args.engine)
    for family, make, n in (
        ("planar 6-6", planar_platform, args.planar),
        ("general 6-6", general_platform, args.general),
        ("3-6", three_six_platform, args.three_six),
    ):
        complete = agree = certified = retracked = regamma = 0
        for seed in range(n):
            p, L = make(seed)
            r = solve(p, L, options=options)
            ms = assembly_modes(p, L, polish=None)
            ok = same_modes(r.modes, ms.modes)
            complete += r.complete
            agree += ok
            certified += all(m.certified for m in r.modes)
            retracked += bool(r.retracked)
            regamma += r.attempts > 1
            if not (r.complete and ok):
                print(
                    f"  {family} seed {seed}: {r.counts()} complete {r.complete}, {len(r.modes)} vs {len(ms)} modes: {r.guarantee}"
                )
        print(
            f"{family:12s} {n:4d} platforms: complete {complete}, agree with multi-start {agree}, all modes certified "
            f"{certified}, re-tracked {retracked}, new gamma {regamma}"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
