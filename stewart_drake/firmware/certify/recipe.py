"""The generated ``sd_ik`` recipe (``fixedpoint.generic``, emitted by ``firmware.generate``) evaluated over
boxes of pose words instead of single poses.

For a batch of cells (boxes of integer pose words) it returns, for every word of the ``sd_ik_trace``
layout (``firmware.check.trace_names``), the exact hull of its value before saturation, whether any
saturating operation that builds it may clip (``possible``) or clips at every pose of the cell
(``certain``), and for every leg an enclosure of ``L_words - L_true`` in length LSBs, where ``L_true`` is
the exact IK of the platform at the pose the words represent. The recipe's shape comes from the same
places the emulation and the generator take it: the monomials of ``generic.rotation_monomials``, the
constants of ``generic.platform_words``, the trig words of ``generic.trig_words`` (tabulated over every
angle word) and the ``QFormat``. A cell of one pose gives the emulation's words exactly (a test pins it).

Error propagation (errors in LSBs; word = true + error):

- sin/cos: the table's own error over the cell's angle words (exact hull of ``word - 2^f sin(pi w / 2^f)``);
- product ``floor(a b / 2^f)``: ``(a eb + B ea) / 2^f - t``, t in [0, 1) (B the true value of b);
- leg term ``floor(R c / 2^f)`` with the rounded constant c of the true ct: ``(R_true (c - ct) + eR c) / 2^f - t``;
- sums add errors; the base anchor subtracts its rounding ``c - ct``;
- ``v^2``: ``2 V ev + ev^2``; the length: ``(isqrt_near(s) - sqrt(s)) + (s - S) / (sqrt(s) + sqrt(S))``,
  the first in [-1/2, 1/2 + 1/(8 (y + 1/2))] for the nearest-of-two rule (y = floor(sqrt(s))).

An error enclosure is valid where no saturation is possible in the leg's chain; elsewhere it is unbounded.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from stewart_drake.core.geometry import Platform
from stewart_drake.firmware.certify.intervals import (
    RangeTable,
    down,
    fadd,
    fdiv_pos,
    fmul,
    fscale,
    fsqrt,
    fsquare,
    fsub,
    imul,
    isquare,
    up,
)
from stewart_drake.fixedpoint.generic import QFormat, platform_words, rotation_monomials, trig_words

ERR_UNIT = 2.0**-24  # the trig error tables hold multiples of this (LSB), rounded outward
AXES = "xyz"


def isqrt_nearest(S: np.ndarray) -> np.ndarray:
    """The nearer of y, y + 1 (by squares) to sqrt(S), y the largest with y^2 <= S: the emulation's rule."""
    S = np.maximum(np.asarray(S, dtype=np.int64), 0)
    y = np.floor(np.sqrt(S.astype(float))).astype(np.int64)
    y -= (y * y > S).astype(np.int64)
    y += ((y + 1) * (y + 1) <= S).astype(np.int64)
    return np.where(np.abs((y + 1) * (y + 1) - S) < np.abs(y * y - S), y + 1, y)


@dataclass
class TrigTables:
    """Range tables over every angle word: the sine/cosine words before their clamp (``pre``) and their
    errors against 2^f sin(pi w / 2^f) in ``ERR_UNIT`` (floor for the lower table, ceil for the upper).
    All six have the same size and offset: one ``positions`` serves them all."""

    sin_pre: RangeTable
    cos_pre: RangeTable
    sin_err_lo: RangeTable
    sin_err_hi: RangeTable
    cos_err_lo: RangeTable
    cos_err_hi: RangeTable


