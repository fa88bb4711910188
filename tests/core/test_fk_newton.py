"""Batched Newton forward kinematics and Jacobian analysis (``stewart_drake.core.newton_fk``, plain numpy)."""

import numpy as np
import pytest

from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import condition_number, inverse_jacobian, leg_lengths
from stewart_drake.core.newton_fk import (
    CONVERGED,
    check_poses_nonsingular,
    forward_kinematics,
    jacobian_analysis,
    legs_and_jacobian,
    validate_lengths,
)
from stewart_drake.core.rotations import rotation_matrix
from stewart_drake.core.sampling import random_poses
from stewart_drake.errors import ForwardKinematicsError, SingularityWarning, SingularPoseError


def _exp(w):
    th = np.linalg.norm(w)
    K = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]]) / th
    return np.eye(3) + np.sin(th) * K + (1 - np.cos(th)) * K @ K


def test_jacobian_matches_kinematics(preset):
    """The R-based evaluator used by Newton reproduces kinematics.leg_lengths / inverse_jacobian
    (same formulas, other arithmetic order: agreement to a few ulps)."""
    q = random_poses(preset, 50, seed=3, region="workspace")
    L, J = legs_and_jacobian(preset, q[:, :3], rotation_matrix(q[:, 3:]))
    np.testing.assert_allclose(L, leg_lengths(preset, q), rtol=1e-14)
    np.testing.assert_allclose(J, inverse_jacobian(preset, q), atol=1e-14)


def test_jacobian_against_finite_differences():
    """Column j of J⁻¹ is dL/dt along the twist e_j (p += h e_j, or R <- exp(h e_j) R).
    Central differences with h = 1e-6 have truncation error ~h² |L''| ~ 1e-12 and rounding ~1e-16/h."""
    p = load_preset("gonzalez-dutra-2009")
    q = random_poses(p, 5, seed=4, region="workspace")
    h = 1e-6
    for pose in q:
        P, R = pose[:3], rotation_matrix(pose[3:])
        _, J = legs_and_jacobian(p, P[None], R[None])
        for j in range(6):
            e = np.zeros(3)
            e[j % 3] = h
            if j < 3:
                plus, minus = (P + e, R), (P - e, R)
            else:
                plus, minus = (P, _exp(e) @ R), (P, _exp(-e) @ R)
            Lp, _ = legs_and_jacobian(p, plus[0][None], plus[1][None])
            Lm, _ = legs_and_jacobian(p, minus[0][None], minus[1][None])
            np.testing.assert_allclose((Lp - Lm)[0] / (2 * h), J[0, :, j], atol=1e-8)


def test_round_trip_1000_poses_per_preset(preset):
    """IK -> FK from home returns the original pose to 1e-9 m / 1e-9 rad.

    Poses are restricted to home's singularity-free region (same sign of det J⁻¹ as home) and to
    κ₂ <= 1e4: beyond a singularity the same lengths belong to another assembly mode, which Newton from
    home correctly does not return (see test_round_trip_beyond_singularity). Bound: the pose error is
    about tol/σ_min; with tol = 1e-13 m and σ_min >= ~1e-4 (κ₂ <= 1e4) that is <= 1e-9."""
    q = random_poses(preset, 1300, seed=11, region="workspace")
    a = jacobian_analysis(preset, q)
    home = jacobian_analysis(preset, preset.home_pose())
    q = q[(a.det_sign == home.det_sign) & (a.condition <= 1e4)]
    assert len(q) >= 1000
    r = forward_kinematics(preset, leg_lengths(preset, q))
    assert r.converged.all() and (r.status == CONVERGED).all()
    assert np.abs(r.poses[:, :3] - q[:, :3]).max() <= 1e-9
    assert np.abs(r.poses[:, 3:] - q[:, 3:]).max() <= 1e-9
    assert r.residual.max() <= 1e-13
    assert not r.near_singular.any()


def test_round_trip_beyond_singularity():
    """utn-kinematic (wide and low) has workspace poses across a singularity from home. FK from home
    mostly returns another assembly mode for their lengths (a valid solution, not the sampled pose);
    FK started near the pose (trajectory following) returns the pose itself."""
    p = load_preset("utn-kinematic")
    q = random_poses(p, 3000, seed=11, region="workspace")
    a = jacobian_analysis(p, q)
    # κ₂ <= 1e3: nearer the singularity two modes lie within a fraction of a millimetre of each other,
    # and even a close guess may land in the neighbour.
    far = q[(a.det_sign != jacobian_analysis(p, p.home_pose()).det_sign) & (a.condition <= 1e3)]
    assert len(far) >= 20
    L = leg_lengths(p, far)
    from_home = forward_kinematics(p, L, on_singular="ignore")
    other = from_home.converged & (np.abs(from_home.poses - far).max(-1) > 1e-6)
    assert other.mean() > 0.5
    np.testing.assert_allclose(leg_lengths(p, from_home.poses[other]), L[other], atol=1e-12)
    nearby = forward_kinematics(p, L, far + 1e-4)  # 0.1 mm and 0.1 mrad off
    np.testing.assert_allclose(nearby.poses, far, atol=1e-9)


