"""Regenerate the start systems of the homotopy forward kinematics (stewart_drake/homotopy/data/).

    PYTHONPATH=. .venv/bin/python scripts/make_fk_start_systems.py [--seed 1] [--out DIR]

One monodromy solve per architecture class (6-6: 40 solutions; 3-6: 16, also used for 6-3), see
``stewart_drake.homotopy.start``. Deterministic for a given seed. Writes start_6-6.npz, start_3-6.npz.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from stewart_drake.homotopy.start import DATA, monodromy_solve
from stewart_drake.homotopy.study import GENERAL, THREE_SIX


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", type=Path, default=DATA)
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    for kind in (GENERAL, THREE_SIX):
        t0 = time.perf_counter()
        S = monodromy_solve(kind, seed=args.seed)
        path = args.out / f"start_{kind}.npz"
        S.save(path)
        print(
            f"{kind}: {len(S.x)} solutions, max residual {S.residual():.2e}, {time.perf_counter() - t0:.2f} s -> {path}"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
