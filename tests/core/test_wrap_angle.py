"""``rotations.wrap_angle``, the one angle wrap of the 3R leg, the servo hexapod and their analyses."""

import numpy as np

from stewart_drake.core.rotations import wrap_angle


def test_wrap_angle_range_and_equivalence():
    x = np.linspace(-20.0, 20.0, 4001)
    w = wrap_angle(x)
    assert np.all(w >= -np.pi) and np.all(w < np.pi)
    # the same angle: cos and sin agree to the rounding of x + pi (|x| <= 20 rad: a few ulps of 20)
    np.testing.assert_allclose(np.cos(w), np.cos(x), atol=1e-14)
    np.testing.assert_allclose(np.sin(w), np.sin(x), atol=1e-14)
    # inside [-pi, pi) nothing changes beyond that rounding; pi itself maps to -pi (half-open interval)
    inside = (x >= -np.pi) & (x < np.pi)
    np.testing.assert_allclose(w[inside], x[inside], atol=1e-15)
    assert wrap_angle(np.pi) == -np.pi and wrap_angle(3 * np.pi) == -np.pi
    assert wrap_angle(0.25).shape == ()
