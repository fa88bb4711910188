import re

import numpy as np
import pytest

from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import (
    check_stroke,
    condition_number,
    inverse_jacobian,
    inverse_kinematics,
    leg_lengths,
    leg_unit_vectors,
    length_jacobian,
    plate_anchors,
    require_nonsingular,
)
from stewart_drake.core.rotations import rotation_matrix
from stewart_drake.core.sampling import random_poses
from stewart_drake.errors import (
    NOT_FINITE_SAMPLE,
    SHAPE,
    NotFiniteError,
    ShapeError,
    SingularPoseError,
    UnreachablePoseError,
)


def test_utn_home_pose_is_473_2_mm():
    p = load_preset("utn-kinematic")
    L = leg_lengths(p, [0, 0, 0.100, 0, 0, 0])
    # Seed table: 473 mm on every leg; exact value sqrt(100² + r²) with r the horizontal leg span.
    np.testing.assert_allclose(L * 1e3, 473.2, atol=0.05)
    assert np.ptp(L) < 1e-12


def test_against_the_seed_formula_for_each_leg():
    # Seed 000 Stewart.m: L1..L6 written out term by term with the base coordinates inline (mm).
    b, d, a = 925.0, 150.0, 612.5
    p = load_preset("utn-kinematic")
    q = np.array([10.0, -20.0, 140.0, 0.3, -0.2, 0.4])
    R = rotation_matrix(q[3:], "utn")
    s = np.sqrt(3)
    t1, t2, t3 = (q[:3] + R @ v for v in ([s / 6 * a, a / 2, 0], [-s / 3 * a, 0, 0], [s / 6 * a, -a / 2, 0]))
    seed = [
        np.sqrt((t1[0] - d / (2 * s) - b / s) ** 2 + (t1[1] - d / 2) ** 2 + t1[2] ** 2),
        np.sqrt((t1[0] - d / (2 * s) + b / (2 * s)) ** 2 + (t1[1] - d / 2 - b / 2) ** 2 + t1[2] ** 2),
        np.sqrt((t2[0] + d / s + b / (2 * s)) ** 2 + (t2[1] - b / 2) ** 2 + t2[2] ** 2),
        np.sqrt((t2[0] + d / s + b / (2 * s)) ** 2 + (t2[1] + b / 2) ** 2 + t2[2] ** 2),
        np.sqrt((t3[0] - d / (2 * s) + b / (2 * s)) ** 2 + (t3[1] + b / 2 + d / 2) ** 2 + t3[2] ** 2),
        np.sqrt((t3[0] - d / (2 * s) - b / s) ** 2 + (t3[1] + d / 2) ** 2 + t3[2] ** 2),
    ]
    q_si = np.r_[q[:3] * 1e-3, q[3:]]
    np.testing.assert_allclose(leg_lengths(p, q_si) * 1e3, seed, rtol=1e-13)


def test_batched_equals_one_by_one(preset):
    q = random_poses(preset, 60, seed=3).reshape(3, 4, 5, 6)
    L = leg_lengths(preset, q)
    assert L.shape == (3, 4, 5, 6)
    for idx in np.ndindex(3, 4, 5):
        np.testing.assert_array_equal(L[idx], leg_lengths(preset, q[idx]))


def test_rotation_centre_offset_rotates_about_that_point():
    p = load_preset("utn-dynamic")
    c = np.array([0.0, 0.0, 0.05])
    pc = p.replace(rotation_centre=c)
    q = np.array([0.01, 0.02, 0.75, 0.2, -0.1, 0.3])
    # With the centre offset, the plate point C sits at (px, py, pz) whatever the rotation.
    anchors = plate_anchors(pc, q)
    R = rotation_matrix(q[3:])
    np.testing.assert_allclose(anchors, q[:3] + (p.top_anchors_per_leg - c) @ R.T)
    # Same plate placement expressed with the T origin as reference point.
    q_origin = np.r_[q[:3] - R @ c, q[3:]]
    np.testing.assert_allclose(leg_lengths(pc, q), leg_lengths(p, q_origin), atol=1e-15)


