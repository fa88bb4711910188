"""3R planar leg (``mechanisms/leg3r``) cross-checked against Drake: every DH frame and both IK
branches (``drake/leg_model``)."""

import numpy as np
import pytest

from stewart_drake.drake.leg_model import drake_fk_errors, drake_ik
from stewart_drake.mechanisms.leg3r import Leg3R, foot, foot_jacobian, inverse_kinematics, random_configurations

LEG = Leg3R()


def wrap(x):
    return (x + np.pi) % (2 * np.pi) - np.pi


def test_fk_matches_drake():
    q = random_configurations(LEG, 200, seed=6)
    assert drake_fk_errors(LEG, q).max() < 1e-14  # every DH frame, 4x4 element-wise


@pytest.mark.parametrize("branch", ["a", "b"])
def test_ik_matches_drake_inverse_kinematics(branch):
    q = random_configurations(LEG, 1000, seed=7)
    p = foot(LEG, q)[:, :2]
    qd, gap = drake_ik(LEG, p, branch)
    qn = inverse_kinematics(LEG, p, branch)
    d = np.abs(wrap(qd - qn)).max(1)
    # Drake stops gap metres from the target; to first order that moves the angles by ||J^-1|| gap.
    bound = np.linalg.norm(np.linalg.inv(foot_jacobian(LEG, qn)), 2, axis=(-2, -1)) * gap
    assert np.all(d <= 2 * bound + 1e-12)
