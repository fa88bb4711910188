"""The host build of the DSP56800E intrinsics (``fixedpoint/c/dsp56800e.h``, ``.c``) and of the seed
firmware's IK (``fixedpoint/c/tp17.c``), called from numpy.

- ``intrinsic(name, a, b=0, c=0)``: one intrinsic elementwise over int64 arrays (one C call per batch);
- ``frac(x, bits=16)``: FRAC16 / FRAC32 of doubles;
- ``tp17_leg_lengths_c(poses)``: the compiled tp17.C IK for ``(..., 6)`` firmware poses (mm, pi-fractions);
- ``op_counts_tp17()``: the intrinsic calls of one pass, from the instrumented build (``DSP_COUNT_OPS``).
"""

from __future__ import annotations

import re
from collections import Counter

import numpy as np

from stewart_drake.fixedpoint.tp17 import check_dsp_poses
from stewart_drake.system.c_build import C_DIR, Compiler, build, library_sources, load


def c_enum(file: str, prefix: str) -> tuple[str, ...]:
    """The members of the ``enum`` in ``fixedpoint/c/<file>`` whose names start with ``prefix``, in value
    order (0, 1, ...) and with ``prefix`` removed; a closing count member ``<prefix>N`` is left out. Read
    from the C source so that Python's operation indices cannot drift from the C build's."""
    text = re.sub(r"/\*.*?\*/", "", (C_DIR / file).read_text(encoding="utf-8"), flags=re.S)
    for body in re.findall(r"enum\s*\{(.*?)\}", text, re.S):
        names = [n.strip() for n in body.split(",") if n.strip()]
        if names and all(re.fullmatch(re.escape(prefix) + r"\w+", n) for n in names):
            return tuple(n[len(prefix) :] for n in names if n != prefix + "N")
    raise LookupError(f"no enum of {prefix}* members in {file}")  # internal: the shipped C sources have both


# dsp_batch(op, ...)'s op codes, by q15 function name (the C ``round`` is q15's ``round_``).
BATCH_OPS = tuple("round_" if n == "round" else n for n in c_enum("dsp_batch.c", "B_"))
# The counters of the instrumented build, dsp_op_counts[DSP_OP_<name>] (names as in fixedpoint.cycles).
OP_NAMES = c_enum("dsp56800e.h", "DSP_OP_")

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
