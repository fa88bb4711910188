"""3R planar leg (seed 003): DH FK, both IK branches, the seed's corrections (Drake cross-checks:
``tests/drake/test_leg_drake.py``)."""

import numpy as np
import pytest

from stewart_drake.mechanisms.leg3r import (
    SEED_FIXES,
    Leg3R,
    UnreachableTargetError,
    foot,
    foot_jacobian,
    forward_kinematics,
    inverse_kinematics,
    inverse_kinematics_3r,
    limit_violations,
    random_configurations,
    seed_inverse_kinematics,
    seed_t03_rotation,
    within_limits,
)

LEG = Leg3R()
# Closed-form trigonometry on 0.2 m chains: a few ulps of 0.2 m.
FK_TOL = 1e-15
# IK -> FK: acos/atan2 near the annulus boundary lose a few digits; still ≪ 1 nm.
ROUND_TRIP_TOL = 1e-12


def wrap(x):
    return (x + np.pi) % (2 * np.pi) - np.pi


def test_dh_product_equals_seed_closed_form():
    q = random_configurations(LEG, 1000, seed=1)
    T, f = forward_kinematics(LEG, q), foot(LEG, q)
    assert np.abs(T[:, :2, 3] - f[:, :2]).max() < FK_TOL * 10
    # The corrected T0^3 rotation block [[sin g, cos g], [-cos g, sin g]] (the seed's is garbled).
    assert np.abs(T[:, :2, :2] - seed_t03_rotation(f[:, 2])).max() < 1e-15
    assert np.all(T[:, 2, 2] == 1) and np.all(T[:, 2, 3] == 0)


def test_alpha_is_the_seed_value():
    assert np.degrees(LEG.alpha) == pytest.approx(-45.4, abs=1e-12)


@pytest.mark.parametrize("branch", ["a", "b"])
def test_ik_fk_round_trip_both_branches(branch):
    q = random_configurations(LEG, 2000, seed=2)
    p = foot(LEG, q)[:, :2]
    qb = inverse_kinematics(LEG, p, branch)
    assert np.abs(foot(LEG, qb)[:, :2] - p).max() < ROUND_TRIP_TOL
    _, phi = LEG.shank
    elbow = wrap(qb[:, 1] + phi)
    assert np.all(elbow >= 0) if branch == "a" else np.all(elbow <= 0)
    # The 3R method with gamma: reaches position and orientation on both branches.
    f = foot(LEG, q)
    q3 = inverse_kinematics_3r(LEG, f, branch)
    err = foot(LEG, q3) - f
    assert np.abs(err[:, :2]).max() < ROUND_TRIP_TOL and np.abs(wrap(err[:, 2])).max() < 1e-12


def test_one_branch_recovers_the_original_configuration():
    q = random_configurations(LEG, 2000, seed=3)
    p = foot(LEG, q)[:, :2]
    d = np.minimum(*(np.abs(wrap(inverse_kinematics(LEG, p, b) - q)).max(1) for b in "ab"))
    # Angles recovered from positions: error ~ ulp / sin(elbow), worst for a nearly straight leg.
    assert d.max() < 1e-6 and np.median(d) < 1e-13
    q3 = inverse_kinematics_3r(LEG, foot(LEG, q), "a")
    same = np.abs(wrap(q3[:, 2] - LEG.alpha)) < 1e-9  # the branch that came from this leg has q3 = alpha
    assert same.mean() > 0.3


def test_unreachable_target_raises_naming_it():
    r_min, r_max = LEG.reach
    targets = np.array([[0.05, -0.1], [0.0, -(r_max + 1e-3)]])
    with pytest.raises(
        UnreachableTargetError,
        match=r"target 2: the foot is 184\.297 mm from the hip, outside the reachable range \[23\.297, 183\.297\] mm",
    ):
        inverse_kinematics(LEG, targets)
    with pytest.raises(UnreachableTargetError, match="the ankle"):
        inverse_kinematics_3r(LEG, [0.0, -0.3, 0.0])
    with pytest.raises(ValueError, match="unknown elbow branch 'c'"):
        inverse_kinematics(LEG, [0.0, -0.1], "c")


def test_boundary_targets_are_solved():
    r_min, r_max = LEG.reach
    for r in (r_min, r_max):
        q = inverse_kinematics(LEG, [0.0, -r], "a")
        assert np.abs(foot(LEG, q)[:2] - [0.0, -r]).max() < 1e-12


def test_joint_limits():
    q = np.array([[0.0, 0.0], [np.radians(100), 0.0], [0.0, np.radians(-140)]])
    assert within_limits(LEG, q).tolist() == [True, False, False]
    v = limit_violations(LEG, q)
    assert [(d["index"], d["joint"]) for d in v] == [([1], "q1"), ([2], "q2")]
    assert v[0]["excess_rad"] == pytest.approx(np.radians(10))


def test_jacobian_matches_finite_differences():
    q = random_configurations(LEG, 20, seed=4)
    e = 1e-6
    Jn = np.stack([(foot(LEG, q + d) - foot(LEG, q - d))[:, :2] / (2 * e) for d in ([e, 0], [0, e])], axis=-1)
    assert np.abs(foot_jacobian(LEG, q) - Jn).max() < 1e-9  # central difference error ~ e² · 0.2 m


def test_seed_ik_is_wrong_and_each_fix_is_needed():
    q = random_configurations(LEG, 500, seed=5)
    f = foot(LEG, q)
    for k in range(len(SEED_FIXES)):
        s = seed_inverse_kinematics(LEG, f, "a", SEED_FIXES[:k])
        err = np.hypot(*(foot(LEG, s) - f)[:, :2].T)
        assert np.nanmax(err) > 1e-2  # centimetres off (or no real solution) until all fixes are in
    full = seed_inverse_kinematics(LEG, f, "a", SEED_FIXES)
    assert np.abs(wrap(full - inverse_kinematics_3r(LEG, f, "a"))).max() < 1e-12
