"""Conversions between the numpy rotations of ``core/rotations`` and Drake's rotation types."""

from __future__ import annotations

import numpy as np
from pydrake.common.eigen_geometry import Quaternion
from pydrake.math import RollPitchYaw, RotationMatrix

from stewart_drake.core.rotations import angles_from_matrix, rotation_matrix


def to_drake(angles, convention: str = "utn") -> RotationMatrix:
    """One ``(3,)`` angle triple (radians, ``convention``) -> ``pydrake.math.RotationMatrix``."""
    R = rotation_matrix(np.asarray(angles, dtype=float).reshape(3), convention)
    return RotationMatrix(R)


def from_drake(rotation, convention: str = "utn") -> np.ndarray:
    """A Drake ``RotationMatrix``, ``RollPitchYaw`` or ``Quaternion`` -> ``(3,)`` angles (radians)."""
    if isinstance(rotation, (RollPitchYaw, Quaternion)):
        rotation = RotationMatrix(rotation)
    if not isinstance(rotation, RotationMatrix):
        raise TypeError(f"expected a Drake RotationMatrix, RollPitchYaw or Quaternion, got {type(rotation).__name__}")
    return angles_from_matrix(rotation.matrix(), convention)
