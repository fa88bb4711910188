"""``stewart-drake report``: run the analyses and write the HTML report."""

from __future__ import annotations

import os
import sys
import time

from stewart_drake.commands._common import add_force_arg, output_folder
from stewart_drake.core.geometry import PRESETS
from stewart_drake.core.processes import check_workers
from stewart_drake.report import command_line, discover_analyses, render, run_analyses, write_report


def register(sub) -> None:
    p = sub.add_parser("report", help="run the analyses on the built-in presets and write an HTML report")
    p.add_argument("--out", default="report", help="output folder (default: report/)")
    p.add_argument("--only", nargs="+", metavar="ANALYSIS", help="run only these analyses (file names in analyses/)")
    p.add_argument("--quick", action="store_true", help="smaller samples (smoke test)")
    p.add_argument(
        "--jobs",
        type=int,
        default=None,
        metavar="N",
        help="analyses run in N worker processes (default: the number of CPUs, at most 4; 1: in this process)",
    )
    add_force_arg(p)
    p.set_defaults(func=run)


def run(args) -> int:
    out = output_folder(args)
    jobs = args.jobs if args.jobs is not None else min(4, os.cpu_count() or 1)
    check_workers("--jobs", jobs)  # the one rule for worker counts (core.processes)
    t0 = time.perf_counter()
    analyses = discover_analyses(only=args.only)
    print(f"running {len(analyses)} analyses in {jobs} process{'es' if jobs > 1 else ''}", file=sys.stderr, flush=True)
    sections = run_analyses(analyses, quick=args.quick, jobs=jobs)
    elapsed = time.perf_counter() - t0
    meta = render.default_meta(sections, command_line(), elapsed, PRESETS)
    index = write_report(sections, out, meta=meta)
    checks = [c for s in sections for c in s.checks]
    failed = [c for c in checks if not c.passed]
    print(f"wrote {index}: {len(checks)} checks, {len(failed)} failed, {elapsed:.0f} s")
    for c in failed:
        print(f"  FAIL {c.section}: {c.what}: worst {c.worst:.4g} {c.unit} > tolerance {c.tolerance:.4g} {c.unit}")
    return 1 if failed else 0
