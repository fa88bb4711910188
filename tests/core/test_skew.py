"""``core.dynamics.skew``: [v]× w = v × w for batches of vectors, and the same bits, dtype and layout as the matrix
stacked entry by entry (its construction changed for speed; every caller's numbers stay as they were)."""

from __future__ import annotations

import numpy as np

from stewart_drake.core.dynamics import skew


def _stacked(v):
    z = np.zeros_like(v[..., 0])
    rows = [[z, -v[..., 2], v[..., 1]], [v[..., 2], z, -v[..., 0]], [-v[..., 1], v[..., 0], z]]
    return np.stack([np.stack(r, -1) for r in rows], -2)


def test_skew_is_the_cross_product_and_the_stacked_matrix():
    rng = np.random.default_rng(8)
    v, w = rng.normal(size=(2, 5, 4, 3))
    v[0, 0] = [0.0, -0.0, 1.0]  # signed zeros keep their sign
    S = skew(v)
    assert S.shape == (5, 4, 3, 3) and S.flags.c_contiguous
    assert S.tobytes() == _stacked(v).tobytes()
    assert np.abs(np.einsum("...ij,...j->...i", S, w) - np.cross(v, w)).max() <= 1e-15  # two roundings at most
    assert skew(np.array([1, 2, 3])).dtype == np.array([1, 2, 3]).dtype  # v's dtype, as before
    assert skew(np.broadcast_to([0.0, 0.0, -9.81], (3, 3))).shape == (3, 3, 3)  # read-only views are fine
