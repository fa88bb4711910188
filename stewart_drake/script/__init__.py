"""The motion language (seed 004, part 3): a Lark grammar (``stewart.lark``), parser, static checks,
interpreter, and back ends that emit Python (calling this library) or the seed's Matlab lines.

Typical use::

    from stewart_drake.script import compile_program
    motion = compile_program(text, "prog.stw", platform)        # parse + check + run: a Motion
    result = evaluate(platform, motion.trajectory())            # IK + inverse dynamics
"""

from __future__ import annotations

from stewart_drake.core.geometry import Platform
from stewart_drake.script.check import check
from stewart_drake.script.errors import Loc, ScriptError, ScriptErrors
from stewart_drake.script.interpreter import execute
from stewart_drake.script.parser import parse
from stewart_drake.script.runtime import DEFAULT_RATE, Motion, Result, Trajectory, evaluate

__all__ = [
    "Loc",
    "Motion",
    "Result",
    "ScriptError",
    "ScriptErrors",
    "Trajectory",
    "check",
    "compile_program",
    "evaluate",
    "execute",
    "parse",
    "run_program",
]


def compile_program(text: str, filename: str, platform: Platform):
    """Parse, check and execute a program starting from the platform's home pose.
    Returns ``(program, motion)``; raises ``ScriptError`` on any problem."""
    program = parse(text, filename)
    check(program)
    motion = Motion.at_home(platform)
    execute(program, motion)
    return program, motion


def run_program(
    text: str,
    filename: str,
    platform: Platform,
    rate: float = DEFAULT_RATE,
    convention: str = "utn",
    coriolis: bool = True,
) -> Result:
    """Everything ``stewart-drake run`` computes, before writing anything: parse, check, execute,
    sample the trajectory, IK with stroke check, inverse dynamics."""
    program, motion = compile_program(text, filename, platform)
    try:
        return evaluate(platform, motion.trajectory(rate), convention=convention, coriolis=coriolis)
    except ScriptError as e:
        for err in getattr(e, "errors", [e]):
            err.source = program.source
        e.source = program.source
        raise