@lru_cache(maxsize=4)
def trig_tables(word_bits: int, trig: str) -> TrigTables:
    """The tables of one format (built once; ~36 MB for 16-bit words)."""
    fmt = QFormat(word_bits, 1.0, trig)
    f = fmt.frac_bits
    w = np.arange(-(1 << f), 1 << f, dtype=np.int64)
    s, c = trig_words(w, fmt)
    t = np.pi * w / (1 << f)
    if trig == "exact":  # the emulation's words before its clamp (generic.trig_words rounds, then clamps 1.0)
        s_pre = np.round(np.sin(t) * (1 << f)).astype(np.int64)
        c_pre = np.round(np.cos(t) * (1 << f)).astype(np.int64)
        if np.any(np.clip(s_pre, -(1 << f), (1 << f) - 1) != s) or np.any(np.clip(c_pre, -(1 << f), (1 << f) - 1) != c):
            raise RuntimeError("trig table differs from generic.trig_words")  # internal: the recipe drifted
    else:
        s_pre, c_pre = s, c
    # the double sin/cos err by < 1e-11 LSB here; one ERR_UNIT (6e-8 LSB) of margin each side covers it
    es = (s - np.sin(t) * (1 << f)) / ERR_UNIT
    ec = (c - np.cos(t) * (1 << f)) / ERR_UNIT
    off = -(1 << f)
    return TrigTables(
        RangeTable(s_pre, off),
        RangeTable(c_pre, off),
        RangeTable(np.floor(es) - 1, off),
        RangeTable(np.ceil(es) + 1, off),
        RangeTable(np.floor(ec) - 1, off),
        RangeTable(np.ceil(ec) + 1, off),
    )


@dataclass
class Model:
    """Everything the recipe needs for one platform and format: word constants and the true constants
    (in LSBs, as float enclosures) of the plate-anchor offsets and base anchors."""

    platform: Platform
    fmt: QFormat
    convention: str
    r_T: np.ndarray  # (6, 3) int64 words
    B: np.ndarray  # (6, 3) int64 words
    r_T_true: tuple  # ((6, 3), (6, 3)) float enclosure, LSB
    B_true: tuple
    monomials: list = field(repr=False)
    tables: TrigTables = field(repr=False)

    @classmethod
    def build(cls, platform: Platform, fmt: QFormat, convention: str = "utn") -> Model:
        r_T, B = platform_words(platform, fmt)
        rt = (platform.top_anchors_per_leg - platform.rotation_centre) / fmt.length_lsb
        bt = np.asarray(platform.base_anchors, dtype=float) / fmt.length_lsb
        return cls(
            platform,
            fmt,
            convention,
            r_T,
            B,
            (down(rt), up(rt)),
            (down(bt), up(bt)),
            rotation_monomials(convention),
            trig_tables(fmt.word_bits, fmt.trig),
        )

    @property
    def free_axis(self) -> int:
        """The angle every rotation entry holds at most one factor of (the middle rotation)."""
        for k, ax in enumerate(AXES):
            if all(
                len({fac for factors in e for fac in factors if fac[1] == ax}) <= 1
                for row in self.monomials
                for e in row
            ):
                return k
        raise RuntimeError("no rotation angle enters every entry once")  # internal: not an Euler product

    @property
    def lo(self) -> int:
        return -(1 << self.fmt.frac_bits)

    @property
    def hi(self) -> int:
        return (1 << self.fmt.frac_bits) - 1

    @property
    def acc_hi(self) -> int:
        return (1 << (2 * self.fmt.word_bits - 1)) - 1


def word_names() -> list[str]:
    """The trace layout's names (``firmware.check.trace_names``) in their order."""
    names = [f"pose[{k}]" for k in range(6)] + [f"sin.{a}" for a in AXES] + [f"cos.{a}" for a in AXES]
    names += [f"R[{i}][{j}]" for i in range(3) for j in range(3)]
    names += [f"leg{i + 1}.{a}" for i in range(6) for a in AXES]
    names += [f"sq{i + 1}" for i in range(6)] + [f"length{i + 1}" for i in range(6)]
    return names


# trig words clamp by design (cos 0 = 1.0 is not representable): their error is within the table's
# certified error, so their clamp is reported but is not a saturation of the arithmetic
BENIGN = {f"{t}.{a}" for t in ("sin", "cos") for a in AXES}


