"""Choosing the engine that runs the firmware: ``python`` (the numpy emulation) or ``c`` (the compiled C,
the default for the fixed-point controller in the loop), falling back to Python with a one-line notice on
stderr when no C compiler (or no cache folder) is available."""

from __future__ import annotations

import sys

from stewart_drake.errors import FirmwareError
from stewart_drake.system.c_build import UNAVAILABLE, cache_dir, default_compiler

ENGINES = ("python", "c")


def resolve_engine(engine: str, what: str = "stewart-drake") -> str:
    """``engine`` if it can run here: ``"c"`` needs a C compiler and a usable cache folder; without them
    the notice says so on stderr and ``"python"`` is returned (same numbers, bit for bit, only slower)."""
    if engine not in ENGINES:
        raise FirmwareError(FirmwareError.ENGINE.format(valid=", ".join(ENGINES), value=engine))
    if engine == "c":
        try:
            default_compiler()
            cache_dir()
        except UNAVAILABLE as e:
            print(f"{what}: note: {e}; running the Python engine instead (bit-identical, slower)", file=sys.stderr)
            return "python"
    return engine


def default_engine(engine: str | None, controller: str, what: str = "stewart-drake") -> str:
    """The engine a closed loop runs: ``engine`` if given (``resolve_engine``), else ``c`` for the
    fixed-point controller (bit-identical to the emulation and faster; ``python`` without a compiler, with
    the notice) and ``python`` for the float twin (it has no firmware)."""
    if engine is None:
        engine = "c" if controller == "fixed" else "python"
    return resolve_engine(engine, what)
