"""DSP56800E / ETSI fractional intrinsics, bit-exact, vectorised over numpy integer arrays.

Words are held in ``int64`` numpy arrays (or scalars) whose *values* are the DSP's two's-complement
words: a ``Word16``/``Frac16`` in [-32768, 32767], a ``Word32``/``Frac32`` in [-2^31, 2^31 - 1].
A ``Frac16`` x reads as the Q15 fraction x / 2^15, a ``Frac32`` as x / 2^31. Every function accepts
scalars or arrays (broadcast together) and returns ``int64``; the same input bits give the same output
bits whatever the shape. Inputs are *not* range-checked inside the intrinsics (that would cost as much
as the arithmetic): validate untrusted data once at the boundary with :func:`word16` / :func:`word32`.

Semantics are those of the CodeWarrior DSP56800E intrinsics (``intrinsics_56800E.h``), which assume
the OMR's SA bit set (saturation on) and R bit set (**two's-complement rounding**: add 0x8000 and
truncate, i.e. ties round toward +inf), and which equal the ETSI/ITU-T basic operators:

=============  =====================================================================================
FRAC16(x)      trunc(x * 32768) toward zero (C cast), saturated: x >= 1 -> 32767, x < -1 -> -32768
FRAC32(x)      trunc(x * 2^31), saturated likewise
add, sub       sat16(a +/- b)
negate         sat16(-a): negate(-32768) = 32767
abs_s          sat16(|a|): abs_s(-32768) = 32767
L_add, L_sub   sat32(a +/- b)
L_negate       sat32(-a);  L_abs: sat32(|a|)
L_mult         sat32(2ab): only -32768 * -32768 saturates (-> 0x7FFFFFFF)
L_mac, L_msu   sat32(acc +/- sat32(2ab))  (two saturations, ETSI order)
mult           sat16((a * b) >> 15): truncation toward -inf; -32768 * -32768 -> 32767
mult_r         sat16((a * b + 2^14) >> 15): rounding, ties toward +inf
extract_h      L >> 16 (arithmetic: the upper word; a truncation toward -inf of L / 2^16)
extract_l      the low 16 bits, reinterpreted as signed (wraps)
L_deposit_h    a << 16;  L_deposit_l: a (sign-extended)
round_         extract_h(L_add(L, 0x8000)): rounding, ties toward +inf, saturating (ETSI ``round``)
mac_r, msu_r   round_(L_mac(acc, a, b)), round_(L_msu(acc, a, b))
shl, shr       16-bit arithmetic shifts; shl saturates; a negative count shifts the other way;
               shr by >= 15 gives 0 or -1
L_shl, L_shr   the same on 32 bits (shr by >= 31 gives 0 or -1)
div_s          floor(a * 2^15 / b) for 0 <= a <= b, b > 0; div_s(a, a) = 32767
mfr32Sqrt      Freescale rtlib: the largest y in [0, 32767] with 2y^2 <= L (a 15-step bit search with
               ``mpy``), then y + 1 if |2(y+1)^2 - L| < |2y^2 - L| (nearest of the two); y + 1 is
               saturated (C reference ``mfr32SqrtC`` uses ``add``), so sqrt(0x7FFFFFFF) = 32767;
               L <= 0 gives 0. Reads as sqrt(L / 2^31) * 2^15.
tfr16SinPIx    Motorola/Freescale ``tfr16.c``: fold x to [0, 0.5], odd Taylor polynomial in x^2 with
               the seven coefficients FRAC16(c_k / 8) (Horner with ``mac_r``), times x with ``L_mult``,
               ``L_shl`` by 3, ``round_``; sign restored with ``negate``.
tfr16CosPIx    ``tfr16.c``: |x|, fold x > 0.5 to 1 - x with a sign flag, sin(pi (0.5 - x)) (+1 LSB on the
               folded branch), so cos(0) = 32767 (1.0 saturates), cos(+/-1) = -32764.
=============  =====================================================================================

Both library functions (mfr32Sqrt, tfr16SinPIx/CosPIx) were checked against the seed table: with them
the port of ``tp17.C`` reproduces all 24 DSP values exactly.

Saturation counting: ``with SaturationCounter() as sat: ...`` records, per intrinsic name, how many
elements saturated (clipped) inside the block; with ``shape=`` it also ORs a per-element mask of
where any saturation happened (flags that broadcast to ``shape``). Counters nest; the overhead when
none is active is one list test per call.
"""

