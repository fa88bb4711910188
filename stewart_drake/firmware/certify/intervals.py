"""Interval arithmetic for the certificate: exact on integer words (int64 numpy arrays, vectorised over
cells), outward-rounded on the float error terms.

Integer words: a pair ``(lo, hi)`` of int64 arrays; every operation of the firmware (product, floor
shift, sum, saturation, nearest integer square root) is monotone in each argument or evaluated at the
corners, so the integer intervals are exact hulls of the operation over the input intervals.

Floats: a pair ``(lo, hi)`` of float64 arrays. Every IEEE operation is correctly rounded (its exact
result lies within half an ulp), so moving each computed end one ulp outward (``np.nextafter``) keeps
the exact real result inside: the float intervals are rigorous enclosures, not estimates.
"""

from __future__ import annotations

import numpy as np

_INF = np.inf
# ``np.nextafter`` costs ~25 ns an element (a libm call each); on large arrays the same result comes from the
# bits: the int64 view of a float64 is monotone in its magnitude on each sign, so one ulp away from zero is
# ±1 on the view. Below this size numpy's call overhead dominates and nextafter itself is cheaper.
_BITS_FROM = 1024
_MIN = np.iinfo(np.int64).min  # the bits of -0.0
_POS_INF = np.float64(np.inf).view(np.int64)
_NEG_INF = np.float64(-np.inf).view(np.int64)


def down(x):
    """One ulp toward -inf: the lower end of an enclosure of a correctly rounded result (bit for bit
    ``np.nextafter(x, -inf)``, a test pins it on every class of float)."""
    if (x.size if isinstance(x, np.ndarray) else np.size(x)) < _BITS_FROM:  # np.size's dispatch costs ~1 µs
        return np.nextafter(x, -_INF)
    i = np.asarray(x, dtype=np.float64).view(np.int64)
    # x > 0: bits − 1; x < 0 (sign bit: i < 0): bits + 1 (in place: one temporary, three passes)
    r = i >> 63
    r |= 1
    np.subtract(i, r, out=r)
    f = r.view(np.float64)
    # +0 (→ bits −1) and −inf (→ bits + 1) land on NaN patterns, as NaN inputs do: only then the special cases
    if np.isnan(f.min()):
        # ±0 → −tiny; −inf stays (NaN stays NaN either way)
        f = np.where(i == 0, _MIN + 1, np.where(i == _NEG_INF, i, r)).view(np.float64)
    return f


def up(x):
    """One ulp toward +inf (bit for bit ``np.nextafter(x, inf)``)."""
    if (x.size if isinstance(x, np.ndarray) else np.size(x)) < _BITS_FROM:  # np.size's dispatch costs ~1 µs
        return np.nextafter(x, _INF)
    i = np.asarray(x, dtype=np.float64).view(np.int64)
    # x >= +0: bits + 1; x < 0: bits − 1 (toward zero)
    r = i >> 63
    r |= 1
    np.add(i, r, out=r)
    f = r.view(np.float64)
    # −0 (→ bits of int64 max) and +inf (→ bits + 1) land on NaN patterns, as NaN inputs do
    if np.isnan(f.min()):
        # −0 → +tiny; +inf stays
        f = np.where(i == _MIN, 1, np.where(i == _POS_INF, i, r)).view(np.float64)
    return f


def fadd(a, b):
    """Enclosure of a + b for float intervals a, b."""
    return down(a[0] + b[0]), up(a[1] + b[1])


def fsub(a, b):
    """Enclosure of a - b."""
    return down(a[0] - b[1]), up(a[1] - b[0])


def fmul(a, b):
    """Enclosure of a * b (the four corner products, each rounded outward)."""
    p = (a[0] * b[0], a[0] * b[1], a[1] * b[0], a[1] * b[1])
    if not all(isinstance(x, np.ndarray) and x.shape == p[0].shape for x in p):  # scalars or broadcast shapes
        return down(np.minimum(np.minimum(p[0], p[1]), np.minimum(p[2], p[3]))), up(
            np.maximum(np.maximum(p[0], p[1]), np.maximum(p[2], p[3]))
        )
    # the same minima and maxima, in the same operand order, into the products' own buffers (fewer
    # temporaries: the large leg arrays stay in cache)
    hi = np.maximum(p[0], p[1])
    lo = np.minimum(p[0], p[1], out=p[0])
    np.minimum(lo, np.minimum(p[2], p[3], out=p[1]), out=lo)
    np.maximum(hi, np.maximum(p[2], p[3], out=p[2]), out=hi)
    return down(lo), up(hi)


