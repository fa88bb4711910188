"""The seed's firmware (``tp17.C``, ported in ``fixedpoint.tp17``) evaluated over boxes of its pose words:
positions in whole millimetres, angles as FRAC16 words (Q15 fractions of pi). The same interval quantities
as ``recipe`` (exact integer hulls, error enclosures against the float IK of the platform file, here
utn-kinematic with a = 612.5 mm), following tp17.C operation by operation: ``m(x, y) = extract_h(L_mult(x,
y))`` is the Q15 product truncated toward -inf (``mulq`` with f = 15), ``add``/``negate`` saturate, the leg
vector adds the firmware's offset words (``tp17_base_offsets``: the y offset's two adds taken as their sum,
the same word unless the first add clamps), and ``mfr32Sqrt`` of ``2 (X^2 + Y^2 + Z^2)`` is the
nearest-of-two integer root. A cell of one pose gives ``tp17_trace``'s words (a test pins it)."""

from __future__ import annotations

import numpy as np

from stewart_drake.core.geometry import Platform
from stewart_drake.firmware.certify.intervals import down, fadd, fdiv_pos, fmul, fscale, fsqrt, fsquare, fsub, imul, up
from stewart_drake.firmware.certify.recipe import (
    AXES,
    ERR_UNIT,
    IV,
    CellEval,
    Model,
    Recorder,
    addw,
    exact_rotation,
    isqrt_nearest,
    mulq,
)
from stewart_drake.fixedpoint.generic import QFormat
from stewart_drake.fixedpoint.q15 import L_mult, SaturationCounter, extract_h, negate
from stewart_drake.fixedpoint.tp17 import LEG_JOINT, tp17_base_offsets, tp17_plate_words

F = 15


def tp17_word_names() -> list[str]:
    """The words of ``Tp17Trace`` in this order: pose, sin, cos, R (co11..co33), leg vectors, L32, lengths."""
    names = ["px", "py", "pz"] + [f"angle.{a}" for a in AXES]
    names += [f"sin.{a}" for a in AXES] + [f"cos.{a}" for a in AXES]
    names += [f"R[{i}][{j}]" for i in range(3) for j in range(3)]
    names += [f"leg{i + 1}.{a}" for i in range(6) for a in AXES]
    names += [f"L32_{i + 1}" for i in range(6)] + [f"length{i + 1}" for i in range(6)]
    return names


class _Rec(Recorder):
    def __init__(self, n: int):
        self._allocate(n, tp17_word_names())


def tp17_entry(model: Model, w: dict, i: int, j: int):
    """co(i+1)(j+1) of tp17.C from sine/cosine words, before its final ``add`` clamps, and whether an inner
    operation clamped (the whole matrix's inner clamps, a conservative flag)."""
    sA, cA, sB, cB, sG, cG = (np.asarray(w[k]) for k in ("sx", "cx", "sy", "cy", "sz", "cz"))
    shape = np.broadcast(sA, cA, sB, cB, sG, cG).shape

    def mm(x, y):
        return extract_h(L_mult(x, y))

    with SaturationCounter(shape=shape) as sat:
        sAsB, sAcB = mm(sA, sB), mm(sA, cB)
        co = [
            [(mm(cB, cG), mm(sAsB, sG)), (mm(negate(cB), sG), mm(sAsB, cG)), (mm(cA, sB),)],
            [(mm(cA, sG),), (mm(cA, cG),), (negate(sA),)],
            [(mm(negate(sB), cG), mm(sAcB, sG)), (mm(sB, sG), mm(sAcB, cG)), (mm(cA, cB),)],
        ]
    terms = co[i][j]
    pre = np.broadcast_to(terms[0] + (terms[1] if len(terms) > 1 else 0), shape)
    if len(terms) == 1 and i == 1 and j == 2:  # negate(sA) is the entry's own (final) clamp
        pre = np.broadcast_to(-sA, shape)
    return pre, np.broadcast_to(sat.mask, shape)