from __future__ import annotations

from collections import Counter

import numpy as np

from stewart_drake.core.argcheck import first_index
from stewart_drake.errors import FixedPointError

MIN16, MAX16 = -(1 << 15), (1 << 15) - 1
MIN32, MAX32 = -(1 << 31), (1 << 31) - 1

_ACTIVE: list[SaturationCounter] = []


class SaturationCounter:
    """Counts saturations per intrinsic inside a ``with`` block.

    ``counts``: ``collections.Counter`` name -> number of saturated elements.
    ``mask``: with ``shape`` given, a boolean array of that shape, True where any recorded saturation
    flag (broadcast to ``shape``) was set; flags that do not broadcast are counted but not mapped.
    """

    def __init__(self, shape: tuple | None = None):
        self.counts: Counter = Counter()
        self.shape = None if shape is None else tuple(shape)
        self.mask = None if shape is None else np.zeros(self.shape, dtype=bool)

    @property
    def total(self) -> int:
        """Saturated elements over every intrinsic."""
        return int(sum(self.counts.values()))

    def record(self, op: str, flags) -> None:
        flags = np.asarray(flags, dtype=bool)
        n = int(np.count_nonzero(flags))
        if n:
            self.counts[op] += n
            if self.mask is not None:
                try:
                    self.mask |= np.broadcast_to(flags, self.shape)
                except ValueError:
                    pass

    def __enter__(self) -> SaturationCounter:
        _ACTIVE.append(self)
        return self

    def __exit__(self, *exc) -> None:
        _ACTIVE.remove(self)


def counting() -> bool:
    """Whether a ``SaturationCounter`` is active (a caller may then not split its arrays: a counter's mask
    maps flags of its own shape)."""
    return bool(_ACTIVE)


def saturate(x: np.ndarray, lo: int, hi: int, op: str) -> np.ndarray:
    """``x`` (int64, any shape) clipped to [lo, hi]; the elements that saturated are recorded under the
    operation name ``op`` by every active ``SaturationCounter``."""
    if _ACTIVE:
        flags = (x < lo) | (x > hi)
        for c in _ACTIVE:
            c.record(op, flags)
    return np.minimum(np.maximum(x, lo), hi)  # same result as np.clip, several times faster on small arrays


def _i(x) -> np.ndarray:
    return np.asarray(x, dtype=np.int64)


def sat16(x, op: str = "sat16") -> np.ndarray:
    """Saturate any integer to the Word16 range."""
    return saturate(_i(x), MIN16, MAX16, op)


def sat32(x, op: str = "sat32") -> np.ndarray:
    """Saturate any integer to the Word32 range."""
    return saturate(_i(x), MIN32, MAX32, op)


def word16(x, name: str = "value") -> np.ndarray:
    """Validate and convert to Word16 values: raises ``FixedPointError`` naming ``name`` and the first bad element."""
    a = np.asarray(x)
    if not np.issubdtype(a.dtype, np.integer):
        if not np.all(np.isfinite(a)) or np.any(a != np.round(a)):
            raise FixedPointError(
                FixedPointError.NOT_INTEGER_16.format(
                    name=name, value=a.ravel()[~np.isfinite(a.ravel()) | (a.ravel() != np.round(a.ravel()))][0]
                )
            )
    a = a.astype(np.int64)
    bad = (a < MIN16) | (a > MAX16)
    if np.any(bad):
        raise FixedPointError(
            FixedPointError.RANGE.format(name=name, value=int(a[bad].ravel()[0]), bits=16, lo=MIN16, hi=MAX16)
        )
    return a


