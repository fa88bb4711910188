"""The compiled path tracker (``track.c``): built once with the project's C build (``system.c_build``:
content-hash cache in ``$STEWART_DRAKE_CACHE``) and called through cffi.

Why compiled: the numpy tracker advances all paths in lockstep, so a length set costs (steps of its
slowest path) × (≈ 20 numpy calls of ≈ 10 µs each), whatever the number of paths; the C loop tracks
one path at a time, each for its own number of steps, with no per-step call overhead. It implements
the numpy tracker's algorithm step for step (``track.py``); the tests check that both give the same
end points. Used when a C compiler is available (``TrackOptions.engine = "auto"``), else numpy.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from stewart_drake.system.c_build import UNAVAILABLE, load, source_keyed_library

SOURCE = Path(__file__).with_name("track.c")
CDEF = """
void sd_track(int64_t n, const double *x0, const double *B0, const double *dB, int fixed, const double *s0,
              const double *ds, const double *v, const double *gamma, const int64_t *cap, const double *opts,
              int64_t end_newton, double *x_out, double *t_out, int64_t *state_out, int64_t *steps_out);
"""
_LIB: list = []  # [(ffi, lib)] once built, or [the UNAVAILABLE error] when it cannot be built here


OPT = "-O2"


def library():
    """``(ffi, lib)`` of the compiled tracker, built on first use. Raises CompilerUnavailable without a
    C compiler, CacheUnavailable without a usable cache (remembered: not tried again), CompileError if the source does not compile (a
    bug, never hidden by a fallback)."""
    if not _LIB:
        try:
            _LIB.append(
                load(source_keyed_library(SOURCE, CDEF, "sd-homotopy-track", OPT), CDEF, cache_declarations=True)
            )
        except UNAVAILABLE as err:
            _LIB.append(err)
    if isinstance(_LIB[0], UNAVAILABLE):
        raise _LIB[0]
    return _LIB[0]


def available() -> bool:
    """True when the compiled tracker can be used (a C compiler and a cache exist; built on first call)."""
    try:
        library()
    except UNAVAILABLE:
        return False
    return True


def _ptr(ffi, a: np.ndarray, ctype: str):
    return ffi.cast(ctype, a.ctypes.data)


def track_c(x0, B0, dB, fixed: bool, s0, ds, v, gamma, cap, opts, end_newton: int):
    """Run ``sd_track`` on contiguous copies of the inputs: x0 ``(n, 8)``, B0, dB ``(6, 4, 4)``, s0, ds
    ``(n, 6)``, v ``(8,)``, gamma ``(n,)`` (complex), cap ``(n,)`` step limits, opts ``(8,)`` (h0, h_max,
    h_min, target, tol, max_jump, contraction, endgame). Returns x ``(n, 8)``, t, state, steps ``(n,)``."""
    ffi, lib = library()
    n = len(x0)
    c = [np.ascontiguousarray(a, dtype=complex) for a in (x0, B0, dB, s0, ds, v, gamma)]
    cap = np.ascontiguousarray(cap, dtype=np.int64)
    opts = np.ascontiguousarray(opts, dtype=float)
    x = np.empty((n, 8), complex)
    t = np.empty(n)
    state = np.empty(n, np.int64)
    steps = np.empty(n, np.int64)
    d = [_ptr(ffi, a, "double *") for a in c]
    lib.sd_track(
        n,
        d[0],
        d[1],
        d[2],
        int(fixed),
        d[3],
        d[4],
        d[5],
        d[6],
        _ptr(ffi, cap, "int64_t *"),
        _ptr(ffi, opts, "double *"),
        end_newton,
        _ptr(ffi, x, "double *"),
        _ptr(ffi, t, "double *"),
        _ptr(ffi, state, "int64_t *"),
        _ptr(ffi, steps, "int64_t *"),
    )
    return x, t, state, steps