class IV:
    """An interval quantity of the recipe: integer word hull, error and true-value enclosures (LSB)."""

    __slots__ = ("w", "e", "t")

    def __init__(self, w, e, t):
        self.w, self.e, self.t = w, e, t


@dataclass
class CellEval:
    """The recipe over ``n`` cells: per trace word the hull before saturation (``pre_lo``, ``pre_hi``:
    (n, W) int64) and the clamp flags (``possible``, ``certain``: (n, W) bool); per leg the error
    enclosure in LSB (``err_lo``, ``err_hi``: (n, 6); infinite where a saturation is possible)."""

    pre_lo: np.ndarray
    pre_hi: np.ndarray
    possible: np.ndarray
    certain: np.ndarray
    err_lo: np.ndarray
    err_hi: np.ndarray

    def post(self, model: Model) -> tuple[np.ndarray, np.ndarray]:
        """The words' hulls after saturation (what the trace holds; ``sq`` capped at the accumulator)."""
        lo_b, hi_b = _bounds(model)
        return np.clip(self.pre_lo, lo_b, hi_b), np.clip(self.pre_hi, lo_b, hi_b)

    @property
    def err_abs(self) -> np.ndarray:
        """(n, 6) bound on |L_words - L_true|, LSB."""
        return np.maximum(np.abs(self.err_lo), np.abs(self.err_hi))


def _bounds(model: Model):
    names = word_names()
    lo_b = np.array([-model.acc_hi - 1 if n.startswith("sq") else model.lo for n in names], dtype=np.int64)
    hi_b = np.array([model.acc_hi if n.startswith("sq") else model.hi for n in names], dtype=np.int64)
    return lo_b, hi_b


class Recorder:
    """Per cell and trace word: the hull before saturation and the clamp flags, as (n, W) arrays.

    They are the transposes of word-major (W, n) arrays: the recipe writes one word (or six) over all cells
    at a time, and a word's column is then contiguous in memory (a cell-major column is strided by W)."""

    def __init__(self, n: int, model: Model):
        self._allocate(n, word_names())

    def _allocate(self, n: int, names: list[str]) -> None:
        self.names = names
        self.index = {k: i for i, k in enumerate(self.names)}
        W = len(self.names)
        self.pre_lo = np.zeros((W, n), dtype=np.int64).T
        self.pre_hi = np.zeros((W, n), dtype=np.int64).T
        self.possible = np.zeros((W, n), dtype=bool).T
        self.certain = np.zeros((W, n), dtype=bool).T

    def sat(self, name: str, lo, hi, wlo: int, whi: int, final: bool = False):
        """Clamp the hull [lo, hi] to [wlo, whi], recording the flags (and the hull when ``final``)."""
        k = self.index[name]
        self.possible[:, k] |= (hi > whi) | (lo < wlo)
        self.certain[:, k] |= (lo > whi) | (hi < wlo)
        if final:
            self.pre_lo[:, k], self.pre_hi[:, k] = lo, hi
        # np.minimum/np.maximum: the same clamp as np.clip without its per-call overhead (hot: ~100 calls a cell batch)
        return np.minimum(np.maximum(lo, wlo), whi), np.minimum(np.maximum(hi, wlo), whi)

    def sat_legs(self, idx, lo, hi, wlo: int, whi: int, final: bool = False, mask=None):
        """``sat`` of the six words ``idx`` (6,) at once on (6, n) hulls (legs first); only the legs where ``mask``
        (6, 1) record their clamp flags (all when None)."""
        possible, certain = (hi > whi) | (lo < wlo), (lo > whi) | (hi < wlo)
        if mask is not None:
            possible, certain = possible & mask, certain & mask
        self.possible[:, idx] |= possible.T
        self.certain[:, idx] |= certain.T
        if final:
            self.pre_lo[:, idx], self.pre_hi[:, idx] = lo.T, hi.T
        return np.minimum(np.maximum(lo, wlo), whi), np.minimum(np.maximum(hi, wlo), whi)

    def flag(self, name: str):
        return self.possible[:, self.index[name]]