def word32(x, name: str = "value") -> np.ndarray:
    """Validate and convert to Word32 values (see :func:`word16`)."""
    a = np.asarray(x)
    if not np.issubdtype(a.dtype, np.integer):
        if not np.all(np.isfinite(a)) or np.any(a != np.round(a)):
            raise FixedPointError(FixedPointError.NOT_INTEGER_32.format(name=name))
    a = a.astype(np.int64)
    bad = (a < MIN32) | (a > MAX32)
    if np.any(bad):
        raise FixedPointError(
            FixedPointError.RANGE.format(name=name, value=int(a[bad].ravel()[0]), bits=32, lo=MIN32, hi=MAX32)
        )
    return a


# ------------------------------------------------------------------------------------------------
# Conversions


def FRAC16(x) -> np.ndarray:
    """Q15 word of a real x (any shape): C's ``(Frac16)(x * 0x8000)``, i.e. truncation toward zero,
    with x >= 1 -> 32767 and x < -1 -> -32768 (the Freescale macro's saturation)."""
    x = np.asarray(x, dtype=float)
    if not np.all(np.isfinite(x)):
        raise FixedPointError(
            FixedPointError.FRAC16_NOT_FINITE.format(value=x[~np.isfinite(x)].ravel()[0] if x.ndim else float(x))
        )
    return saturate(np.trunc(x * 32768.0).astype(np.int64), MIN16, MAX16, "FRAC16")


def FRAC32(x) -> np.ndarray:
    """Q31 word of a real x: truncation toward zero, saturated to [-2^31, 2^31 - 1]."""
    x = np.asarray(x, dtype=float)
    if not np.all(np.isfinite(x)):
        raise FixedPointError(FixedPointError.FRAC32_NOT_FINITE)
    return saturate(np.trunc(np.clip(x, -2.0, 2.0) * 2147483648.0).astype(np.int64), MIN32, MAX32, "FRAC32")


def to_float16(w) -> np.ndarray:
    """Q15 word(s) -> float fraction w / 2^15."""
    return _i(w) / 32768.0


def to_float32(w) -> np.ndarray:
    """Q31 word(s) -> float fraction w / 2^31."""
    return _i(w) / 2147483648.0


# ------------------------------------------------------------------------------------------------
# 16-bit operators


def add(a, b) -> np.ndarray:
    """sat16(a + b)."""
    return saturate(_i(a) + _i(b), MIN16, MAX16, "add")


def sub(a, b) -> np.ndarray:
    """sat16(a - b)."""
    return saturate(_i(a) - _i(b), MIN16, MAX16, "sub")


def negate(a) -> np.ndarray:
    """sat16(-a); negate(-32768) = 32767."""
    return saturate(-_i(a), MIN16, MAX16, "negate")


def abs_s(a) -> np.ndarray:
    """sat16(|a|); abs_s(-32768) = 32767."""
    return saturate(np.abs(_i(a)), MIN16, MAX16, "abs_s")


def mult(a, b) -> np.ndarray:
    """sat16((a*b) >> 15): Q15 product truncated toward -inf; only -32768*-32768 saturates."""
    return saturate((_i(a) * _i(b)) >> 15, MIN16, MAX16, "mult")


def mult_r(a, b) -> np.ndarray:
    """sat16((a*b + 2^14) >> 15): Q15 product rounded, ties toward +inf."""
    return saturate((_i(a) * _i(b) + (1 << 14)) >> 15, MIN16, MAX16, "mult_r")


def shl(a, n) -> np.ndarray:
    """16-bit arithmetic shift left by n with saturation; n < 0 shifts right (see :func:`shr`)."""
    a, n = np.broadcast_arrays(_i(a), _i(n))
    left = np.clip(n, 0, 16)
    right = np.clip(-n, 0, 15)
    return np.where(n >= 0, saturate(a << left, MIN16, MAX16, "shl"), a >> right)


