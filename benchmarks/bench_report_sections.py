"""CPU seconds of report sections built in-process (``report.build_section``, one fresh process per build, matplotlib
imported before the clock starts), best of ``--repeat``; with ``--ref REV`` the same sections of git revision REV
(exported to a temporary folder) run interleaved with the working tree's, and the ratio of the best CPU times is
printed (interleaved, so machine load hits both alike: on a shared machine compare ratios, not seconds).

    PYTHONPATH=. python benchmarks/bench_report_sections.py [--sections synthesis firmware_certificate workspace]
        [--modes quick full] [--repeat 3] [--ref main]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CHILD = """
import sys, time
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot  # noqa: F401  (imported before the clock: every report worker has it)
from pathlib import Path
import stewart_drake
from stewart_drake.report import build_section, load_analysis, parts
parts.IN_WORKER = True  # a section's parallel_map runs in this process
a = load_analysis(Path(stewart_drake.__file__).parent / "analyses" / (sys.argv[1] + ".py"))
c0 = time.process_time()
s = build_section(a, sys.argv[2] == "quick")
print(time.process_time() - c0, sum(not c.passed for c in s.checks))
"""


def cpu_of(tree: Path, section: str, mode: str) -> float:
    """CPU seconds of one build of ``section`` from the package in ``tree`` (a fresh process)."""
    out = subprocess.run(
        [sys.executable, "-c", CHILD, section, mode],
        cwd=tree,
        env={**os.environ, "PYTHONPATH": str(tree), "MPLBACKEND": "Agg"},
        capture_output=True,
        text=True,
        check=True,
    ).stdout.split()
    if int(out[1]):
        print(f"  ({tree.name}: {section} {mode} has {out[1]} failed checks)")
    return float(out[0])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sections", nargs="+", default=["synthesis", "firmware_certificate", "workspace"])
    ap.add_argument("--modes", nargs="+", default=["quick", "full"], choices=["quick", "full"])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--ref", help="git revision to compare with (interleaved)")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        trees = {"tree": ROOT}
        if args.ref:
            ref = Path(tmp) / "ref"
            ref.mkdir()
            archive = Path(tmp) / "ref.tar"
            subprocess.run(["git", "archive", "-o", str(archive), args.ref], cwd=ROOT, check=True)
            with tarfile.open(archive) as t:
                t.extractall(ref, filter="data")
            trees["ref"] = ref
        best = {}
        for _ in range(args.repeat):
            for section in args.sections:
                for mode in args.modes:
                    for name, tree in trees.items():
                        t = cpu_of(tree, section, mode)
                        best[name, section, mode] = min(best.get((name, section, mode), t), t)
        for section in args.sections:
            for mode in args.modes:
                line = f"{section:22s} {mode:5s} tree {best['tree', section, mode]:6.2f} s CPU"
                if args.ref:
                    r = best["ref", section, mode]
                    line += f"   {args.ref} {r:6.2f} s   tree/ref {best['tree', section, mode] / r:.2f}"
                print(line)


if __name__ == "__main__":
    main()
