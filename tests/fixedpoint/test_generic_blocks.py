"""``generic.leg_length_words`` splits large batches into blocks of poses when no saturation counter is active
(its temporaries then stay in cache): the words are those of one pass over the whole batch, saturating poses
included, and a counter still sees every saturation (it gets the one-pass path)."""

from __future__ import annotations

import numpy as np

from stewart_drake.core.geometry import load_preset
from stewart_drake.fixedpoint import generic
from stewart_drake.fixedpoint.generic import QFormat, leg_length_words, pose_words
from stewart_drake.fixedpoint.q15 import SaturationCounter, counting


def test_blocks_give_the_words_of_one_pass():
    p = load_preset("utn-dynamic")
    fmt = QFormat(16, 1e-4, "tfr16")  # words reach ±3.28 m: the poses below ±4 m saturate positions, sums, roots
    rng = np.random.default_rng(2)
    n = 2 * generic.BLOCK + 77  # two full blocks and a partial one
    q = np.c_[rng.uniform(-4, 4, (n, 3)), rng.uniform(-0.6, 0.6, (n, 3))]
    w = pose_words(q, fmt).reshape(n, 1, 6)  # a leading shape of more than one axis
    with SaturationCounter(shape=w.shape[:-1]) as sat:
        assert counting()
        one_pass = leg_length_words(p, w, fmt)
    assert not counting()
    blocked = leg_length_words(p, w, fmt)
    assert blocked.shape == w.shape and np.array_equal(blocked, one_pass)
    assert sat.counts["generic.sqrt"] > 0 and sat.counts["generic.add"] > 0  # saturating poses exercised
    assert 0 < sat.mask.sum() < n  # and poses that do not saturate
