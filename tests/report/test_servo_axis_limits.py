"""The servo section's reachable ranges (``analyses.servo.axis_limits``): every direction bisected at once must
give, bit for bit, the scalar bisection of one direction at a time (the section's table before), and each limit
must separate a reachable step from an unreachable one."""

import numpy as np

from stewart_drake.analyses.servo import axis_limits
from stewart_drake.mechanisms.servo import solve


def _one_direction(h, direction, hi):
    lo = 0.0
    for _ in range(40):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if solve(h, h.home_pose() + mid * direction).ok else (lo, mid)
    return lo


def test_axis_limits_equal_the_scalar_bisection(hexapod):
    rng = np.random.default_rng(3)
    d = np.vstack([np.eye(6), -np.eye(6), rng.normal(size=(4, 6)) * [0.01, 0.01, 0.01, 0.1, 0.1, 0.1]])
    hi = np.r_[[0.1] * 3, [np.pi / 2] * 3, [0.1] * 3, [np.pi / 2] * 3, [2.0] * 4]
    got = axis_limits(hexapod, d, hi)
    np.testing.assert_array_equal(got, [_one_direction(hexapod, dk, hk) for dk, hk in zip(d, hi)])
    home = hexapod.home_pose()
    assert np.all(solve(hexapod, home + got[:, None] * d).ok)
    assert not np.any(solve(hexapod, home + (got[:, None] + 1e-6 * hi[:, None]) * d).ok)
