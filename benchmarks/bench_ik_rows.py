"""``stewart-drake ik --poses`` time against the number of rows: linear, not quadratic.

Run by hand: ``.venv/bin/python benchmarks/bench_ik_rows.py [--rows 10000 100000 1000000]``. Writes CSVs
of random poses (a tenth of them out of stroke or below the base, so the per-row flags are exercised)
in a temporary folder, runs the command in-process with its output discarded, and prints seconds per
file and the ratio of time per row between the largest and the smallest file (1 = linear).
"""

from __future__ import annotations

import argparse
import contextlib
import os
import tempfile
import time

import numpy as np

from stewart_drake.cli import main as cli


def write_poses(path: str, n: int, rng) -> None:
    q = np.column_stack([rng.uniform(-50, 50, (n, 2)), rng.uniform(80, 250, n), rng.uniform(-5, 5, (n, 3))])
    bad = rng.random(n) < 0.1
    q[bad, 2] = rng.choice([-100.0, 650.0], bad.sum())
    np.savetxt(path, q, delimiter=",", fmt="%.6f", header="px,py,pz,a,b,g", comments="")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rows", type=int, nargs="+", default=[10_000, 100_000, 1_000_000])
    ap.add_argument("--json", action="store_true", help="time --json output instead of the table")
    args = ap.parse_args(argv)
    rng = np.random.default_rng(0)
    times = {}
    with tempfile.TemporaryDirectory() as d:
        for n in args.rows:
            f = os.path.join(d, f"p{n}.csv")
            write_poses(f, n, rng)
            with open(os.devnull, "w") as null, contextlib.redirect_stdout(null):
                t0 = time.perf_counter()
                rc = cli(["ik", "--poses", f] + (["--json"] if args.json else []))
                times[n] = time.perf_counter() - t0
            print(f"{n:>9} rows: {times[n]:7.2f} s  ({times[n] / n * 1e6:.2f} µs/row, exit {rc})")
    lo, hi = min(times), max(times)
    print(f"time per row, {hi} vs {lo} rows: ratio {(times[hi] / hi) / (times[lo] / lo):.2f} (1 = linear)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