def mulq(a: IV, b: IV, f: int, rec: Recorder, name: str, m: Model) -> IV:
    lo, hi = imul(a.w, b.w)
    w = rec.sat(name, lo >> f, hi >> f, m.lo, m.hi)
    af = (a.w[0].astype(float), a.w[1].astype(float))
    e = fscale(fadd(fmul(af, b.e), fmul(b.t, a.e)), 2.0**-f)
    e = fsub(e, (0.0, 1.0))
    t = fscale(fmul(a.t, b.t), 2.0**-f)
    return IV(w, e, t)


def addw(
    acc: IV, term: IV, sign: int, rec: Recorder, name: str, m: Model, final: bool, bound: float | None = None
) -> IV:
    if sign > 0:
        lo, hi = acc.w[0] + term.w[0], acc.w[1] + term.w[1]
        e, t = fadd(acc.e, term.e), fadd(acc.t, term.t)
    else:
        lo, hi = acc.w[0] - term.w[1], acc.w[1] - term.w[0]
        e, t = fsub(acc.e, term.e), fsub(acc.t, term.t)
    if bound is not None:
        # the true value is bounded by geometry (|R_ij| <= 1): true in [-bound, bound]; where nothing before
        # clamped, word = true + error exactly, so the integer word lies in [ceil(t + e), floor(t + e)]
        t = (np.maximum(t[0], -bound), np.minimum(t[1], bound))
        clean = ~rec.flag(name)
        te = fadd(t, e)
        lo = np.where(clean, np.maximum(lo, np.ceil(te[0]).astype(np.int64)), lo)
        hi = np.where(clean, np.minimum(hi, np.floor(te[1]).astype(np.int64)), hi)
    return IV(rec.sat(name, lo, hi, m.lo, m.hi, final), e, t)


def evaluate(model: Model, cell_lo: np.ndarray, cell_hi: np.ndarray) -> CellEval:
    """The recipe over ``(n, 6)`` cells of pose words ``[cell_lo, cell_hi]`` (inclusive, int64)."""
    cell_lo = np.asarray(cell_lo, dtype=np.int64)
    cell_hi = np.asarray(cell_hi, dtype=np.int64)
    n = cell_lo.shape[0]
    m, f = model, model.fmt.frac_bits
    rec = Recorder(n, m)
    zero_f = (np.zeros(n), np.zeros(n))
    for k in range(6):
        rec.pre_lo[:, k], rec.pre_hi[:, k] = cell_lo[:, k], cell_hi[:, k]
    # -- sine and cosine words: exact hulls over the cell's angle words, with their errors
    tb = m.tables
    trig = {}
    for k, ax in enumerate(AXES):
        pos = tb.sin_pre.positions(cell_lo[:, 3 + k], cell_hi[:, 3 + k])  # the same for the six tables
        for name, pre, elo_t, ehi_t in (
            ("s", tb.sin_pre, tb.sin_err_lo, tb.sin_err_hi),
            ("c", tb.cos_pre, tb.cos_err_lo, tb.cos_err_hi),
        ):
            label = f"{'sin' if name == 's' else 'cos'}.{ax}"
            w = rec.sat(label, pre.min_at(pos), pre.max_at(pos), m.lo, m.hi, final=True)
            e = (elo_t.min_at(pos) * ERR_UNIT, ehi_t.max_at(pos) * ERR_UNIT)
            t = fsub((w[0].astype(float), w[1].astype(float)), e)
            trig[f"{name}{ax}"] = IV(w, e, t)
    # -- rotation entries: sums of truncated products, as rotation_from_words forms them
    R = {}
    zero_i = (np.zeros(n, dtype=np.int64), np.zeros(n, dtype=np.int64))
    for i in range(3):
        for j in range(3):
            name = f"R[{i}][{j}]"
            acc = IV(zero_i, zero_f, zero_f)
            items = list(model.monomials[i][j].items())
            adds = sum(abs(c) for _, c in items)
            done = 0
            for factors, coef in items:
                term = trig[factors[0]]
                for fac in factors[1:]:
                    term = mulq(term, trig[fac], f, rec, name, m)
                for _ in range(abs(coef)):
                    done += 1
                    last = done == adds
                    acc = addw(acc, term, coef, rec, name, m, last, float(1 << f) if last else None)
            if adds == 0:
                rec.pre_lo[:, rec.index[name]] = 0
                rec.pre_hi[:, rec.index[name]] = 0
            R[(i, j)] = acc
    exact_rotation(model, cell_lo, cell_hi, rec)
    r_sat = np.zeros(n, dtype=bool)
    for i in range(3):
        for j in range(3):
            r_sat |= rec.flag(f"R[{i}][{j}]")
    # -- legs: v = p + sum_k floor(R_rk c_ik / 2^f) - b, saturated; sq = sum v^2; L = isqrt_near(sq).
    # The six legs at once, (6, n) arrays: every operation is elementwise, so each leg's words and enclosures
    # are bit for bit those of a loop over the legs; a leg whose constant is 0 takes the other branch by mask
    # (its clamp is not recorded), as the loop's ``if`` did.
    err_lo, err_hi = _legs(m, cell_lo, cell_hi, R, r_sat, rec)
    return CellEval(rec.pre_lo, rec.pre_hi, rec.possible, rec.certain, err_lo, err_hi)