def shr(a, n) -> np.ndarray:
    """16-bit arithmetic shift right by n (toward -inf; n >= 15 gives 0 or -1); n < 0 shifts left, saturating."""
    return shl(a, -_i(n))


# ------------------------------------------------------------------------------------------------
# 32-bit operators


def L_add(a, b) -> np.ndarray:
    """sat32(a + b)."""
    return saturate(_i(a) + _i(b), MIN32, MAX32, "L_add")


def L_sub(a, b) -> np.ndarray:
    """sat32(a - b)."""
    return saturate(_i(a) - _i(b), MIN32, MAX32, "L_sub")


def L_negate(a) -> np.ndarray:
    """sat32(-a); L_negate(-2^31) = 2^31 - 1."""
    return saturate(-_i(a), MIN32, MAX32, "L_negate")


def L_abs(a) -> np.ndarray:
    """sat32(|a|)."""
    return saturate(np.abs(_i(a)), MIN32, MAX32, "L_abs")


def L_mult(a, b) -> np.ndarray:
    """sat32(2ab): the Q31 product of two Q15 words; only -32768 * -32768 saturates."""
    return saturate(2 * _i(a) * _i(b), MIN32, MAX32, "L_mult")


def L_mac(acc, a, b) -> np.ndarray:
    """L_add(acc, L_mult(a, b))."""
    return L_add(acc, L_mult(a, b))


def L_msu(acc, a, b) -> np.ndarray:
    """L_sub(acc, L_mult(a, b))."""
    return L_sub(acc, L_mult(a, b))


def L_shl(a, n) -> np.ndarray:
    """32-bit arithmetic shift left by n with saturation; n < 0 shifts right."""
    a, n = np.broadcast_arrays(_i(a), _i(n))
    left = np.clip(n, 0, 32)
    right = np.clip(-n, 0, 31)
    # a << 32 overflows int64 only for |a| >= 2^31, which a Word32 never is.
    return np.where(n >= 0, saturate(a << left, MIN32, MAX32, "L_shl"), a >> right)


def L_shr(a, n) -> np.ndarray:
    """32-bit arithmetic shift right by n (n >= 31 gives 0 or -1); n < 0 shifts left, saturating."""
    return L_shl(a, -_i(n))


def extract_h(L) -> np.ndarray:
    """The upper 16 bits of a Word32: L >> 16 (arithmetic), i.e. floor(L / 2^16)."""
    return _i(L) >> 16


def extract_l(L) -> np.ndarray:
    """The lower 16 bits of a Word32 as a signed word (wraps, no saturation)."""
    return ((_i(L) & 0xFFFF) ^ 0x8000) - 0x8000


def L_deposit_h(a) -> np.ndarray:
    """a << 16 (a Word16 into the upper half, low half zero)."""
    return _i(a) << 16


def L_deposit_l(a) -> np.ndarray:
    """a sign-extended to 32 bits."""
    return _i(a)


def round_(L) -> np.ndarray:
    """extract_h(L_add(L, 0x8000)): round a Q31 to Q15, ties toward +inf, saturating (ETSI ``round``)."""
    return L_add(L, 0x8000) >> 16


def mac_r(acc, a, b) -> np.ndarray:
    """round_(L_mac(acc, a, b))."""
    return round_(L_mac(acc, a, b))


def msu_r(acc, a, b) -> np.ndarray:
    """round_(L_msu(acc, a, b))."""
    return round_(L_msu(acc, a, b))


