"""``box_quadratic_max`` on a batch evaluates each face only where it holds a candidate: an entry's value and
maximiser must not depend, bit for bit, on its companions in the batch (other orders, other sub-batches). A matrix
alone is not compared: its vertices go through a matrix-vector product instead of a matrix product, whose last
bits may differ, as they always did."""

from __future__ import annotations

import numpy as np
import pytest

from stewart_drake.design.boxquad import box_quadratic_max


@pytest.mark.parametrize("d", [1, 2, 3])
def test_an_entrys_result_does_not_depend_on_its_batch(d):
    rng = np.random.default_rng(d)
    Q = rng.normal(size=(60, d, d))
    Q[:20, 0, 0] -= 2.0  # concave along the first axis: interior faces win there
    Q[20:25] = 0.0  # every value 0: the interior's x = 0 kept
    b = rng.uniform(0.1, 1.0, d)
    for QQ, bb in ((Q, b), (-Q, b), (Q, np.r_[b[:-1], 0.0])):  # a zero-width coordinate too
        value, arg = box_quadratic_max(QQ.reshape(6, 10, d, d), bb)  # two batch axes
        value, arg = value.reshape(60), arg.reshape(60, d)
        perm = rng.permutation(60)
        for idx in (perm, np.arange(0, 7), np.arange(3, 40), np.arange(21, 23), np.arange(15, 60, 4)):
            v, a = box_quadratic_max(QQ[idx], bb)
            assert v.tobytes() == value[idx].tobytes() and a.tobytes() == arg[idx].tobytes()