def _legs(m: Model, cell_lo: np.ndarray, cell_hi: np.ndarray, R: dict, r_sat: np.ndarray, rec: Recorder):
    """The leg chains of ``evaluate`` for all six legs at once: ``(err_lo, err_hi)`` (n, 6), infinite where a
    saturation is possible in the leg's chain (recorded in ``rec``). Arrays are (6, n), legs first, so that
    numpy's inner loops run over the cells (an inner axis of 6 is slow to broadcast)."""
    n, f = cell_lo.shape[0], m.fmt.frac_bits
    zero_i = (np.zeros((6, n), dtype=np.int64), np.zeros((6, n), dtype=np.int64))
    zero_f = (np.zeros((6, n)), np.zeros((6, n)))
    col = {
        k: IV(tuple(x[None, :] for x in R[k].w), tuple(x[None, :] for x in R[k].e), tuple(x[None, :] for x in R[k].t))
        for k in R
    }
    sq_w, sq_e, sq_t = zero_i, zero_f, zero_f
    idx_of = rec.index
    flags = np.zeros((6, n), dtype=bool)  # a clamp possible in the leg's own words (legs, sq, length)
    for r in range(3):
        idx = np.array([idx_of[f"leg{i + 1}.{AXES[r]}"] for i in range(6)])
        pw = (np.broadcast_to(cell_lo[None, :, r], (6, n)), np.broadcast_to(cell_hi[None, :, r], (6, n)))
        v = IV(pw, zero_f, (pw[0].astype(float), pw[1].astype(float)))
        for k in range(3):
            c = m.r_T[:, k, None].astype(np.int64)  # (6, 1)
            nz = c != 0
            ct = (m.r_T_true[0][:, k, None], m.r_T_true[1][:, k, None])
            Rk = col[(r, k)]
            contrib_t = fscale(fmul(Rk.t, ct), 2.0**-f)
            # c == 0: the firmware omits a term that rounds to zero: its true value is all error
            omit = IV(v.w, fsub(v.e, contrib_t), fadd(v.t, contrib_t)) if not nz.all() else None
            if nz.any():  # c != 0: the term floor(R c / 2^f), error (R_true (c - ct) + eR c) / 2^f - t, added
                lo, hi = imul(Rk.w, (c, c))
                cf = c.astype(float)
                dc = fsub((cf, cf), ct)
                e_lo, e_hi = Rk.e[0] * cf, Rk.e[1] * cf  # fscale(Rk.e, c) with the sign of each leg's c
                eRc = (down(np.where(cf < 0, e_hi, e_lo)), up(np.where(cf < 0, e_lo, e_hi)))
                e = fsub(fscale(fadd(fmul(Rk.t, dc), eRc), 2.0**-f), (0.0, 1.0))
                w = rec.sat_legs(idx, v.w[0] + (lo >> f), v.w[1] + (hi >> f), m.lo, m.hi, mask=nz)
                v = IV(w, fadd(v.e, e), fadd(v.t, contrib_t))
                if omit is not None:  # legs of both kinds: each takes its own branch
                    v = IV(
                        *(
                            tuple(np.where(nz, a, b) for a, b in zip(x, y, strict=True))
                            for x, y in ((v.w, omit.w), (v.e, omit.e), (v.t, omit.t))
                        )
                    )
            else:
                v = omit
        b = m.B[:, r, None].astype(np.int64)
        nzb = b != 0
        bt = (m.B_true[0][:, r, None], m.B_true[1][:, r, None])
        lo, hi = v.w[0] - b, v.w[1] - b  # b == 0: the word itself, recorded, never clamped
        w = rec.sat_legs(idx, lo, hi, m.lo, m.hi, final=True, mask=nzb)
        if not nzb.all():
            w = (np.where(nzb, w[0], lo), np.where(nzb, w[1], hi))
        bf = b.astype(float)
        # word - true: the word subtracts b, the truth bt
        v = IV(w, fadd(v.e, fsub(bt, (bf, bf))), fsub(v.t, bt))
        # sq += v^2, saturating at the accumulator
        v2 = isquare(v.w)
        sq_idx = np.array([idx_of[f"sq{i + 1}"] for i in range(6)])
        sq_w = rec.sat_legs(sq_idx, sq_w[0] + v2[0], sq_w[1] + v2[1], -m.acc_hi - 1, m.acc_hi, final=r == 2)
        sq_e = fadd(sq_e, fadd(fscale(fmul(v.t, v.e), 2.0), fsquare(v.e)))
        sq_t = fadd(sq_t, fsquare(v.t))
        flags |= rec.possible[:, idx].T
    # the length: nearest integer root, saturated to the word
    len_idx = np.array([idx_of[f"length{i + 1}"] for i in range(6)])
    rec.sat_legs(len_idx, isqrt_nearest(sq_w[0]), isqrt_nearest(sq_w[1]), m.lo, m.hi, final=True)
    s_f = (sq_w[0].astype(float), sq_w[1].astype(float))
    den = fadd(fsqrt(s_f), fsqrt(sq_t))
    ok = den[0] > 0
    den_safe = (np.where(ok, den[0], 1.0), np.where(ok, den[1], 1.0))
    prop = fdiv_pos(sq_e, den_safe)
    yfloor = np.floor(np.sqrt(sq_w[0].astype(float))) - 1.0  # a lower bound on y, safe against rounding
    rnd_hi = up(0.5 + 0.125 / (np.maximum(yfloor, 0.0) + 0.5))
    e = fadd(prop, (np.full((6, n), -0.5), rnd_hi))
    chain = r_sat[None, :] | flags | rec.possible[:, sq_idx].T | rec.possible[:, len_idx].T
    good = ok & ~chain
    return np.ascontiguousarray(np.where(good, e[0], -np.inf).T), np.ascontiguousarray(np.where(good, e[1], np.inf).T)


