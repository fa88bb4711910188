"""The host build of the DSP56800E intrinsics (``fixedpoint/c/dsp56800e.h``, ``.c``) and of the seed
firmware's IK (``fixedpoint/c/tp17.c``), called from numpy.

- ``intrinsic(name, a, b=0, c=0)``: one intrinsic elementwise over int64 arrays (one C call per batch);
- ``frac(x, bits=16)``: FRAC16 / FRAC32 of doubles;
- ``tp17_leg_lengths_c(poses)``: the compiled tp17.C IK for ``(..., 6)`` firmware poses (mm, pi-fractions);
- ``op_counts_tp17()``: the intrinsic calls of one pass, from the instrumented build (``DSP_COUNT_OPS``).
"""

from __future__ import annotations

from collections import Counter

import numpy as np

from stewart_drake.core.c_build import Compiler, build, library_sources, load
from stewart_drake.fixedpoint.tp17 import check_dsp_poses

# The order of the B_* enum in dsp_batch.c.
BATCH_OPS = (
    "add",
    "sub",
    "negate",
    "abs_s",
    "mult",
    "mult_r",
    "shl",
    "shr",
    "L_add",
    "L_sub",
    "L_negate",
    "L_abs",
    "L_mult",
    "L_mac",
    "L_msu",
    "L_shl",
    "L_shr",
    "extract_h",
    "extract_l",
    "L_deposit_h",
    "L_deposit_l",
    "round_",
    "mac_r",
    "msu_r",
    "div_s",
    "mfr32Sqrt",
    "tfr16SinPIx",
    "tfr16CosPIx",
)
# The order of the DSP_OP_* enum in dsp56800e.h.
OP_NAMES = (
    "add sub negate abs_s L_add L_sub L_negate L_abs L_mult extract_h extract_l L_deposit_h L_deposit_l "
    "round mult mult_r shl shr L_shl L_shr div_s mfr32Sqrt tfr16SinPIx tfr16CosPIx FRAC16"
).split()

CDEF = """
int dsp_batch(int op, const int64_t *a, const int64_t *b, const int64_t *c, int64_t *out, long n);
void dsp_batch_frac(int which, const double *x, int64_t *out, long n);
void tp17_ik_batch(const double *poses, long n, int a, int b, int d, int16_t *out);
"""
COUNTING_CDEF = (
    CDEF
    + f"""
extern long dsp_op_counts[{len(OP_NAMES)}];
extern int dsp_op_counting;
extern long dsp_saturations;
"""
)


def host_library(counting: bool = False, compiler: Compiler | None = None):
    """``(ffi, lib)`` of the host build (compiled on first use, then cached); ``counting``: the
    instrumented build (op and saturation counters)."""
    path = build(
        library_sources("dsp56800e.c", "dsp_batch.c", "tp17.c"),
        compiler=compiler,
        defines=("DSP_COUNT_OPS", "DSP_COUNT_SATURATIONS") if counting else (),
        opt="-O2",
    )
    return load(path, COUNTING_CDEF if counting else CDEF)


def intrinsic(name: str, a, b=0, c=0, compiler: Compiler | None = None) -> np.ndarray:
    """``name`` (a ``q15`` function name, e.g. ``L_mac``) applied by the C build elementwise to the
    broadcast int64 operands (in-range words: the caller validates); returns int64 of the broadcast shape."""
    ffi, lib = host_library(compiler=compiler)
    op = BATCH_OPS.index(name)
    a, b, c = (
        np.ascontiguousarray(x, dtype=np.int64)
        for x in np.broadcast_arrays(np.asarray(a), np.asarray(b), np.asarray(c))
    )
    out = np.empty(a.shape, dtype=np.int64)
    lib.dsp_batch(
        op,
        ffi.from_buffer("int64_t[]", a),
        ffi.from_buffer("int64_t[]", b),
        ffi.from_buffer("int64_t[]", c),
        ffi.from_buffer("int64_t[]", out),
        out.size,
    )
    return out


def frac(x, bits: int = 16, compiler: Compiler | None = None) -> np.ndarray:
    """FRAC16 (``bits=16``) or FRAC32 (``bits=32``) of doubles ``x`` by the C build."""
    ffi, lib = host_library(compiler=compiler)
    x = np.ascontiguousarray(x, dtype=float)
    out = np.empty(x.shape, dtype=np.int64)
    lib.dsp_batch_frac(int(bits == 32), ffi.from_buffer("double[]", x), ffi.from_buffer("int64_t[]", out), out.size)
    return out


def tp17_leg_lengths_c(
    poses, a: int = 612, b: int = 925, d: int = 150, compiler: Compiler | None = None, counting: bool = False
) -> np.ndarray:
    """``(..., 6)`` int64 leg lengths (mm) from the compiled tp17.C for ``(..., 6)`` firmware poses
    [px, py, pz mm; alpha, beta, gamma fractions of pi] (validated as ``tp17.check_dsp_poses``)."""
    q = np.ascontiguousarray(check_dsp_poses(poses), dtype=float)
    ffi, lib = host_library(counting=counting, compiler=compiler)
    flat = q.reshape(-1, 6)
    out = np.empty((len(flat), 6), dtype=np.int16)
    lib.tp17_ik_batch(
        ffi.from_buffer("double[]", flat), len(flat), int(a), int(b), int(d), ffi.from_buffer("int16_t[]", out)
    )
    return out.astype(np.int64).reshape(q.shape)


def op_counts_tp17(pose=(0.0, 0.0, 100.0, 0.1, 0.05, 0.02)) -> Counter:
    """Intrinsic calls in one pass of the compiled tp17.C loop body, counted by the instrumented build."""
    ffi, lib = host_library(counting=True)
    lib.dsp_op_counting = 1
    for k in range(len(OP_NAMES)):
        lib.dsp_op_counts[k] = 0
    tp17_leg_lengths_c(np.asarray(pose, dtype=float), counting=True)
    counts = Counter({name: int(lib.dsp_op_counts[k]) for k, name in enumerate(OP_NAMES) if lib.dsp_op_counts[k]})
    for k in range(len(OP_NAMES)):
        lib.dsp_op_counts[k] = 0
    return counts
