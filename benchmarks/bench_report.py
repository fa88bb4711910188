"""The cold report's cost (``stewart-drake report --no-cache`` into a fresh folder), full and ``--quick``,
optionally beside another checkout of the project (e.g. an older commit) timed in the same run, interleaved
so that both see the same machine load:

    PYTHONPATH=. python benchmarks/bench_report.py [--quick-only] [--compare OTHER_CHECKOUT]

Per run: wall seconds, CPU seconds (user + sys of the command and every process it started: workers,
clusters), the load average before it, and the idle-machine estimate CPU / cores (the report's workers keep
the cores busy; start-up adds a few seconds), beside the targets of issue 28 (30 s full, 10 s quick, on an
idle 2-core machine). On a loaded machine the wall time depends on the other jobs; CPU seconds compare.
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TARGET_S = {"full": 30.0, "quick": 10.0}  # wall, idle 2-core machine


def run_report(checkout: Path, quick: bool) -> dict:
    """One cold report from ``checkout``: wall and CPU seconds, load before, checks line, exit status."""
    env = dict(os.environ, PYTHONPATH=str(checkout), MPLBACKEND="Agg")
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    load = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [sys.executable, "-m", "stewart_drake.cli", "report", "--no-cache", "--out", str(Path(tmp) / "rep")]
        t0 = time.perf_counter()
        r = subprocess.run(cmd + (["--quick"] if quick else []), env=env, cwd=checkout, capture_output=True, text=True)
        wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    wrote = [line for line in r.stderr.splitlines() + r.stdout.splitlines() if "checks" in line and "wrote" in line]
    return {
        "wall": wall,
        "cpu": cpu,
        "load": load,
        "rc": r.returncode,
        "checks": wrote[-1] if wrote else r.stderr[-300:],
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick-only", action="store_true", help="only the --quick report")
    ap.add_argument("--compare", type=Path, help="another checkout, timed in the same run")
    args = ap.parse_args()
    cores = os.cpu_count() or 1
    checkouts = [("this", ROOT)] + ([("compare", args.compare.resolve())] if args.compare else [])
    modes = ["quick"] if args.quick_only else ["full", "quick"]
    print(f"{cores} cores; idle estimate = CPU / {cores} (start-up not included)")
    print(
        f"{'mode':6} {'checkout':8} {'wall s':>8} {'CPU s':>8} {'load':>5} {'idle est. s':>11} {'target s':>9}  rc  checks"
    )
    for mode in modes:
        for name, path in checkouts:  # interleaved: both checkouts see the same load
            r = run_report(path, mode == "quick")
            print(
                f"{mode:6} {name:8} {r['wall']:8.1f} {r['cpu']:8.1f} {r['load']:5.1f} {r['cpu'] / cores:11.1f} "
                f"{TARGET_S[mode]:9.0f}  {r['rc']:2d}  {r['checks']}",
                flush=True,
            )


if __name__ == "__main__":
    main()
