import numpy as np
import pytest

from stewart_drake.core.rotations import (
    angles_from_matrix,
    angular_velocity_map,
    convert_angles,
    pose_from_si,
    pose_to_si,
    rotation_matrix,
)

RNG = np.random.default_rng(7)
# Away from gimbal lock (middle angle ±90°) the inverse is unique; 1e-12 rad is float round-off.
ANGLES = RNG.uniform([-np.pi, -1.4, -np.pi], [np.pi, 1.4, np.pi], (500, 3))


def test_utn_is_ry_rx_rz_written_out_as_in_the_seed():
    a, b, g = 0.3, -0.7, 1.1
    ca, sa, cb, sb, cg, sg = np.cos(a), np.sin(a), np.cos(b), np.sin(b), np.cos(g), np.sin(g)
    ttb = np.array(  # seed 000 Stewart.m, element by element
        [
            [cb * cg + sa * sb * sg, -cb * sg + sa * sb * cg, ca * sb],
            [ca * sg, ca * cg, -sa],
            [-sb * cg + sa * cb * sg, sb * sg + sa * cb * cg, ca * cb],
        ]
    )
    np.testing.assert_allclose(rotation_matrix([a, b, g], "utn"), ttb, atol=1e-15)


@pytest.mark.parametrize("convention", ["utn", "zyx"])
def test_angles_round_trip(convention):
    # utn's middle angle is alpha (about X), zyx's is theta (about Y): put the bounded one in the middle.
    ang = ANGLES[:, [1, 0, 2]] if convention == "utn" else ANGLES
    back = angles_from_matrix(rotation_matrix(ang, convention), convention)
    np.testing.assert_allclose(back, ang, atol=1e-12)


def test_convert_between_conventions_keeps_the_rotation():
    ang = ANGLES[:, [1, 0, 2]]
    zyx = convert_angles(ang, "utn", "zyx")
    np.testing.assert_allclose(rotation_matrix(zyx, "zyx"), rotation_matrix(ang, "utn"), atol=1e-13)


def test_gimbal_lock_gives_a_valid_decomposition():
    R = rotation_matrix([np.pi / 2, 0.4, 0.3], "utn")
    back = angles_from_matrix(R, "utn")
    np.testing.assert_allclose(rotation_matrix(back, "utn"), R, atol=1e-12)


@pytest.mark.parametrize("convention", ["utn", "zyx"])
def test_angular_velocity_map_against_finite_differences(convention):
    # ω^ = Ṙ Rᵀ; central differences with h = 1e-6 are accurate to ~h² ≈ 1e-12 plus round-off ~1e-10.
    h = 1e-6
    for ang in ANGLES[:20, [1, 0, 2]] if convention == "utn" else ANGLES[:20]:
        rate = RNG.normal(size=3)
        Rdot = (rotation_matrix(ang + h * rate, convention) - rotation_matrix(ang - h * rate, convention)) / (2 * h)
        W = Rdot @ rotation_matrix(ang, convention).T
        omega = np.array([W[2, 1], W[0, 2], W[1, 0]])
        np.testing.assert_allclose(angular_velocity_map(ang, convention) @ rate, omega, atol=1e-8)


def test_units_at_the_edges():
    q = pose_to_si([100, 0, 50, 0.1, 18, 0], "mm", "pi")
    np.testing.assert_allclose(q, [0.1, 0, 0.05, 0.1 * np.pi, 18 * np.pi, 0])
    np.testing.assert_allclose(pose_from_si(q, "mm", "pi"), [100, 0, 50, 0.1, 18, 0])
    np.testing.assert_allclose(pose_to_si([0, 0, 0, 180, 90, 0], "m", "deg")[3:], [np.pi, np.pi / 2, 0])


def test_bad_names_are_reported():
    with pytest.raises(ValueError, match="unknown rotation convention 'xyz'"):
        rotation_matrix([0, 0, 0], "xyz")
    with pytest.raises(ValueError, match="unknown angle unit 'grad'"):
        pose_to_si([0] * 6, "m", "grad")
    with pytest.raises(ValueError, match="unknown length unit 'in'"):
        pose_to_si([0] * 6, "in", "rad")
    with pytest.raises(ValueError, match=r"a pose needs 6 numbers .* got shape \(5,\)"):
        pose_to_si([0] * 5)
