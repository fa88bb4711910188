"""Batched 2 × 2 Gram matrices and 2 × 2 / 3 × 3 solves with numpy's own bits, and approximate inverses, one C loop
per batch (``core/small_linalg.c``
through ``system.c_build``), numpy as the reference and the fallback.

Why: the legs' inverse dynamics (``dynamics.leg_forces_with_legs``) forms, per leg and per row of a feed-forward
table, the 2 × 2 Gram matrix of its universal joint's rate map and solves it twice. numpy does each with a
LAPACK/BLAS call per matrix (``@`` → dsyrk, ``linalg.solve`` → dgesv): ~0.3 µs each, a third of a table's time.
The fixed-point controller turns any last-bit change of a feed-forward force into different words, so the loop
here repeats numpy's arithmetic exactly — its OpenBLAS's fused multiply-adds included (numpy has no fused
multiply-add of its own, so no numpy expression could) — and checks that at load: a probe of random matrices
(both pivot orders, magnitudes 1e-8 … 1e8, near-singular) must give numpy's bits, else numpy runs (another
BLAS, another CPU's kernels). A batch with a pivot outside LAPACK's usual branch (zero, subnormal, not finite)
or a non-finite solution also runs numpy, which raises or answers as it always did. Without a C compiler numpy
runs, silently: the numbers are the same either way.
"""

from __future__ import annotations

import platform
from pathlib import Path

import numpy as np

SOURCE = Path(__file__).with_name("small_linalg.c")
CDEF = """
void sd_gram2(int64_t n, int64_t k, const double *B, double *G);
int sd_lu2(int64_t n, const double *A, double *F);
int sd_solve2(int64_t n, const double *F, const double *y, double *x);
int sd_solve3(int64_t n, const double *A, const double *y, double *x);
int sd_inverse(int64_t nb, int64_t n, const double *A, double *X);
"""


def _flags() -> tuple[str, ...]:
    """No contraction of a product and a sum the kernels round apart; on an x86-64 with the FMA extension,
    ``fma()`` as its instruction (without it, a libm call per operation: slower than numpy's BLAS calls)."""
    try:
        with open("/proc/cpuinfo") as f:
            fma = platform.machine() in ("x86_64", "AMD64") and " fma " in f.read(1 << 16)
    except OSError:
        fma = False
    return ("-ffp-contract=off", "-mfma") if fma else ("-ffp-contract=off",)


FLAGS = _flags()
PROBE_SIZE = 4096
_LIB: list = []


def library():
    """``(ffi, lib)`` of the compiled loops when they give numpy's bits here (probed once), else None."""
    if not _LIB:
        # deferred: the compiler glue (subprocess, tempfile, hashing, cffi) is needed only when the loops are first
        # run, and every command imports this module at start (through the kinematics)
        from stewart_drake.system.c_build import UNAVAILABLE, CompileError, load, source_keyed_library

        try:
            lib = load(
                source_keyed_library(SOURCE, CDEF, "sd-small-linalg", "-O2", FLAGS), CDEF, cache_declarations=True
            )
        except (*UNAVAILABLE, CompileError, OSError, ImportError):  # numpy gives the same numbers: run it
            lib = None
        _LIB.append(lib if lib is not None and _probe(lib) else None)
    return _LIB[0]


def numpy_gram(B) -> np.ndarray:
    """``(..., 2, 2)`` Bᵀ B of ``(..., k, 2)`` matrices, numpy's way (the reference)."""
    return np.swapaxes(B, -1, -2) @ B


def gram(B) -> np.ndarray:
    """``(..., 2, 2)`` Bᵀ B of ``(..., k, 2)`` float matrices: ``numpy_gram``'s numbers."""
    B = np.asarray(B, dtype=float)
    c = library()
    if c is None or B.shape[-1] != 2 or B.ndim < 2:
        return numpy_gram(B)
    ffi, lib = c
    flat = np.ascontiguousarray(B.reshape(-1, *B.shape[-2:]))
    G = np.empty((len(flat), 2, 2))
    lib.sd_gram2(len(flat), B.shape[-2], ffi.from_buffer("double[]", flat), ffi.from_buffer("double[]", G))
    return G.reshape(B.shape[:-2] + (2, 2))


class Solver2:
    """Solves of ``(..., 2, 2)`` matrices ``A`` for any number of right-hand sides in turn (the factors computed
    once): ``solve(y)`` gives ``np.linalg.solve(A, y[..., None])[..., 0]``'s numbers (and its errors)."""

    def __init__(self, A):
        self.A = np.asarray(A, dtype=float)
        self._factors = None
        c = library()
        if c is not None and self.A.shape[-2:] == (2, 2):
            ffi, lib = c
            flat = np.ascontiguousarray(self.A.reshape(-1, 2, 2))
            F = np.empty((len(flat), 5))
            if not lib.sd_lu2(len(flat), ffi.from_buffer("double[]", flat), ffi.from_buffer("double[]", F)):
                self._factors = F

    def solve(self, y) -> np.ndarray:
        """``(..., 2)`` x with A x = y for ``(..., 2)`` y (broadcast against A's batch)."""
        y = np.asarray(y, dtype=float)
        shape = np.broadcast_shapes(self.A.shape[:-1], y.shape)
        if self._factors is not None and shape == self.A.shape[:-1]:
            ffi, lib = library()
            flat = np.ascontiguousarray(np.broadcast_to(y, shape).reshape(-1, 2))
            x = np.empty_like(flat)
            fb = ffi.from_buffer
            if not lib.sd_solve2(len(flat), fb("double[]", self._factors), fb("double[]", flat), fb("double[]", x)):
                return x.reshape(shape)
        return np.linalg.solve(self.A, y[..., None])[..., 0]


