"""``stewart-drake report``: run the analyses and write the HTML report."""

from __future__ import annotations


from ._common import add_force_arg, output_folder


def register(sub) -> None:
    p = sub.add_parser("report", help="run the analyses on the built-in presets and write an HTML report")
    p.add_argument("--out", default="report", help="output folder (default: report/)")
    p.add_argument("--only", nargs="+", metavar="ANALYSIS", help="run only these analyses (file names in analyses/)")
    p.add_argument("--quick", action="store_true", help="smaller samples (smoke test)")
    add_force_arg(p)
    p.set_defaults(func=run)


def run(args) -> int:
    from ..report import discover_analyses, run_analyses, write_report

    out = output_folder(args)
    analyses = discover_analyses(only=args.only)
    sections = run_analyses(analyses, quick=args.quick)
    index = write_report(sections, out)
    checks = [c for s in sections for c in s.checks]
    failed = [c for c in checks if not c.passed]
    print(f"wrote {index}: {len(checks)} checks, {len(failed)} failed")
    for c in failed:
        print(f"  FAIL {c.section}: {c.what}: worst {c.worst:.4g} {c.unit} > tolerance {c.tolerance:.4g} {c.unit}")
    return 1 if failed else 0