def tp17_model(platform: Platform) -> Model:
    """The model of 16-bit words with tfr16 trig and 1 mm LSB (tp17's), for the platform's true constants."""
    return Model.build(platform, QFormat(16, 1e-3, "tfr16"), "utn")


def _neg(a: IV, rec: Recorder, name: str, m: Model) -> IV:
    return IV(rec.sat(name, -a.w[1], -a.w[0], m.lo, m.hi), (-a.e[1], -a.e[0]), (-a.t[1], -a.t[0]))


def evaluate_tp17(model: Model, cell_lo: np.ndarray, cell_hi: np.ndarray) -> CellEval:
    """tp17.C over ``(n, 6)`` cells of its pose words (mm, FRAC16 angle words), inclusive."""
    cell_lo = np.asarray(cell_lo, dtype=np.int64)
    cell_hi = np.asarray(cell_hi, dtype=np.int64)
    n, m = cell_lo.shape[0], model
    rec = _Rec(n)
    zf = (np.zeros(n), np.zeros(n))
    for k in range(6):
        rec.pre_lo[:, k], rec.pre_hi[:, k] = cell_lo[:, k], cell_hi[:, k]
    tb = m.tables
    s, c = [], []
    for k, ax in enumerate(AXES):
        pos = tb.sin_pre.positions(cell_lo[:, 3 + k], cell_hi[:, 3 + k])  # the same for the six tables
        for out, pre, elo, ehi, label in (
            (s, tb.sin_pre, tb.sin_err_lo, tb.sin_err_hi, f"sin.{ax}"),
            (c, tb.cos_pre, tb.cos_err_lo, tb.cos_err_hi, f"cos.{ax}"),
        ):
            w = rec.sat(label, pre.min_at(pos), pre.max_at(pos), m.lo, m.hi, final=True)
            e = (elo.min_at(pos) * ERR_UNIT, ehi.max_at(pos) * ERR_UNIT)
            out.append(IV(w, e, fsub((w[0].astype(float), w[1].astype(float)), e)))
    sA, sB, sG = s
    cA, cB, cG = c

    def mm(x, y, name):
        return mulq(x, y, F, rec, name, m)

    def fin(v: IV, name: str) -> IV:
        k = rec.index[name]
        rec.pre_lo[:, k], rec.pre_hi[:, k] = v.w
        return v

    def add2(a, b, name):
        return addw(a, b, 1, rec, name, m, True)

    sAsB = mm(sA, sB, "R[0][0]")
    sAcB = mm(sA, cB, "R[2][0]")
    R = [
        [
            add2(mm(cB, cG, "R[0][0]"), mm(sAsB, sG, "R[0][0]"), "R[0][0]"),
            add2(mm(_neg(cB, rec, "R[0][1]", m), sG, "R[0][1]"), mm(sAsB, cG, "R[0][1]"), "R[0][1]"),
            fin(mm(cA, sB, "R[0][2]"), "R[0][2]"),
        ],
        [
            fin(mm(cA, sG, "R[1][0]"), "R[1][0]"),
            fin(mm(cA, cG, "R[1][1]"), "R[1][1]"),
            fin(_neg(sA, rec, "R[1][2]", m), "R[1][2]"),
        ],
        [
            add2(mm(_neg(sB, rec, "R[2][0]", m), cG, "R[2][0]"), mm(sAcB, sG, "R[2][0]"), "R[2][0]"),
            add2(mm(sB, sG, "R[2][1]"), mm(sAcB, cG, "R[2][1]"), "R[2][1]"),
            fin(mm(cA, cB, "R[2][2]"), "R[2][2]"),
        ],
    ]
    top = tp17_plate_words()
    offs = tp17_base_offsets()
    exact_rotation(m, cell_lo, cell_hi, rec, tp17_entry)
    r_true = (m.platform.top_anchors_per_leg - m.platform.rotation_centre) * 1e3  # mm, per leg
    b_true = np.asarray(m.platform.base_anchors, dtype=float) * 1e3
    err_lo = np.full((n, 6), -np.inf)
    err_hi = np.full((n, 6), np.inf)
    r_sat = rec.possible[:, [rec.index[f"R[{i}][{j}]"] for i in range(3) for j in range(3)]].any(axis=1)
    for i in range(6):
        j = LEG_JOINT[i]
        sq_w, sq_e, sq_t = (np.zeros(n, np.int64), np.zeros(n, np.int64)), zf, zf
        chain = r_sat.copy()
        for r in range(3):
            name = f"leg{i + 1}.{AXES[r]}"
            v = None
            for k in range(3):
                cw = int(top[j, k])
                ct = (down(r_true[i, k]), up(r_true[i, k]))
                Rk = R[r][k]
                contrib_t = fscale(fmul(Rk.t, ct), 2.0**-F)
                lo, hi = imul(Rk.w, (np.int64(cw), np.int64(cw)))
                e = fscale(fadd(fmul(Rk.t, fsub((float(cw), float(cw)), ct)), fscale(Rk.e, float(cw))), 2.0**-F)
                term = IV((lo >> F, hi >> F), fsub(e, (0.0, 1.0)), contrib_t)
                v = term if v is None else addw(v, term, 1, rec, name, m, False)
            p = IV((cell_lo[:, r], cell_hi[:, r]), zf, (cell_lo[:, r].astype(float), cell_hi[:, r].astype(float)))
            v = addw(v, p, 1, rec, name, m, False)
            o = int(offs[i, r])
            bt = (down(b_true[i, r]), up(b_true[i, r]))
            off = IV((np.full(n, o), np.full(n, o)), fadd((float(o), float(o)), bt), fsub(zf, bt))
            v = addw(off, v, 1, rec, name, m, True)  # add(offset, top): the word is offset + top
            chain |= rec.flag(name)
            v2 = (
                np.where((v.w[0] <= 0) & (v.w[1] >= 0), 0, np.minimum(v.w[0] ** 2, v.w[1] ** 2)),
                np.maximum(v.w[0] ** 2, v.w[1] ** 2),
            )
            sq_w = (sq_w[0] + v2[0], sq_w[1] + v2[1])
            sq_e = fadd(sq_e, fadd(fscale(fmul(v.t, v.e), 2.0), fsquare(v.e)))
            sq_t = fadd(sq_t, fsquare(v.t))
        L32 = rec.sat(f"L32_{i + 1}", 2 * sq_w[0], 2 * sq_w[1], -(2**31), 2**31 - 1, final=True)
        y_lo, y_hi = isqrt_nearest(L32[0] // 2), isqrt_nearest(L32[1] // 2)
        rec.sat(f"length{i + 1}", y_lo, y_hi, m.lo, m.hi, final=True)
        chain |= rec.flag(f"L32_{i + 1}") | rec.flag(f"length{i + 1}")
        s_f = (sq_w[0].astype(float), sq_w[1].astype(float))
        den = fadd(fsqrt(s_f), fsqrt(sq_t))
        ok = den[0] > 0
        prop = fdiv_pos(sq_e, (np.where(ok, den[0], 1.0), np.where(ok, den[1], 1.0)))
        yfloor = np.floor(np.sqrt(sq_w[0].astype(float))) - 1.0
        e = fadd(prop, (np.full(n, -0.5), up(0.5 + 0.125 / (np.maximum(yfloor, 0.0) + 0.5))))
        good = ok & ~chain
        err_lo[:, i] = np.where(good, e[0], -np.inf)
        err_hi[:, i] = np.where(good, e[1], np.inf)
    return CellEval(rec.pre_lo, rec.pre_hi, rec.possible, rec.certain, err_lo, err_hi)