def solve3(A, y) -> np.ndarray:
    """``(..., 3)`` x with A x = y for ``(..., 3, 3)`` A and ``(..., 3)`` y of the same batch:
    ``np.linalg.solve(A, y[..., None])[..., 0]``'s numbers (and its errors)."""
    A, y = np.asarray(A, dtype=float), np.asarray(y, dtype=float)
    c = library()
    if c is not None and A.shape[-2:] == (3, 3) and y.shape == A.shape[:-1]:
        ffi, lib = c
        fb = ffi.from_buffer
        flat, rhs = np.ascontiguousarray(A.reshape(-1, 3, 3)), np.ascontiguousarray(y.reshape(-1, 3))
        x = np.empty_like(rhs)
        if not lib.sd_solve3(len(flat), fb("double[]", flat), fb("double[]", rhs), fb("double[]", x)):
            return x.reshape(y.shape)
    return np.linalg.solve(A, y[..., None])[..., 0]


def approximate_inverse(A) -> np.ndarray:
    """``(..., n, n)`` X ≈ A⁻¹ for float ``(..., n, n)`` A (n ≤ 8), for an a-posteriori bound that holds for any X
    (``kinematics.condition_at_most``): Gauss–Jordan with partial pivoting in one C loop, not numpy's bits;
    ``np.linalg.inv`` (its answers and errors) where a pivot is zero or not finite, or without the loop."""
    A = np.asarray(A, dtype=float)
    c = library()
    n = A.shape[-1] if A.ndim >= 2 else 0
    if c is not None and 1 <= n <= 8 and A.shape[-2] == n:
        ffi, lib = c
        flat = np.ascontiguousarray(A.reshape(-1, n, n))
        X = np.empty_like(flat)
        if not lib.sd_inverse(len(flat), n, ffi.from_buffer("double[]", flat), ffi.from_buffer("double[]", X)):
            return X.reshape(A.shape)
    return np.linalg.inv(A)


def _probe(c) -> bool:
    """True when the compiled loops give numpy's bits on ``PROBE_SIZE`` random matrices of each kind."""
    ffi, lib = c
    fb = ffi.from_buffer
    rng = np.random.default_rng(20261202)
    n = PROBE_SIZE
    B = rng.normal(size=(n, 3, 2)) * 10.0 ** rng.uniform(-8, 8, (n, 1, 1))
    B[: n // 4, :, 0] = -0.0  # a zero column: zero products of either sign
    G = np.empty((n, 2, 2))
    lib.sd_gram2(n, 3, fb("double[]", B), fb("double[]", G))
    A = rng.normal(size=(n, 2, 2)) * 10.0 ** rng.uniform(-8, 8, (n, 1, 1))
    A[: n // 4, 1] = A[: n // 4, 0] * (1 + 1e-6 * rng.normal(size=(n // 4, 2)))  # near-singular
    y = rng.normal(size=(n, 2)) * 10.0 ** rng.uniform(-8, 8, (n, 1))
    F, x = np.empty((n, 5)), np.empty((n, 2))
    if lib.sd_lu2(n, fb("double[]", A), fb("double[]", F)) or lib.sd_solve2(
        n, fb("double[]", F), fb("double[]", y), fb("double[]", x)
    ):
        return False
    A3 = rng.normal(size=(n, 3, 3)) * 10.0 ** rng.uniform(-8, 8, (n, 1, 1))
    A3[: n // 4, 2] = A3[: n // 4, 0] * (1 + 1e-6 * rng.normal(size=(n // 4, 3)))  # near-singular
    y3, x3 = rng.normal(size=(n, 3)) * 10.0 ** rng.uniform(-8, 8, (n, 1)), np.empty((n, 3))
    if lib.sd_solve3(n, fb("double[]", A3), fb("double[]", y3), fb("double[]", x3)):
        return False
    return (
        same_bits(G, numpy_gram(B))
        and same_bits(x, np.linalg.solve(A, y[..., None])[..., 0])
        and same_bits(x3, np.linalg.solve(A3, y3[..., None])[..., 0])
    )


def same_bits(a, b) -> bool:
    """True when two float arrays are equal bit for bit (a zero's sign and a NaN's bits included)."""
    a, b = np.asarray(a), np.asarray(b)
    return (
        a.shape == b.shape
        and a.dtype == b.dtype
        and np.ascontiguousarray(a).tobytes() == np.ascontiguousarray(b).tobytes()
    )