def test_trajectory_following_uses_previous_pose():
    """Following a 100 Hz trajectory, each solve starts from the previous pose and converges in a few
    iterations (quadratic convergence from a 1 mm / 0.01 rad guess)."""
    p = load_preset("utn-dynamic")
    t = np.arange(0, 2, 0.01)
    traj = np.zeros((len(t), 6))
    traj[:, 0], traj[:, 1], traj[:, 2] = 0.05 * np.sin(2 * t), 0.05 * np.cos(3 * t), 0.7 + 0.02 * np.sin(t)
    traj[:, 3], traj[:, 5] = 0.1 * np.sin(t), 0.2 * np.sin(2 * t)
    L = leg_lengths(p, traj)
    prev = traj[0]
    for k in range(len(t)):
        r = forward_kinematics(p, L[k], prev, check_singularity=False)
        assert r.converged and r.iterations <= 4
        np.testing.assert_allclose(r.poses, traj[k], atol=1e-10)
        prev = r.poses


def test_impossible_lengths_reported_not_returned():
    """utn-kinematic legs 1 and 2 share plate joint T1 and their base anchors are b = 925 mm apart, so
    |L1 − L2| <= 925 mm for any assembly: L1 = 300 mm, L2 = 1300 mm is impossible."""
    p = load_preset("utn-kinematic")
    good = leg_lengths(p, p.home_pose())
    bad = good.copy()
    bad[0], bad[1] = 0.3, 1.3
    r = forward_kinematics(p, np.stack([good, bad]))
    assert r.converged.tolist() == [True, False]
    assert r.failures() == [(1,)]
    assert np.isnan(r.poses[1]).all() and np.isfinite(r.iterate[1]).all()
    assert r.residual[1] > 1e-3  # the triangle inequality is violated by 75 mm
    with pytest.raises(
        ForwardKinematicsError, match=r"lengths sample 2 \(.*300\.000, 1300\.000.* mm\) (did not converge|diverged)"
    ):
        r.raise_if_failed()


def test_iteration_limit_and_max_step():
    """A 50 mm move with steps capped at 1 mm needs >= 50 iterations; with 10 allowed it must fail."""
    p = load_preset("utn-dynamic")
    target = p.home_pose() + [0.05, 0, 0, 0, 0, 0]
    L = leg_lengths(p, target)
    r = forward_kinematics(p, L, max_step_m=1e-3, max_iter=10)
    assert not r.converged and r.iterations == 10
    with pytest.raises(ForwardKinematicsError, match="did not converge within the iteration limit after 10 iterations"):
        r.raise_if_failed()
    r = forward_kinematics(p, L, max_step_m=1e-3, max_iter=100)
    assert r.converged and 50 <= r.iterations <= 55
    np.testing.assert_allclose(r.poses, target, atol=1e-12)


def test_singularity_checks():
    """The 3-6 platform is singular when the plate turns 90° about Z (a classical result, found here by
    bisection on the sign of det J⁻¹): the check raises, and Newton warns when started there."""
    p = load_preset("utn-dynamic")
    sing = p.home_pose() + [0, 0, 0, 0, 0, np.pi / 2]
    assert jacobian_analysis(p, sing).condition > 1e12
    with pytest.raises(SingularPoseError, match=r"pose 1 is near a singularity: Jacobian condition number .* > 1e\+08"):
        check_poses_nonsingular(p, sing)
    L = leg_lengths(p, p.home_pose() + [0.01, 0, 0, 0, 0, 0])
    with pytest.warns(SingularityWarning, match="initial pose"):
        forward_kinematics(p, L, sing)
    with pytest.raises(SingularPoseError, match="initial pose"):
        forward_kinematics(p, L, sing, on_singular="raise")


def test_near_singular_solution_flagged():
    """A solution close to the 90° singularity is returned but flagged and warned about."""
    p = load_preset("utn-dynamic")
    q = p.home_pose() + [0, 0, 0, 0, 0, np.pi / 2 - 1e-9]
    with pytest.warns(SingularityWarning, match="forward-kinematics solution"):
        r = forward_kinematics(p, leg_lengths(p, q), q + [0, 0, 0, 0, 0, -1e-3], max_condition=1e6)
    assert r.near_singular


def test_jacobian_analysis_consistent_with_kinematics():
    p = load_preset("gonzalez-dutra-2009")
    q = random_poses(p, 20, seed=5, region="workspace")
    a = jacobian_analysis(p, q)
    np.testing.assert_allclose(a.condition, condition_number(p, q), rtol=1e-10)
    # Frobenius condition used inside Newton brackets the 2-norm one: κ₂ <= κ_F <= 6 κ₂.
    r = forward_kinematics(p, leg_lengths(p, q), q)
    assert np.all((r.condition >= a.condition * (1 - 1e-12)) & (r.condition <= 6 * a.condition))


def test_input_validation():
    p = load_preset("utn-dynamic")
    with pytest.raises(ValueError, match=r"lengths sample 1: leg 3 length -0.1 m is not a positive finite number"):
        validate_lengths([0.7, 0.7, -0.1, 0.7, 0.7, 0.7])
    with pytest.raises(ValueError, match=r"shape \(\.\.\., 6\)"):
        forward_kinematics(p, [0.7] * 5)
    with pytest.raises(ValueError, match="on_singular must be"):
        forward_kinematics(p, [0.7] * 6, on_singular="loud")
    with pytest.raises(ValueError, match="max_iter must be a positive integer"):
        forward_kinematics(p, [0.7] * 6, max_iter=0)
    with pytest.raises(ValueError, match="do not match lengths"):
        forward_kinematics(p, np.full((4, 6), 0.7), np.zeros((3, 6)))
