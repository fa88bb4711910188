"""``stewart-drake report``: run the analyses and write the HTML report."""

from __future__ import annotations

import sys

from stewart_drake.commands._common import add_force_arg, output_folder, refuse_machine_file
from stewart_drake.report.api import report


def register(sub) -> None:
    p = sub.add_parser(
        "report",
        help="run the analyses on the built-in presets (or on your platform or machine) and write an HTML report",
    )
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
    p.add_argument(
        "--no-cache",
        action="store_true",
        help="recompute every section (default: a section whose inputs and code are unchanged comes from the cache)",
    )
    who = p.add_mutually_exclusive_group()
    who.add_argument(
        "--platform",
        action="append",
        metavar="FILE|NAME",
        help="report on this platform file or preset instead of the presets (repeat for several); sections that "
        "do not apply say what they need",
    )
    who.add_argument(
        "--machine",
        metavar="FILE",
        help="report on this machine file: its platform and payload, the loop's fixed-point format (firmware:), "
        "its motions and requirements",
    )
    add_force_arg(p)
    p.set_defaults(func=run)


def run(args) -> int:
    refuse_machine_file(args.platform, "--machine")
    out = output_folder(args)
    say = lambda line: print(line, file=sys.stderr, flush=True)  # noqa: E731
    r = report(
        out,
        only=args.only,
        quick=args.quick,
        jobs=args.jobs,
        on_start=say,
        cache=not args.no_cache,
        platform=args.platform,
        machine=args.machine,
    )
    print(f"wrote {r.index}: {len(r.checks)} checks, {len(r.failed)} failed, {r.elapsed_s:.0f} s")
    for c in r.failed:
        print(f"  FAIL {c.section}: {c.what}: worst {c.worst:.4g} {c.unit} > tolerance {c.tolerance:.4g} {c.unit}")
    return 0 if r.ok else 1