def fscale(a, c: float):
    """Enclosure of c * a for a float constant c (exact when c is a power of two)."""
    lo, hi = a[0] * c, a[1] * c
    if c < 0:
        lo, hi = hi, lo
    return down(lo), up(hi)


def fsquare(a):
    """Enclosure of a**2 (0 when a straddles 0)."""
    lo2, hi2 = a[0] * a[0], a[1] * a[1]
    straddle = (a[0] <= 0) & (a[1] >= 0)
    lo = np.where(straddle, 0.0, np.minimum(lo2, hi2))
    return np.maximum(down(lo), 0.0), up(np.maximum(lo2, hi2))


def fdiv_pos(a, d):
    """Enclosure of a / d for a divisor interval d with d[0] > 0."""
    q = (a[0] / d[0], a[0] / d[1], a[1] / d[0], a[1] / d[1])
    return down(np.minimum(np.minimum(q[0], q[1]), np.minimum(q[2], q[3]))), up(
        np.maximum(np.maximum(q[0], q[1]), np.maximum(q[2], q[3]))
    )


def fsqrt(a):
    """Enclosure of sqrt(a) for a >= 0 (negative lower ends clipped to 0)."""
    return np.maximum(down(np.sqrt(np.maximum(a[0], 0.0))), 0.0), up(np.sqrt(np.maximum(a[1], 0.0)))


def imul(a, b):
    """Exact hull of the integer products a * b (int64; the callers keep |a|, |b| < 2^31)."""
    p = (a[0] * b[0], a[0] * b[1], a[1] * b[0], a[1] * b[1])
    return np.minimum(np.minimum(p[0], p[1]), np.minimum(p[2], p[3])), np.maximum(
        np.maximum(p[0], p[1]), np.maximum(p[2], p[3])
    )


def isquare(a):
    """Exact hull of a**2 over an integer interval."""
    lo2, hi2 = a[0] * a[0], a[1] * a[1]
    straddle = (a[0] <= 0) & (a[1] >= 0)
    return np.where(straddle, 0, np.minimum(lo2, hi2)), np.maximum(lo2, hi2)


class RangeTable:
    """Range minimum and maximum queries on a fixed integer array (a sparse table: O(1) per query,
    ``len(values) * log2(len(values))`` int32 of memory). Used for the sine/cosine words and their
    errors over every angle-word interval: the exact hull, not a bound by monotone pieces.

    Level ``k`` holds the min (max) of every run of ``2^k`` values; the levels lie end to end in one flat
    array (level k from ``start[k]``), so a batch of queries is two gathers, whatever their lengths."""

    def __init__(self, values: np.ndarray, offset: int):
        v = np.asarray(values, dtype=np.int64)
        self.offset = offset
        self.size = v.size
        mins, maxs = [v.astype(np.int32)], [v.astype(np.int32)]
        k = 1
        while (1 << k) <= v.size:
            a, b = mins[-1], maxs[-1]
            h = 1 << (k - 1)
            mins.append(np.minimum(a[:-h], a[h:]))
            maxs.append(np.maximum(b[:-h], b[h:]))
            k += 1
        self.start = np.cumsum([0] + [x.size for x in mins[:-1]]).astype(np.int64)
        self.flat_min = np.concatenate(mins)
        self.flat_max = np.concatenate(maxs)

    def positions(self, lo, hi) -> tuple[np.ndarray, np.ndarray]:
        """The flat indices of the two overlapping runs covering ``values[lo - offset .. hi - offset]``
        (inclusive; lo <= hi): valid for every table of this size and offset."""
        i = np.asarray(lo, dtype=np.int64) - self.offset
        j = np.asarray(hi, dtype=np.int64) - self.offset
        # floor(log2(n)) exactly: frexp gives n = m 2^e with m in [0.5, 1) (n < 2^53 is a float exactly)
        k = np.frexp(j - i + 1)[1].astype(np.int64) - 1
        base = self.start[k]
        return base + i, base + j - (np.int64(1) << k) + 1

    def min_at(self, pos) -> np.ndarray:
        """The range minima at ``positions`` (int64)."""
        return np.minimum(self.flat_min[pos[0]], self.flat_min[pos[1]]).astype(np.int64)

    def max_at(self, pos) -> np.ndarray:
        """The range maxima at ``positions`` (int64)."""
        return np.maximum(self.flat_max[pos[0]], self.flat_max[pos[1]]).astype(np.int64)

    def query(self, lo, hi):
        """``(min, max)`` of ``values[lo - offset .. hi - offset]`` (inclusive), vectorised; lo <= hi."""
        pos = self.positions(lo, hi)
        return self.min_at(pos), self.max_at(pos)
