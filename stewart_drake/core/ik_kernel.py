"""The compiled IK kernel: ``(..., 6)`` poses -> ``(..., 6)`` leg lengths (metres), ``core/ik_kernel.c``
through ``system.c_build`` (cffi), with ``kinematics.leg_lengths`` as the reference and the fallback.

Why: a design search or a dense map evaluates IK billions of times; the numpy path streams a dozen
``(n, 6)`` temporaries per block, the C loop keeps a pose in registers and uses its own sine and cosine
(fdlibm's kernels, < 1 ulp): ≈ 7x the numpy path's poses per CPU second on one core
(``benchmarks/bench_ik_kernel.py``; ≈ 350 instructions per pose by callgrind). Same formula and summation order
as the numpy path; the only difference is the last bit of a sine or cosine, so the lengths agree to a few
ulp (the tests pin 1e-15 m, absolute, on legs of 0.2–1.2 m). Without a C compiler the numpy path runs,
with a one-line note on stderr.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from stewart_drake.core.argcheck import as_poses
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_lengths as numpy_leg_lengths
from stewart_drake.core.rotations import CONVENTIONS, check_convention
from stewart_drake.errors import FkInputError
from stewart_drake.system.c_build import UNAVAILABLE, load, source_keyed_library

SOURCE = Path(__file__).with_name("ik_kernel.c")
CDEF = "void sd_ik(int64_t n, const double *g, int conv, const double *q, double *L);"
OPT = "-O2"
NO_COMPILER_NOTE = "note: no C compiler: IK runs the numpy path (~6x slower)"
_LIB: list = []


def library():
    """``(ffi, lib)`` of the compiled kernel, or None without a compiler or cache (noted once on stderr)."""
    if not _LIB:
        try:
            _LIB.append(load(source_keyed_library(SOURCE, CDEF, "sd-ik-kernel", OPT), CDEF))
        except UNAVAILABLE:
            print(NO_COMPILER_NOTE, file=sys.stderr)
            _LIB.append(None)
    return _LIB[0]


def available() -> bool:
    """True when the compiled kernel runs here."""
    return library() is not None


def leg_lengths(platform: Platform, poses, convention: str = "utn", *, engine: str = "auto") -> np.ndarray:
    """``(..., 6)`` leg lengths (m) for ``(..., 6)`` poses (m, rad, ``convention``): the compiled kernel
    (``engine`` ``auto`` or ``c``), else ``kinematics.leg_lengths`` (``numpy``, or ``auto`` without a compiler)."""
    check_convention(convention)
    if engine not in ("auto", "c", "numpy"):
        raise FkInputError(FkInputError.ENGINE.format(value=engine))
    q = as_poses(poses)
    lib = library() if engine != "numpy" else None
    if lib is None and engine == "c":
        raise FkInputError(FkInputError.NO_COMPILER)
    if lib is None:
        return numpy_leg_lengths(platform, q, convention)
    ffi, c = lib
    flat = np.ascontiguousarray(q.reshape(-1, 6), dtype=float)
    out = np.empty_like(flat)
    g = np.concatenate(
        [platform.base_anchors.ravel(), (platform.top_anchors_per_leg - platform.rotation_centre).ravel()]
    )
    fb = ffi.from_buffer
    c.sd_ik(len(flat), fb("double[]", g), CONVENTIONS.index(convention), fb("double[]", flat), fb("double[]", out))
    return out.reshape(q.shape)
