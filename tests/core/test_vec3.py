"""``vec3.cross`` must give ``np.cross``'s bits (the feed-forward tables, and so the closed-loop logs, depend
on them): random vectors over broadcast shapes, and the special values where a reordered expression would
show — signed zeros, infinities, NaN, subnormals, products that overflow or cancel."""

import numpy as np
import pytest

from stewart_drake.core.vec3 import cross


def bits(x) -> np.ndarray:
    return np.asarray(x, dtype=np.float64).view(np.int64)


@pytest.mark.parametrize(
    "shape_a, shape_b", [((3,), (3,)), ((500, 6, 3), (500, 6, 3)), ((500, 1, 3), (500, 6, 3)), ((6, 3), (40, 6, 3))]
)
def test_random_vectors_equal_np_cross_bit_for_bit(shape_a, shape_b):
    rng = np.random.default_rng(7)
    a = rng.normal(size=shape_a) * 10.0 ** rng.integers(-300, 300, shape_a)
    b = rng.normal(size=shape_b) * 10.0 ** rng.integers(-300, 300, shape_b)
    with np.errstate(all="ignore"):
        np.testing.assert_array_equal(bits(cross(a, b)), bits(np.cross(a, b)))
        np.testing.assert_array_equal(bits(cross(b, a)), bits(np.cross(b, a)))


def test_special_values_equal_np_cross_bit_for_bit():
    special = np.array([0.0, -0.0, 1.0, -1.0, np.inf, -np.inf, np.nan, 5e-324, -5e-324, 1e308, -1e308, 1e-160])
    grid = np.stack(np.meshgrid(special, special, special, indexing="ij"), -1).reshape(-1, 3)
    a = np.repeat(grid, 7, axis=0)
    b = np.tile(grid[:: max(1, len(grid) // 7)][:7], (len(grid), 1))
    with np.errstate(all="ignore"):
        mine, ref = cross(a, b), np.cross(a, b)
    nan = np.isnan(ref)
    np.testing.assert_array_equal(np.isnan(mine), nan)
    np.testing.assert_array_equal(bits(mine)[~nan], bits(ref)[~nan])  # NaN payloads aside, every bit


def test_other_operands_go_to_np_cross():
    assert cross([1, 0, 0], [0, 1, 0]).tolist() == [0, 0, 1]
    a = np.array([1.0, 2.0, 3.0], dtype=np.float32)
    assert cross(a, a).dtype == np.float32
