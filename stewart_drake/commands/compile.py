"""``stewart-drake compile``: translate a motion program (.stw) to Python or to the seed's Matlab lines.

The program is checked and run first (syntax, variables, argument counts, reachability on
``--platform``), so nothing is written for a program with errors.
"""

from __future__ import annotations

import sys

from stewart_drake.commands._common import add_platform_arg, platform_from_args
from stewart_drake.core.rotations import CONVENTIONS
from stewart_drake.script import ScriptError, compile_program
from stewart_drake.script.emit import emit_matlab, emit_python
from stewart_drake.script.runtime import check_reachable
from stewart_drake.script.source import read_program
from stewart_drake.system.output_folder import check_output_file, write_output_file


def register(sub) -> None:
    p = sub.add_parser(
        "compile",
        help="translate a motion program (.stw) to Python (calling this library) or Matlab (the seed's output)",
    )
    p.add_argument("program", metavar="PROGRAM.stw", help="motion-language source file")
    p.add_argument("--emit", choices=["python", "matlab"], required=True, help="back end")
    p.add_argument(
        "-o", "--output", metavar="FILE", help="write here instead of standard output ('-': standard output)"
    )
    add_platform_arg(p)
    p.add_argument("--convention", choices=list(CONVENTIONS), default="utn", help="Euler convention (default utn)")
    p.add_argument("--rate", type=float, default=100.0, help="python: trajectory samples per second (default 100)")
    p.set_defaults(func=run)


def run(args) -> int:
    text = read_program(args.program)
    if args.output == "-":  # the usual convention: "-" is standard output, never a file named "-"
        args.output = None
    if args.output:
        check_output_file(args.output, option="--output")
    platform = platform_from_args(args)
    try:
        program, motion = compile_program(text, args.program, platform)
        try:
            check_reachable(platform, motion.trajectory(args.rate), args.convention)
        except ScriptError as e:
            for err in getattr(e, "errors", [e]):
                err.source = text
            e.source = text
            raise
    except ScriptError as e:
        print(e.render(), file=sys.stderr)
        return 2
    if args.emit == "matlab":
        code = emit_matlab(motion)
    else:
        code = emit_python(program, platform=args.platform, convention=args.convention, rate=args.rate)
    if args.output:
        write_output_file(args.output, code, option="--output")
    else:
        sys.stdout.write(code)
    return 0
