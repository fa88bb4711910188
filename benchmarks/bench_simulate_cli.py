"""Real-time factor of ``stewart-drake simulate`` as a user runs it (the whole command: imports, gain
design, Diagram build, run, logs and plots), for both integrators and both fixed-point engines, optionally
beside another checkout of the project (e.g. an older commit) timed in the same run, interleaved:

    PYTHONPATH=. python benchmarks/bench_simulate_cli.py [--duration 2] [--repeat 3] [--compare OTHER_CHECKOUT]

The real-time factor is simulated seconds / wall seconds of the command (the best of ``--repeat``); the
simulated seconds are long enough that the run dominates the fixed costs.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CASES = [("sap", "python"), ("cenic", "python"), ("sap", "c"), ("cenic", "c")]


def wall(checkout: Path, integrator: str, engine: str, duration: float) -> float:
    """Seconds of one ``simulate`` command run from ``checkout``."""
    env = dict(os.environ, PYTHONPATH=str(checkout), MPLBACKEND="Agg")
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [sys.executable, "-m", "stewart_drake.cli", "simulate", "--duration", str(duration), "--no-progress",
               "--integrator", integrator, "--engine", engine, "--out", str(Path(tmp) / "out")]
        t0 = time.perf_counter()
        subprocess.run(cmd, env=env, cwd=checkout, check=True, capture_output=True)
        return time.perf_counter() - t0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--duration", type=float, default=2.0, help="simulated seconds per command (default 2)")
    ap.add_argument("--repeat", type=int, default=3, help="commands per case; the best is reported (default 3)")
    ap.add_argument("--compare", type=Path, default=None, help="another checkout to time alongside this one")
    args = ap.parse_args(argv)
    trees = {"this": ROOT} | ({"other": args.compare.resolve()} if args.compare else {})
    best = {(name, case): float("inf") for name in trees for case in CASES}
    for _ in range(args.repeat):
        for case in CASES:
            for name, tree in trees.items():  # interleaved: both trees see the same machine load
                best[name, case] = min(best[name, case], wall(tree, *case, args.duration))
    print(f"stewart-drake simulate --duration {args.duration:g} (seed on utn-dynamic, fixed point, 1 kHz); "
          f"real-time factor = simulated s / wall s of the command, best of {args.repeat}:")
    for case in CASES:
        cells = "   ".join(f"{name}: {args.duration / best[name, case]:5.3f}x ({best[name, case]:6.2f} s)" for name in trees)
        ratio = f"   this/other {best['other', case] / best['this', case]:.2f}x" if args.compare else ""
        print(f"  --integrator {case[0]:5s} --engine {case[1]:6s}  {cells}{ratio}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