def div_s(a, b) -> np.ndarray:
    """Q15 quotient a / b for 0 <= a <= b, b > 0: floor(a * 2^15 / b), and 32767 when a == b.
    Raises ``FixedPointError`` outside that domain (the hardware result is undefined there)."""
    a, b = np.broadcast_arrays(_i(a), _i(b))
    bad = (a < 0) | (b <= 0) | (a > b)
    k = first_index(bad)
    if k is not None:
        raise FixedPointError(FixedPointError.DIV_S.format(a=int(a[k]), b=int(b[k])))
    return np.where(a == b, MAX16, (a << 15) // np.where(b == 0, 1, b))


# ------------------------------------------------------------------------------------------------
# Library functions (mfr32Sqrt, tfr16SinPIx, tfr16CosPIx)


def mfr32Sqrt(L) -> np.ndarray:
    """16-bit square root of a Frac32: sqrt(L / 2^31) * 2^15, as the Freescale rtlib computes it
    (see the module table). Exact integer arithmetic; L <= 0 gives 0."""
    L = _i(L)
    half = np.maximum(L, 0) >> 1  # 2y^2 <= L  <=>  y^2 <= floor(L / 2)
    y = np.floor(np.sqrt(half.astype(float))).astype(np.int64)
    y -= (y * y > half).astype(np.int64)  # correct the float estimate by one LSB either way
    y += ((y + 1) * (y + 1) <= half).astype(np.int64)
    y = np.minimum(y, MAX16)
    yr = np.minimum(y + 1, MAX16)
    use_r = np.abs(L - 2 * yr * yr) < np.abs(L - 2 * y * y)
    return np.where(use_r, yr, y)


_SINE_COEFS = (
    0.39269908169872,
    -0.64596409750625,
    0.31877050498467,
    -0.07446482317004,
    0.01026823582639,
    -0.00092130386821,
    0.00005828785072,
)


def _sinpix_poly(x) -> np.ndarray:
    """tfr16SinPIx evaluated operation by operation (the reference the lookup table is built from)."""
    c = [int(v) for v in FRAC16(np.array(_SINE_COEFS))]
    x = _i(x)
    neg = x < 0
    x = np.where(neg, negate(x), x)
    x = np.where(x > FRAC16(0.5), sub(FRAC16(1.0), x), x)
    z = mult_r(x, x)
    t = mac_r(L_deposit_h(c[5]), z, c[6])
    for k in range(4, -1, -1):
        t = mac_r(L_deposit_h(c[k]), t, z)
    r = round_(L_shl(L_mult(t, x), 3))
    return np.where(neg, negate(r), r)


def _cospix_poly(x) -> np.ndarray:
    """tfr16CosPIx evaluated operation by operation."""
    x = _i(x)
    x = np.where(x < 0, negate(x), x)
    fold = x > FRAC16(0.5)
    x = np.where(fold, sub(FRAC16(1.0), x), x)
    x = sub(FRAC16(0.5), x)
    x = np.where(fold, add(x, 1), x)
    z = _sinpix_poly(x)
    return np.where(fold, negate(z), z)


_ALL16 = np.arange(MIN16, MAX16 + 1, dtype=np.int64)
_LUT: dict[str, np.ndarray] = {}


def _lut(name: str) -> np.ndarray:
    if name not in _LUT:
        saved = _ACTIVE[:]
        _ACTIVE.clear()  # building the table is not the caller's arithmetic
        try:
            _LUT[name] = (_sinpix_poly if name == "sin" else _cospix_poly)(_ALL16)
        finally:
            _ACTIVE[:] = saved
    return _LUT[name]


def tfr16SinPIx(x) -> np.ndarray:
    """sin(pi x) of a Q15 word, Q15 result, bit-exact to ``tfr16.c`` (evaluated once for all 65536
    inputs and then looked up). Never saturates: |result| <= 32767."""
    return _lut("sin")[_i(x) - MIN16]


def tfr16CosPIx(x) -> np.ndarray:
    """cos(pi x) of a Q15 word, Q15 result, bit-exact to ``tfr16.c``: cos(0) = 32767 (1.0 is not
    representable), cos(-1) = -32764 (the polynomial is a few LSB short of 1 near its peak)."""
    return _lut("cos")[_i(x) - MIN16]


# The Processor Expert bean names used in tp17.C.
TFR1_tfr16SinPIx = tfr16SinPIx
TFR1_tfr16CosPIx = tfr16CosPIx

INTRINSICS = (
    "FRAC16",
    "FRAC32",
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
