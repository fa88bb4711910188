"""``kinematics.condition_at_most``: the cheap a-posteriori bound that decides most Jacobians of the
feed-forward table must give the SVD's answer (``scaled_condition <= limit``) on every matrix — poses about
home, matrices built with condition numbers from 1 to 1e20 and a dense band around the limit, a zero matrix
— and the inverse dynamics must still name the first singular sample with the SVD's condition number."""

import re

import numpy as np
import pytest

from stewart_drake.core import kinematics as kin
from stewart_drake.core.dynamics import MAX_CONDITION, leg_forces_with_legs
from stewart_drake.core.geometry import load_preset
from stewart_drake.errors import SingularPoseError

PLATFORM = load_preset("utn-dynamic")


def test_poses_about_home_agree_with_the_svd():
    rng = np.random.default_rng(0)
    q = PLATFORM.home_pose() + rng.normal(0, [0.05, 0.05, 0.05, 0.2, 0.2, 0.2], (5000, 6))
    J = kin.length_jacobian(PLATFORM, q)
    np.testing.assert_array_equal(
        kin.condition_at_most(PLATFORM, J, MAX_CONDITION), kin.scaled_condition(PLATFORM, J) <= MAX_CONDITION
    )


def test_constructed_condition_numbers_agree_with_the_svd():
    """Random orthogonal U, V and singular values (1, …, 1/√κ, …, 1/κ): κ from 1 to 1e20, and ±90 % about
    the limit where the bound (≤ limit/4 to decide) hands over to the SVD; one all-zero matrix (inv fails)."""
    rng = np.random.default_rng(1)
    kappas = np.concatenate([np.logspace(0, 20, 1500), MAX_CONDITION * (1 + np.linspace(-0.9, 0.9, 1500))])
    U, _, Vt = np.linalg.svd(rng.normal(size=(len(kappas), 6, 6)))
    S = np.ones((len(kappas), 6))
    S[:, -1], S[:, 2] = 1 / kappas, 1 / np.sqrt(kappas)
    A = U @ (S[..., None] * Vt)
    J = np.concatenate([A[..., :3], A[..., 3:] * kin.anchor_radius(PLATFORM)], axis=-1)  # scaled back: A
    expect = kin.scaled_condition(PLATFORM, J) <= MAX_CONDITION
    assert 0 < expect.sum() < len(expect)  # both answers occur
    np.testing.assert_array_equal(kin.condition_at_most(PLATFORM, J, MAX_CONDITION), expect)
    J[17] = 0.0
    expect[17] = False
    np.testing.assert_array_equal(kin.condition_at_most(PLATFORM, J, MAX_CONDITION), expect)


def test_singular_sample_named_with_the_svd_condition():
    """A table whose third sample is in the Euler angles' gimbal lock (a quarter turn of the first angle:
    dL/dq loses rank) names sample 3 and the SVD's condition number of that sample."""
    q = np.tile(PLATFORM.home_pose(), (4, 1))
    q[2, 3] = np.pi / 2
    k = float(kin.scaled_condition(PLATFORM, kin.length_jacobian(PLATFORM, q[2])))
    assert k > MAX_CONDITION
    with pytest.raises(SingularPoseError, match="^sample 3: .*" + re.escape(f"condition number {k:.3g} > ")):
        leg_forces_with_legs(PLATFORM, q, np.zeros(6), np.zeros(6))


@pytest.mark.parametrize("limit", [3.0, 1e3, MAX_CONDITION])
def test_condition_above_gives_the_svds_side_of_the_limit(limit):
    """``condition_above`` (κ² from the eigenvalues of AᵀA outside a band about the limit, the SVD inside it)
    answers ``scaled_condition > limit`` on every matrix: κ from 1 to 1e20, a dense band of ±1e-4 about the
    limit with some at ±1e-9 (inside the band: the SVD's call) and exactly at it, a zero matrix; at a large
    limit (1e8: κ² lost to rounding) the band covers the eigenvalue path's error, so the SVD decides there."""
    rng = np.random.default_rng(2)
    near = limit * (1 + np.concatenate([np.linspace(-1e-4, 1e-4, 400), np.linspace(-1e-9, 1e-9, 101)]))
    kappas = np.concatenate([np.logspace(0, 20, 1000), near])
    U, _, Vt = np.linalg.svd(rng.normal(size=(len(kappas), 6, 6)))
    S = np.ones((len(kappas), 6))
    S[:, -1], S[:, 2] = 1 / kappas, 1 / np.sqrt(kappas)
    A = U @ (S[..., None] * Vt)
    A[0] = 0.0
    J = np.concatenate([A[..., :3], A[..., 3:] * kin.anchor_radius(PLATFORM)], axis=-1)
    expect = kin.scaled_condition(PLATFORM, J) > limit
    assert expect[0] and 0 < expect[1000:].sum() < len(near)  # both sides occur in the band
    np.testing.assert_array_equal(kin.condition_above(PLATFORM, J, limit), expect)


def test_condition_above_on_workspace_jacobians():
    """The J⁻¹ of poses over gonzalez-dutra-2009's workspace at the report's dexterity bound κ ≤ 3: the SVD's answers."""
    g = load_preset("gonzalez-dutra-2009")
    rng = np.random.default_rng(3)
    q = g.home_pose() + rng.uniform(-1, 1, (20000, 6)) * [0.3, 0.3, 0.15, 0.3, 0.3, 0.3]
    J = kin.inverse_jacobian(g, q)
    expect = kin.scaled_condition(g, J) > 3.0
    assert 0.05 < expect.mean() < 0.95
    np.testing.assert_array_equal(kin.condition_above(g, J, 3.0), expect)


def test_one_matrix_gives_the_answer_of_a_batch():
    """One ``(6, 6)`` matrix that the bound leaves to the SVD (near the limit; exactly singular) is decided as in
    a batch, not refused with a numpy error (its answer was a 0-d array turned scalar): the leg forces at one
    pose a ten-millionth of a radian off the gimbal lock (κ ≈ 7.7e7 < 1e8) exist, those at the lock are named."""
    q = PLATFORM.home_pose() + [0.0, 0.0, 0.0, np.pi / 2 - 1e-7, 0.0, 0.0]
    J = kin.length_jacobian(PLATFORM, q)
    assert MAX_CONDITION / 4 < kin.scaled_condition(PLATFORM, J) <= MAX_CONDITION  # the SVD decides, yes
    assert (
        kin.condition_at_most(PLATFORM, J, MAX_CONDITION) == kin.condition_at_most(PLATFORM, J[None], MAX_CONDITION)[0]
    )
    assert kin.condition_at_most(PLATFORM, np.zeros((6, 6)), MAX_CONDITION) == np.False_
    F = leg_forces_with_legs(PLATFORM, q, np.zeros(6), np.zeros(6))
    assert np.array_equal(F, leg_forces_with_legs(PLATFORM, q[None], np.zeros(6), np.zeros(6))[0])
