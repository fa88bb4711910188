"""Branch and bound over a box of pose words: best-first bisection of the cells whose error bound is
largest or whose saturation is undecided, with a fixed budget of cell evaluations and a capped pool of
live cells (memory bounded whatever the box), and the search for witness poses in undecided cells.

Deterministic: the order of work depends only on the box, the format and the budget (no clock)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stewart_drake.firmware.certify.points import point_words
from stewart_drake.firmware.certify.recipe import BENIGN, CellEval, Model, word_names
from stewart_drake.firmware.certify.recipe import evaluate as evaluate_generic
from stewart_drake.firmware.certify.tp17_recipe import evaluate_tp17, tp17_word_names
from stewart_drake.fixedpoint.generic import leg_length_words
from stewart_drake.fixedpoint.q15 import SaturationCounter
from stewart_drake.fixedpoint.tp17 import tp17_leg_lengths

MAX_CELLS = 200_000  # default evaluation budget
BATCH = 4096  # cells split per round
MAX_POOL = 32_768  # live cells kept; beyond, the least interesting retire into the running hulls
ARITHMETIC_OPS = ("generic.mult", "generic.add", "generic.sub", "generic.L_add", "generic.sqrt")


@dataclass
class Search:
    """The outcome of the branch and bound, in words (``certificate.Certificate`` adds units)."""

    pre_lo: np.ndarray  # (W,) hull of every word before saturation
    pre_hi: np.ndarray
    possible: np.ndarray  # (W,) some leaf may clamp the word
    certain: np.ndarray  # (W,) some leaf clamps it at every pose
    err_bound_lsb: np.ndarray  # (6,) max over leaves of |L_words - L_true| (inf where saturation is possible)
    witness: np.ndarray | None  # (6,) pose words that saturate the emulation, or None
    witness_ops: dict  # the emulation's saturation counts at the witness
    witness_words: list  # the words the recipe says clamp at the witness (the emulation agrees: a test pins it)
    unresolved: np.ndarray  # (k, 2, 6) cells with an undecided saturation and no witness (at most 20)
    unresolved_count: int
    cells: int  # cells evaluated
    exhausted: bool  # the budget ended the search


def _split_dim(model: Model, lo: np.ndarray, hi: np.ndarray, angles_only: np.ndarray) -> np.ndarray:
    """The dimension to bisect: the widest in length LSBs of leg movement (angles weighted by the
    largest plate-anchor offset); only angles where ``angles_only`` (the rotation words alone are undecided)."""
    f = model.fmt.frac_bits
    sens = np.r_[[1.0] * 3, [np.pi / (1 << f) * (np.abs(model.r_T).max() + 1.0)] * 3]
    eff = (hi - lo).astype(float) * sens
    eff[hi <= lo] = -1.0
    d = np.argmax(eff, axis=1)
    # rotation words alone undecided: the exact rotation hull enumerates the two angles other than the
    # middle rotation's and takes that one at its extremes, so halve the wider of the two others
    ang = (hi[:, 3:] - lo[:, 3:]).astype(float)
    ang[:, model.free_axis] = -1.0
    d_rot = 3 + np.argmax(ang, axis=1)
    ok = ang[np.arange(ang.shape[0]), d_rot - 3] > 0
    return np.where(angles_only & ok, d_rot, d)


def _split(model: Model, lo: np.ndarray, hi: np.ndarray, angles_only: np.ndarray):
    d = _split_dim(model, lo, hi, angles_only)
    r = np.arange(lo.shape[0])
    mid = lo[r, d] + (hi[r, d] - lo[r, d]) // 2
    lo2, hi1 = lo.copy(), hi.copy()
    hi1[r, d] = mid
    lo2[r, d] = mid + 1
    return np.concatenate([lo, lo2]), np.concatenate([hi1, hi])


def emulation_saturates(model: Model, words: np.ndarray, implementation: str = "generated") -> dict:
    """The emulation's own saturation counts (arithmetic only: the trig clamp is within its certified
    error; the pose conversion is not the firmware's arithmetic) for one pose-words vector: the
    independent confirmation of a witness."""
    w = np.asarray(words, dtype=np.int64)
    with SaturationCounter() as sat:
        if implementation == "tp17":
            tp17_leg_lengths(np.r_[w[:3].astype(float), w[3:] / 32768.0])
        else:
            leg_length_words(model.platform, w, model.fmt, model.convention)
    keep = (lambda k: k != "FRAC16") if implementation == "tp17" else (lambda k: k in ARITHMETIC_OPS)
    return {k: int(v) for k, v in sat.counts.items() if keep(k)}


class _Pool:
    def __init__(self):
        self.lo = self.hi = None
        self.ev: CellEval | None = None
        self.score = None

    def add(self, lo, hi, ev: CellEval, score):
        if self.lo is None:
            self.lo, self.hi, self.ev, self.score = lo, hi, ev, score
            return
        self.lo = np.concatenate([self.lo, lo])
        self.hi = np.concatenate([self.hi, hi])
        self.score = np.concatenate([self.score, score])
        e, n = self.ev, ev
        keys = ("pre_lo", "pre_hi", "possible", "certain", "err_lo", "err_hi")
        self.ev = CellEval(*(np.concatenate([getattr(e, k), getattr(n, k)]) for k in keys))

    def take(self, idx):
        keep = np.ones(self.lo.shape[0], dtype=bool)
        keep[idx] = False
        out = (self.lo[idx], self.hi[idx], _subset(self.ev, idx), self.score[idx])
        self.lo, self.hi, self.score = self.lo[keep], self.hi[keep], self.score[keep]
        self.ev = _subset(self.ev, keep)
        return out


def _subset(ev: CellEval, idx) -> CellEval:
    return CellEval(ev.pre_lo[idx], ev.pre_hi[idx], ev.possible[idx], ev.certain[idx], ev.err_lo[idx], ev.err_hi[idx])


class _Hull:
    """Running aggregates of retired cells."""

    def __init__(self, W: int):
        self.pre_lo = np.full(W, np.iinfo(np.int64).max)
        self.pre_hi = np.full(W, np.iinfo(np.int64).min)
        self.possible = np.zeros(W, dtype=bool)
        self.certain = np.zeros(W, dtype=bool)
        self.err = np.zeros(6)

    def absorb(self, ev: CellEval):
        if ev.pre_lo.shape[0] == 0:
            return
        self.pre_lo = np.minimum(self.pre_lo, ev.pre_lo.min(axis=0))
        self.pre_hi = np.maximum(self.pre_hi, ev.pre_hi.max(axis=0))
        self.possible |= ev.possible.any(axis=0)
        self.certain |= ev.certain.any(axis=0)
        self.err = np.maximum(self.err, ev.err_abs.max(axis=0))


def run_search(
    model: Model,
    box_lo: np.ndarray,
    box_hi: np.ndarray,
    max_cells: int = MAX_CELLS,
    seed: int = 0,
    implementation: str = "generated",
) -> Search:
    """Certify the box of pose words ``[box_lo, box_hi]`` within ``max_cells`` cell evaluations.

    A cell's priority: infinite while a word may clamp there and no witness has shown that word clamping
    (split it to decide), -1 once its clamps are all shown (its error is unbounded anyway), else its
    largest error bound (split the worst first). A word is shown by a witness pose confirmed by the
    emulation's own saturation counter, or by a cell where it clamps at every pose."""
    names = tp17_word_names() if implementation == "tp17" else word_names()
    evaluate = evaluate_tp17 if implementation == "tp17" else evaluate_generic
    arith = np.array([n not in BENIGN for n in names])
    rot_words = np.array([n.startswith("R[") for n in names])
    rng = np.random.default_rng(seed)
    hull = _Hull(len(names))
    pool = _Pool()
    lo = np.asarray(box_lo, dtype=np.int64)[None, :]
    hi = np.asarray(box_hi, dtype=np.int64)[None, :]
    cells = 0
    shown = np.zeros(len(names), dtype=bool)
    witnesses: list[tuple[np.ndarray, dict, list]] = []

    def undecided_of(ev: CellEval):
        return ev.possible & arith & ~ev.certain & ~shown

    def score_of(ev: CellEval, lo, hi):
        s = ev.err_abs.max(axis=1)
        s = np.where((ev.possible & arith).any(axis=1), -1.0, s)
        if shown.any():  # saturation shown: the error is unbounded, only undecided words are worth splitting for
            s = np.full_like(s, -1.0)
        s = np.where(undecided_of(ev).any(axis=1), np.inf, s)
        return np.where(np.all(hi <= lo, axis=1), -2.0, s)  # a single pose: final

    def look_for_witness(ev: CellEval, lo, hi):
        nonlocal shown
        shown |= (ev.certain & arith).any(axis=0)
        flagged = np.flatnonzero(undecided_of(ev).any(axis=1))[:256]
        if flagged.size == 0:
            return
        pts = [lo[flagged], hi[flagged], (lo[flagged] + hi[flagged]) // 2]
        if cells <= 1:  # the whole box: its 64 corners, where the longest legs are
            pts.append(np.array([[hi[0, k] if (c >> k) & 1 else lo[0, k] for k in range(6)] for c in range(64)]))
        pts.append(lo[flagged] + (rng.random(lo[flagged].shape) * (hi[flagged] - lo[flagged] + 1)).astype(np.int64))
        cand = np.concatenate(pts)
        pe = evaluate(model, cand, cand) if implementation == "tp17" else point_words(model, cand)  # single poses
        for k in np.flatnonzero((pe.possible & arith & ~shown).any(axis=1))[:8]:
            new = pe.possible[k] & arith & ~shown
            if not new.any():
                continue
            ops = emulation_saturates(model, cand[k], implementation)
            if ops:  # confirmed by the emulation itself
                witnesses.append((cand[k].copy(), ops, [names[j] for j in np.flatnonzero(pe.possible[k] & arith)]))
                shown |= new

    ev = evaluate(model, lo, hi)
    cells += 1
    look_for_witness(ev, lo, hi)
    pool.add(lo, hi, ev, score_of(ev, lo, hi))
    exhausted = False
    first_witness_at = None
    while True:
        if witnesses and first_witness_at is None:
            first_witness_at = cells
        pool.score = s = score_of(pool.ev, pool.lo, pool.hi)
        live = np.flatnonzero(s >= 0)
        if live.size == 0:
            break
        # once a witness shows saturation, deciding the other words gets a quarter of the budget
        limit = max_cells if not witnesses else min(max_cells, first_witness_at + max_cells // 4)
        k = min(BATCH, live.size, (limit - cells) // 2)
        if k <= 0:
            exhausted = True
            break
        top = live[np.argsort(-s[live], kind="stable")[:k]]
        lo, hi, ev_t, _ = pool.take(top)
        und = undecided_of(ev_t)
        angles_only = und.any(axis=1) & ~(und & ~rot_words).any(axis=1)
        lo, hi = _split(model, lo, hi, angles_only)
        ev = evaluate(model, lo, hi)
        cells += lo.shape[0]
        look_for_witness(ev, lo, hi)
        pool.add(lo, hi, ev, score_of(ev, lo, hi))
        if pool.lo.shape[0] > MAX_POOL:  # retire the least interesting cells into the running hull
            order = np.argsort(pool.score, kind="stable")
            _, _, ev_r, _ = pool.take(order[: pool.lo.shape[0] - MAX_POOL // 2])
            hull.absorb(ev_r)
    hull.absorb(pool.ev)
    undecided = np.flatnonzero(undecided_of(pool.ev).any(axis=1))
    certain_cells = np.flatnonzero((pool.ev.certain & arith).any(axis=1))
    if certain_cells.size and not witnesses:  # a cell that clamps everywhere: its corner is a witness
        cand = pool.lo[certain_cells[0]]
        ops = emulation_saturates(model, cand, implementation)
        if ops:
            witnesses.append(
                (cand.copy(), ops, [names[j] for j in np.flatnonzero(pool.ev.certain[certain_cells[0]] & arith)])
            )
    w = witnesses[0] if witnesses else (None, {}, [])
    return Search(
        hull.pre_lo,
        hull.pre_hi,
        hull.possible,
        hull.certain | shown,
        hull.err,
        w[0],
        w[1],
        w[2],
        np.stack([pool.lo[undecided[:20]], pool.hi[undecided[:20]]], axis=1),
        int(undecided.size),
        cells,
        exhausted,
    )
