"""A fixed-point inverse kinematics for any :class:`~stewart_drake.core.geometry.Platform`, with a chosen
word length, to study word length against leg-length error.

It follows the firmware's recipe (``tp17.C``) generalised, not its exact instruction sequence:

1. angles -> fractions of pi in Q(f) words, f = word_bits - 1 (truncation toward zero, like FRAC16);
2. sin(pi x), cos(pi x) as Q(f) words: ``trig="exact"`` rounds the true value (1.0, i.e. cos 0, is stored
   as 2^f - 1: the table's rounding, not counted as a saturation), ``trig="tfr16"`` uses the DSP library
   (word_bits = 16 only);
3. each rotation-matrix entry as the firmware forms it: a sum of signed products of two or three
   sines/cosines, every product truncated back to Q(f) (``(a*b) >> f``, the ``extract_h(L_mult)``
   idiom), sums saturated to the word (the products are derived from the convention's elementary
   rotations, so ``utn`` and ``zyx`` both work);
4. lengths as integer words of ``length_lsb`` metres (anchors, rotation centre and position rounded to
   the nearest LSB); the plate anchor p + R r with each R·r product truncated as in 3 and the sums
   saturated to the word;
5. the squared length summed in a 2·word_bits accumulator (saturating) and its integer square root
   rounded to the nearer of y, y + 1 (the mfr32Sqrt rule), saturated to the word (a length beyond the
   word's range cannot be stored; mfr32Sqrt saturates likewise).

Saturations are recorded in any active :class:`~.q15.SaturationCounter` under ``generic.*`` names.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import product

import numpy as np

from stewart_drake.core.argcheck import as_poses, first_index
from stewart_drake.core.geometry import Platform
from stewart_drake.core.rotations import check_convention
from stewart_drake.errors import FixedPointError, counted
from stewart_drake.fixedpoint.q15 import counting, saturate, tfr16CosPIx, tfr16SinPIx

TRIG_MODES = ("exact", "tfr16")
BLOCK = 8192  # poses per block of leg_length_words: its (n,) int64 temporaries (64 kB) stay in cache


@dataclass(frozen=True)
class QFormat:
    """Word length and scaling of the generic fixed-point IK.

    word_bits   width of every data word, signed, 8..31 (the DSP: 16)
    length_lsb  metres per LSB of a length word (the DSP: 1e-3, integer millimetres)
    trig        ``exact`` (correctly rounded Q(word_bits-1) sine/cosine) or ``tfr16`` (the DSP library)
    """

    word_bits: int = 16
    length_lsb: float = 1e-3
    trig: str = "exact"

    def __post_init__(self):
        if not (isinstance(self.word_bits, (int, np.integer)) and 8 <= self.word_bits <= 31):
            raise FixedPointError(FixedPointError.WORD_BITS.format(value=self.word_bits))
        if not (np.isfinite(self.length_lsb) and self.length_lsb > 0):
            raise FixedPointError(FixedPointError.LENGTH_LSB.format(value=self.length_lsb))
        if self.trig not in TRIG_MODES:
            raise FixedPointError(FixedPointError.TRIG.format(valid=", ".join(TRIG_MODES), value=self.trig))
        if self.trig == "tfr16" and self.word_bits != 16:
            raise FixedPointError(FixedPointError.TFR16_BITS.format(value=self.word_bits))

    @property
    def frac_bits(self) -> int:
        return self.word_bits - 1

    @property
    def range_m(self) -> float:
        """The largest length a word holds (metres)."""
        return (2 ** (self.word_bits - 1) - 1) * self.length_lsb


# ------------------------------------------------------------------------------------------------
# Rotation matrices as sums of signed trig monomials, derived from the elementary rotations.
# A polynomial is a dict {tuple of factor names: integer coefficient}; factors are "cX", "sX" etc.


def _elementary(axis: str):
    c, s = f"c{axis}", f"s{axis}"
    one, zero = {(): 1}, {}
    pos, neg = {(s,): 1}, {(s,): -1}
    cc = {(c,): 1}
    if axis == "x":
        return [[one, zero, zero], [zero, cc, neg], [zero, pos, cc]]
    if axis == "y":
        return [[cc, zero, pos], [zero, one, zero], [neg, zero, cc]]
    return [[cc, neg, zero], [pos, cc, zero], [zero, zero, one]]


def _matmul(A, B):
    out = [[{} for _ in range(3)] for _ in range(3)]
    for i, j, k in product(range(3), range(3), range(3)):
        for (fa, ca), (fb, cb) in product(A[i][k].items(), B[k][j].items()):
            key = fa + fb
            out[i][j][key] = out[i][j].get(key, 0) + ca * cb
    return [[{k: v for k, v in e.items() if v} for e in row] for row in out]


def rotation_monomials(convention: str = "utn"):
    """3x3 nested lists of {factors: sign}: R_BT as sums of products of cx, sx, cy, sy, cz, sz (the
    factors in the order the elementary rotations multiply)."""
    check_convention(convention)
    order = ("y", "x", "z") if convention == "utn" else ("z", "y", "x")
    R = _elementary(order[0])
    for ax in order[1:]:
        R = _matmul(R, _elementary(ax))
    return R


# ------------------------------------------------------------------------------------------------


def angle_words(angles, fmt: QFormat) -> np.ndarray:
    """``(...)`` Q(word_bits-1) words of angles (radians) as fractions of pi: truncated toward zero like
    FRAC16, saturated. Raises ``FixedPointError`` for |angle| > pi."""
    angles = np.asarray(angles, dtype=float)
    f = fmt.frac_bits
    x = angles / np.pi
    k = first_index(np.abs(x) > 1.0)
    if k is not None:
        raise FixedPointError(FixedPointError.ANGLE.format(index=counted(k[:-1]), angle=angles[k]))
    return saturate(np.trunc(x * (1 << f)).astype(np.int64), -(1 << f), (1 << f) - 1, "generic.angle")


def trig_words(w, fmt: QFormat):
    """``(sin, cos)`` Q(word_bits-1) words of sin(pi x), cos(pi x) for angle words ``w`` (fractions of pi)."""
    w = np.asarray(w, dtype=np.int64)
    if fmt.trig == "tfr16":
        return tfr16SinPIx(w), tfr16CosPIx(w)
    f = fmt.frac_bits
    lo, hi = -(1 << f), (1 << f) - 1
    t = np.pi * w / (1 << f)
    # 1.0 is stored as the word's top: the table's rounding, not a saturation (not recorded)
    s = np.minimum(np.maximum(np.round(np.sin(t) * (1 << f)).astype(np.int64), lo), hi)
    c = np.minimum(np.maximum(np.round(np.cos(t) * (1 << f)).astype(np.int64), lo), hi)
    return s, c


def _trig_words(angles: np.ndarray, fmt: QFormat):
    return trig_words(angle_words(angles, fmt), fmt)


def fixed_point_rotation(angles, fmt: QFormat = QFormat(), convention: str = "utn") -> np.ndarray:
    """``(..., 3, 3)`` Q(word_bits-1) words of R_BT for ``(..., 3)`` angles (radians)."""
    return rotation_from_words(angle_words(angles, fmt), fmt, convention)


def rotation_from_words(w, fmt: QFormat = QFormat(), convention: str = "utn") -> np.ndarray:
    """``(..., 3, 3)`` Q(word_bits-1) words of R_BT for ``(..., 3)`` angle words (see ``angle_words``)."""
    w = np.asarray(w, dtype=np.int64)
    f = fmt.frac_bits
    lo, hi = -(1 << f), (1 << f) - 1
    s, c = trig_words(w, fmt)
    words = {}
    for k, ax in enumerate("xyz"):
        words[f"s{ax}"], words[f"c{ax}"] = s[..., k], c[..., k]
    S = w.shape[:-1]
    R = np.zeros(S + (3, 3), dtype=np.int64)
    for i, j in product(range(3), range(3)):
        acc = np.zeros(S, dtype=np.int64)
        for factors, coef in rotation_monomials(convention)[i][j].items():
            if not factors:  # the constant 1 (cannot occur in a 3-angle product, kept for safety)
                term = np.full(S, hi, dtype=np.int64)
            else:
                term = words[factors[0]]
                for fac in factors[1:]:
                    term = saturate((term * words[fac]) >> f, lo, hi, "generic.mult")
            for _ in range(abs(coef)):
                acc = saturate(acc + (term if coef > 0 else -term), lo, hi, "generic.add")
        R[..., i, j] = acc
    return R


def _isqrt_nearest(S: np.ndarray) -> np.ndarray:
    S = np.maximum(S, 0)
    y = np.floor(np.sqrt(S.astype(float))).astype(np.int64)
    y -= (y * y > S).astype(np.int64)
    y += ((y + 1) * (y + 1) <= S).astype(np.int64)
    return np.where(np.abs((y + 1) * (y + 1) - S) < np.abs(y * y - S), y + 1, y)


def length_words(x_m, fmt: QFormat, what: str) -> np.ndarray:
    """Integer words of lengths ``x_m`` (metres) in units of ``fmt.length_lsb``, rounded to nearest;
    raises ``FixedPointError`` naming ``what`` if one does not fit the word."""
    lsb, hi = fmt.length_lsb, (1 << fmt.frac_bits) - 1
    w = np.round(np.asarray(x_m) / lsb)
    if np.any(np.abs(w) > hi + 1):
        raise FixedPointError(
            FixedPointError.LENGTH_WORD.format(
                what=what,
                value=np.asarray(x_m).ravel()[np.argmax(np.abs(w).ravel())],
                bits=fmt.word_bits,
                lsb=lsb,
                range_m=fmt.range_m,
            )
        )
    return np.clip(w.astype(np.int64), -hi - 1, hi)


def platform_words(platform: Platform, fmt: QFormat) -> tuple[np.ndarray, np.ndarray]:
    """``(r_T, B)``: the ``(6, 3)`` plate-anchor offsets from the rotation centre and the base anchors as
    length words — the constants of the fixed-point IK (computed once, at generation time in C)."""
    r_T = length_words(platform.top_anchors_per_leg - platform.rotation_centre, fmt, "a plate anchor offset")
    B = length_words(platform.base_anchors, fmt, "a base anchor")
    return r_T, B


def pose_words(poses, fmt: QFormat = QFormat()) -> np.ndarray:
    """``(..., 6)`` int64 pose words of ``(..., 6)`` SI poses, as the firmware takes them: positions in
    length LSBs (rounded to nearest, saturated), angles as Q(word_bits-1) fractions of pi (truncated)."""
    q = as_poses(poses)
    f = fmt.frac_bits
    pos = saturate(np.round(q[..., :3] / fmt.length_lsb).astype(np.int64), -(1 << f), (1 << f) - 1, "generic.position")
    return np.concatenate([pos, angle_words(q[..., 3:], fmt)], axis=-1)


def leg_length_words(
    platform: Platform,
    words,
    fmt: QFormat = QFormat(),
    convention: str = "utn",
    consts: tuple[np.ndarray, np.ndarray] | None = None,
) -> np.ndarray:
    """``(..., 6)`` int64 leg-length words from ``(..., 6)`` pose words (``pose_words``): steps 3–5 of
    the recipe. ``consts``: ``platform_words`` if already computed. A length beyond the word saturates."""
    w = np.asarray(words, dtype=np.int64)
    consts = platform_words(platform, fmt) if consts is None else consts
    if w.ndim > 1 and w.size > 6 * BLOCK and not counting():
        # every step is per pose: blocks of poses give the same words with their temporaries in cache
        flat = w.reshape(-1, 6)
        out = np.empty(flat.shape, dtype=np.int64)
        for s in range(0, flat.shape[0], BLOCK):
            out[s : s + BLOCK] = _leg_length_words(flat[s : s + BLOCK], fmt, convention, consts)
        return out.reshape(w.shape)
    return _leg_length_words(w, fmt, convention, consts)


def _leg_length_words(
    w: np.ndarray, fmt: QFormat, convention: str, consts: tuple[np.ndarray, np.ndarray]
) -> np.ndarray:
    f = fmt.frac_bits
    lo, hi = -(1 << f), (1 << f) - 1
    r_T, B = consts
    pos = w[..., :3]
    R = rotation_from_words(w[..., 3:], fmt, convention)  # (..., 3, 3)
    S = w.shape[:-1]
    acc_hi = (1 << (2 * fmt.word_bits - 1)) - 1
    out = np.empty(S + (6,), dtype=np.int64)
    for i in range(6):
        sq = np.zeros(S, dtype=np.int64)
        for r in range(3):
            v = pos[..., r]
            for k in range(3):
                if r_T[i, k]:
                    v = saturate(v + ((R[..., r, k] * r_T[i, k]) >> f), lo, hi, "generic.add")
            v = saturate(v - B[i, r], lo, hi, "generic.sub")
            sq = saturate(sq + v * v, -acc_hi - 1, acc_hi, "generic.L_add")
        out[..., i] = saturate(_isqrt_nearest(sq), lo, hi, "generic.sqrt")
    return out


def fixed_point_leg_lengths(
    platform: Platform, poses, fmt: QFormat = QFormat(), convention: str = "utn", return_words: bool = False
) -> np.ndarray:
    """``(..., 6)`` leg lengths (metres, integer multiples of ``fmt.length_lsb``) computed in fixed
    point with ``fmt`` for ``(..., 6)`` SI poses. ``return_words``: the integer length words instead."""
    q = as_poses(poses)
    consts = platform_words(platform, fmt)
    out = leg_length_words(platform, pose_words(q, fmt), fmt, convention, consts)
    return out if return_words else out * fmt.length_lsb
