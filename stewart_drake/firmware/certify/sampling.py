"""The sampled side of the certificate: random and adversarial poses of a box through the bit-exact
emulation (``fixedpoint.generic``) against the double-precision IK at the pose the words represent.

A sample is not a proof: these figures check the proven bounds (a bound below a sampled error would be
a bug) and measure how tight they are; they also give the simulation-only ("fxpopt") ranges."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.firmware.certify.points import point_words
from stewart_drake.firmware.certify.recipe import BENIGN, Model, word_names
from stewart_drake.fixedpoint.generic import leg_length_words

CHUNK = 1 << 16
BENIGN_MASK = np.array([n in BENIGN for n in word_names()])


def word_pose_si(model: Model, words: np.ndarray) -> np.ndarray:
    """``(..., 6)`` SI poses the pose words represent (positions in LSBs, angles in Q(f) pi-fractions)."""
    w = np.asarray(words, dtype=float)
    f = model.fmt.frac_bits
    return np.concatenate([w[..., :3] * model.fmt.length_lsb, w[..., 3:] * (np.pi / (1 << f))], axis=-1)


def length_errors(model: Model, words: np.ndarray) -> np.ndarray:
    """``(n, 6)`` L_emulation - L_double in length LSBs for ``(n, 6)`` pose words."""
    Lw = leg_length_words(model.platform, words, model.fmt, model.convention)
    Lf = leg_lengths(model.platform, word_pose_si(model, words), model.convention) / model.fmt.length_lsb
    return Lw - Lf


@dataclass
class Sampled:
    """Sampled extremes over ``n`` poses: every trace word's min/max (after saturation, as the firmware
    holds them, and before: ``pre_*``), the worst |error| per leg (LSB) and the pose words attaining it,
    and how many poses saturated an arithmetic word."""

    n: int
    word_min: np.ndarray
    word_max: np.ndarray
    pre_min: np.ndarray
    pre_max: np.ndarray
    worst_err: np.ndarray
    worst_pose: np.ndarray
    saturated: int
    first_saturating: np.ndarray | None


def sample_box(model: Model, lo, hi, n: int, seed: int = 0, adversarial: int = 0) -> Sampled:
    """``n`` uniform pose words of ``[lo, hi]`` (plus the 64 corners), then ``adversarial`` rounds of a
    local search around the worst poses (±1, ±2, ±4 ... words), in chunks: memory bounded whatever n."""
    lo = np.asarray(lo, dtype=np.int64)
    hi = np.asarray(hi, dtype=np.int64)
    rng = np.random.default_rng(seed)
    acc = None
    corners = np.array([[hi[k] if (c >> k) & 1 else lo[k] for k in range(6)] for c in range(64)])
    done = 0
    batches = [corners]
    while done < n or batches:
        if not batches:
            m = min(CHUNK, n - done)
            batches.append(lo + np.floor(rng.random((m, 6)) * (hi - lo + 1)).astype(np.int64))
            done += m
        w = np.minimum(batches.pop(), hi)
        acc = _merge(acc, measure_words(model, w))
    for r in range(adversarial):
        worst = acc.worst_pose  # (6 legs, 6)
        step = 1 << (r % 8)
        pert = rng.integers(-step, step + 1, size=(6, 1024, 6))
        w = np.clip(worst[:, None, :] + pert, lo, hi).reshape(-1, 6)
        acc = _merge(acc, measure_words(model, w))
    return acc


def measure_words(model: Model, w: np.ndarray) -> Sampled:
    """Sampled extremes over the ``(n, 6)`` pose words ``w`` (one chunk)."""
    ev = point_words(model, w)  # the recipe at single poses (= the emulation, pinned by a test), integers only
    post_lo, _ = ev.post(model)
    arith_sat = (ev.possible & ~BENIGN_MASK).any(axis=1)  # the trig clamp is within its certified error
    err = np.abs(length_errors(model, w))
    err = np.where(arith_sat[:, None], 0.0, err)  # a saturated pose has no error bound to check
    k = np.argmax(err, axis=0)
    sat_idx = np.flatnonzero(arith_sat)
    return Sampled(
        w.shape[0],
        post_lo.min(axis=0),
        post_lo.max(axis=0),
        ev.pre_lo.min(axis=0),
        ev.pre_lo.max(axis=0),
        err[k, np.arange(6)],
        w[k],
        int(sat_idx.size),
        w[sat_idx[0]] if sat_idx.size else None,
    )


def _merge(a: Sampled | None, b: Sampled) -> Sampled:
    if a is None:
        return b
    better = b.worst_err > a.worst_err
    return Sampled(
        a.n + b.n,
        np.minimum(a.word_min, b.word_min),
        np.maximum(a.word_max, b.word_max),
        np.minimum(a.pre_min, b.pre_min),
        np.maximum(a.pre_max, b.pre_max),
        np.where(better, b.worst_err, a.worst_err),
        np.where(better[:, None], b.worst_pose, a.worst_pose),
        a.saturated + b.saturated,
        a.first_saturating if a.first_saturating is not None else b.first_saturating,
    )
