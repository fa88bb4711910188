"""The shared argument checks: the first offending index agrees with numpy's own ``argwhere``, shapes
are reported scipy-style, and a non-finite sample is named by its batch index counted from 1."""

import re

import numpy as np
import pytest

from stewart_drake.core.argcheck import as_poses, check_finite_samples, check_shape, first_index
from stewart_drake.errors import NOT_FINITE_SAMPLE, SHAPE, NotFiniteError, ShapeError, StewartError


@pytest.mark.parametrize("shape", [(), (7,), (3, 4), (2, 3, 5)])
def test_first_index_is_argwhere_first_row(shape):
    rng = np.random.default_rng(0)
    for _ in range(20):
        mask = rng.random(shape) < 0.2
        expected = tuple(int(i) for i in np.argwhere(mask)[0]) if mask.any() else None
        assert first_index(mask) == expected


def test_check_shape_messages():
    with pytest.raises(ShapeError, match=re.escape("Expected poses to have shape (..., 6), got (5,)")):
        check_shape(np.zeros(5), "poses", (..., 6))
    with pytest.raises(ShapeError, match=re.escape(SHAPE.format(name="anchors", shape="(6, 3)", got="(5, 3)"))):
        check_shape(np.zeros((5, 3)), "anchors", (6, 3))
    with pytest.raises(ShapeError, match=re.escape(SHAPE.format(name="v", shape="(..., 6, 3)", got="(3,)"))):
        check_shape(np.zeros(3), "v", (..., 6, 3))  # fewer dimensions than the trailing shape
    assert check_shape([[1, 2, 3]] * 6, "anchors", (6, 3)).dtype == float
    assert check_shape(np.zeros((2, 4, 6, 3)), "v", (..., 6, 3)).shape == (2, 4, 6, 3)


def test_non_finite_sample_is_named_counted_from_one():
    q = np.zeros((2, 3, 6))
    q[1, 2, 4] = np.inf
    message = NOT_FINITE_SAMPLE.format(what="pose", index="2,3", values=q[1, 2].tolist())
    with pytest.raises(NotFiniteError, match=re.escape(message)):
        as_poses(q)
    with pytest.raises(NotFiniteError, match=re.escape("x 4 is not finite: nan")):
        check_finite_samples([0.0, 1.0, 2.0, np.nan], "x", sample_ndim=0)
    single = np.r_[0.0, 0.0, np.nan, 0.0, 0.0, 0.0]
    with pytest.raises(NotFiniteError, match=re.escape("pose 1 is not finite")):
        as_poses(single)
    assert issubclass(NotFiniteError, StewartError) and issubclass(ShapeError, ValueError)
