"""Choosing the engine that runs the firmware: ``python`` (the numpy emulation) or ``c`` (the compiled C),
falling back to Python with a one-line notice on stderr when no C compiler is available."""

from __future__ import annotations

import sys

from stewart_drake.core.c_build import CompilerUnavailable, default_compiler
from stewart_drake.errors import FirmwareError

ENGINES = ("python", "c")


def resolve_engine(engine: str, what: str = "stewart-drake") -> str:
    """``engine`` if it can run here: ``"c"`` needs a C compiler; without one the notice says so on
    stderr and ``"python"`` is returned (same numbers, bit for bit, only slower)."""
    if engine not in ENGINES:
        raise FirmwareError(FirmwareError.ENGINE.format(valid=", ".join(ENGINES), value=engine))
    if engine == "c":
        try:
            default_compiler()
        except CompilerUnavailable as e:
            print(f"{what}: note: {e}; running the Python engine instead (bit-identical, slower)", file=sys.stderr)
            return "python"
    return engine