@pytest.mark.parametrize("convention", ["utn", "zyx"])
def test_length_jacobian_against_finite_differences(preset, convention):
    # Central differences, h = 1e-6: truncation ~h²·L''' ≈ 1e-12, round-off ~eps·L/h ≈ 1e-10.
    h = 1e-6
    for q in random_poses(preset, 20, seed=5):
        J = length_jacobian(preset, q, convention)
        fd = np.stack(
            [
                (leg_lengths(preset, q + h * e, convention) - leg_lengths(preset, q - h * e, convention)) / (2 * h)
                for e in np.eye(6)
            ],
            -1,
        )
        np.testing.assert_allclose(J, fd, atol=1e-8)


def test_inverse_jacobian_maps_twists_to_leg_rates(preset):
    # Move the plate along a twist (v, ω) for a small time; the leg-length change is J⁻¹·twist·dt.
    rng = np.random.default_rng(11)
    dt = 1e-6
    for q in random_poses(preset, 10, seed=6):
        v, w = rng.normal(size=3) * 0.1, rng.normal(size=3)
        R = rotation_matrix(q[3:])
        th = np.linalg.norm(w) * dt
        k = w / np.linalg.norm(w)
        K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
        dR = np.eye(3) + np.sin(th) * K + (1 - np.cos(th)) * K @ K
        moved = q[:3] + v * dt + (preset.top_anchors_per_leg - preset.rotation_centre) @ (dR @ R).T
        L1 = np.linalg.norm(moved - preset.base_anchors, axis=1)
        rate = (L1 - leg_lengths(preset, q)) / dt
        np.testing.assert_allclose(rate, inverse_jacobian(preset, q) @ np.r_[v, w], atol=1e-5)


def test_unit_vectors_are_unit(preset):
    u = leg_unit_vectors(preset, random_poses(preset, 50))
    np.testing.assert_allclose(np.linalg.norm(u, axis=-1), 1.0, atol=1e-15)


def test_stroke_violation_names_pose_leg_and_amount():
    p = load_preset("utn-kinematic")
    poses = np.array([[0, 0, 0.1, 0, 0, 0], [0, 0, 0.6, 0, 0, 0]])
    L = leg_lengths(p, poses)
    check = check_stroke(p, L)
    assert check.within.tolist() == [True, False]
    v = check.violations()
    assert [x["leg"] for x in v] == [1, 2, 3, 4, 5, 6] and all(x["pose"] == [1] for x in v)
    assert v[0]["excess_m"] == pytest.approx(L[1, 0] - 0.7)
    with pytest.raises(
        UnreachablePoseError,
        match=r"pose 2: leg 1 length \d+\.\d{3} mm is \d+\.\d{3} mm above the stroke maximum 700\.000 mm",
    ) as e:
        inverse_kinematics(p, poses)
    assert e.value.leg == 1 and e.value.excess == pytest.approx(L[1, 0] - 0.7)


def test_below_minimum_is_reported():
    p = load_preset("utn-dynamic")
    with pytest.raises(UnreachablePoseError, match=r"pose 1: leg \d length .* below the stroke minimum 550\.000 mm"):
        inverse_kinematics(p, [0, 0, 0.3, 0, 0, 0])


def test_bad_pose_input():
    p = load_preset("utn-dynamic")
    # ShapeError and NotFiniteError are ValueErrors too (callers that catch ValueError keep working).
    with pytest.raises(ShapeError, match=re.escape(SHAPE.format(name="poses", shape="(..., 6)", got="(4, 5)"))):
        leg_lengths(p, np.zeros((4, 5)))
    bad = [0.0, 0.0, np.nan, 0.0, 0.0, 0.0]
    with pytest.raises(NotFiniteError, match=re.escape(NOT_FINITE_SAMPLE.format(what="pose", index=3, values=bad))):
        leg_lengths(p, np.r_[[p.home_pose()] * 2, [bad]])
    assert issubclass(ShapeError, ValueError) and issubclass(NotFiniteError, ValueError)


def test_singular_pose_is_reported():
    p = load_preset("utn-dynamic")
    # The plate in the base plane at zero orientation: every leg is horizontal, so no leg resists a
    # vertical force (the z column of J⁻¹ vanishes).
    q = np.array([0, 0, 0, 0, 0, 0.0])
    assert condition_number(p, q) > 1e12
    with pytest.raises(SingularPoseError, match=r"pose 1 is singular or nearly so: Jacobian condition number"):
        require_nonsingular(p, q)
    assert condition_number(p, p.home_pose()) < 100