ENUMERATION_LIMIT = 4096  # angle-word pairs enumerated per cell for an exact rotation hull


def rotation_entry(model: Model, words: dict, i: int, j: int) -> tuple[np.ndarray, np.ndarray]:
    """R[i][j] before its final clamp, from sine/cosine words (arrays), as rotation_from_words forms it,
    and where a product or a partial sum on the way clamped."""
    f = model.fmt.frac_bits
    shape = np.broadcast(*words.values()).shape
    acc = np.zeros(shape, dtype=np.int64)
    clamped = np.zeros(shape, dtype=bool)
    items = list(model.monomials[i][j].items())
    adds = sum(abs(c) for _, c in items)
    done = 0
    for factors, coef in items:
        term = words[factors[0]]
        for fac in factors[1:]:
            raw = (term * words[fac]) >> f
            clamped |= (raw < model.lo) | (raw > model.hi)
            term = np.clip(raw, model.lo, model.hi)
        for _ in range(abs(coef)):
            done += 1
            acc = acc + (term if coef > 0 else -term)
            if done < adds:
                clamped |= (acc < model.lo) | (acc > model.hi)
                acc = np.clip(acc, model.lo, model.hi)
    return acc, clamped


def exact_rotation(model: Model, cell_lo: np.ndarray, cell_hi: np.ndarray, rec: Recorder, entry=None) -> None:
    """Exact hulls of the rotation words in cells where the intervals leave a clamp undecided.

    Every entry holds at most one factor (sine or cosine) of the middle rotation's angle (``free_axis``),
    and every step (product, floor shift, clamp, sum of terms without that angle) is monotone in that
    factor's word: fixing the other two angles, the entry's extremes lie at the extremes of its factor
    words. So enumerating the word pairs of the other two angles (up to ``ENUMERATION_LIMIT``) and taking
    the free angle's factor extremes gives the exact hull (and where no product or partial sum clamps, its
    clamp is decided exactly). ``entry(model, words, i, j) -> (word before its final clamp, inner clamp)``:
    the entry as the firmware forms it from sine/cosine words (default: ``rotation_from_words``' way)."""
    entry = entry or rotation_entry
    names = [f"R[{i}][{j}]" for i in range(3) for j in range(3)]
    cols = [rec.index[nm] for nm in names]
    flagged = np.flatnonzero(rec.possible[:, cols].any(axis=1))
    if flagged.size == 0:
        return
    tb = model.tables
    width = cell_hi[:, 3:] - cell_lo[:, 3:] + 1
    free = model.free_axis
    pair = [k for k in range(3) if k != free]
    for c in flagged:
        if int(width[c, pair[0]]) * int(width[c, pair[1]]) > ENUMERATION_LIMIT:
            continue
        ga, gb = np.meshgrid(
            np.arange(cell_lo[c, 3 + pair[0]], cell_hi[c, 3 + pair[0]] + 1),
            np.arange(cell_lo[c, 3 + pair[1]], cell_hi[c, 3 + pair[1]] + 1),
            indexing="ij",
        )
        grid = {pair[0]: ga.ravel(), pair[1]: gb.ravel()}
        words = {}
        for k in pair:
            s_, c_ = trig_words(grid[k], model.fmt)
            words[f"s{AXES[k]}"], words[f"c{AXES[k]}"] = s_, c_
        ext = {}
        for nm, tab in (("s", tb.sin_pre), ("c", tb.cos_pre)):
            lo_, hi_ = tab.query(cell_lo[c : c + 1, 3 + free], cell_hi[c : c + 1, 3 + free])
            ext[nm] = np.clip(np.array([lo_[0], hi_[0]]), model.lo, model.hi)
        lo_all = []
        for i in range(3):
            for j in range(3):
                vals = []
                for which in (0, 1):
                    w = dict(words)
                    w[f"s{AXES[free]}"] = ext["s"][which]
                    w[f"c{AXES[free]}"] = ext["c"][which]
                    vals.append(entry(model, w, i, j))
                v = np.concatenate([vals[0][0].ravel(), vals[1][0].ravel()])
                inner = bool(vals[0][1].any() or vals[1][1].any())
                lo_all.append((int(v.min()), int(v.max()), inner))
        for col, (lo_, hi_, inner) in zip(cols, lo_all):
            rec.pre_lo[c, col], rec.pre_hi[c, col] = lo_, hi_
            # an inner clamp makes the path non-monotone in general: keep the interval flags then
            if not inner:
                rec.possible[c, col] = (hi_ > model.hi) | (lo_ < model.lo)
                rec.certain[c, col] = (lo_ > model.hi) | (hi_ < model.lo)
