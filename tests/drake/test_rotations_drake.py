"""Rotation conventions (``core/rotations``) cross-checked against Drake's RollPitchYaw, RotationMatrix
and Quaternion (``drake/conversions``)."""

import numpy as np
import pytest
from pydrake.common.eigen_geometry import Quaternion
from pydrake.math import RollPitchYaw, RotationMatrix

from stewart_drake.core.rotations import angles_from_matrix, quaternion_to_matrix, rotation_matrix
from stewart_drake.drake.conversions import from_drake, to_drake

RNG = np.random.default_rng(7)
# Away from gimbal lock (middle angle ±90°) the inverse is unique; 1e-12 rad is float round-off.
ANGLES = RNG.uniform([-np.pi, -1.4, -np.pi], [np.pi, 1.4, np.pi], (500, 3))


def test_zyx_matches_drake_roll_pitch_yaw():
    for ang in ANGLES[:50]:
        R = RotationMatrix(RollPitchYaw(*ang)).matrix()
        np.testing.assert_allclose(rotation_matrix(ang, "zyx"), R, atol=1e-14)
        np.testing.assert_allclose(from_drake(RollPitchYaw(*ang), "zyx"), ang, atol=1e-12)


def test_drake_round_trip_utn():
    ang = np.array([0.2, -0.4, 0.9])
    np.testing.assert_allclose(from_drake(to_drake(ang, "utn"), "utn"), ang, atol=1e-13)


def test_quaternion_to_matrix_matches_drake():
    """Against Drake's Quaternion -> RotationMatrix (Eigen's formula, written differently): equal to a few
    ulps; q and -q and any positive scaling give the same rotation."""
    q = RNG.normal(size=(40, 4))
    R = quaternion_to_matrix(q)
    for qk, Rk in zip(q / np.linalg.norm(q, axis=-1, keepdims=True), R):
        np.testing.assert_allclose(
            Rk, RotationMatrix(Quaternion(qk)).matrix(), atol=2e-15
        )  # entries <= 1: a few roundings of 1.1e-16
    np.testing.assert_allclose(quaternion_to_matrix(-3.0 * q), R, atol=1e-15)
    np.testing.assert_allclose(quaternion_to_matrix(q.reshape(2, 20, 4)), R.reshape(2, 20, 3, 3), atol=0)
    np.testing.assert_allclose(
        from_drake(Quaternion(q[0] / np.linalg.norm(q[0]))), angles_from_matrix(R[0]), atol=1e-13
    )
    with pytest.raises(ValueError, match=r"quaternions need 4 numbers \(w, x, y, z\), got shape \(3,\)"):
        quaternion_to_matrix([1.0, 0.0, 0.0])
