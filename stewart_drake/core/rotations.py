"""Named Euler-angle conventions and angle units.

A pose is ``(..., 6)``: ``[px, py, pz, a_x, a_y, a_z]`` in metres and radians, where ``a_x``, ``a_y``,
``a_z`` are the angles *about* the base X, Y and Z axes. The convention names the order in which the
three elementary rotations compose:

- ``utn``  (seeds 000/001/004): ``R = Ry(beta) @ Rx(alpha) @ Rz(gamma)`` with (alpha, beta, gamma) =
  (a_x, a_y, a_z). Singular (gimbal lock) at alpha = ±pi/2.
- ``zyx``  (seed 002, yaw-pitch-roll, Drake's ``RollPitchYaw``): ``R = Rz(psi) @ Ry(theta) @ Rx(phi)``
  with (phi, theta, psi) = (a_x, a_y, a_z). Singular at theta = ±pi/2.

Units at the edges: ``rad``, ``deg`` and ``pi`` (a fraction of pi, as the DSP code takes them).
"""

from __future__ import annotations

import numpy as np

from stewart_drake.errors import RotationError

CONVENTIONS = ("utn", "zyx")
ANGLE_UNITS = {"rad": 1.0, "deg": np.pi / 180.0, "pi": np.pi}
LENGTH_UNITS = {"m": 1.0, "mm": 1e-3}


def check_convention(convention: str) -> str:
    """Return ``convention`` if it is known, else raise RotationError naming it."""
    if not isinstance(convention, str) or convention not in CONVENTIONS:
        raise RotationError(RotationError.CONVENTION.format(value=convention, valid=", ".join(CONVENTIONS)))
    return convention


def angle_scale(unit: str) -> float:
    """Radians per ``unit`` (``rad``, ``deg`` or ``pi``)."""
    try:
        return ANGLE_UNITS[unit]
    except KeyError:
        raise RotationError(RotationError.ANGLE_UNIT.format(value=unit, valid=", ".join(ANGLE_UNITS))) from None


def length_scale(unit: str) -> float:
    """Metres per ``unit`` (``m`` or ``mm``)."""
    try:
        return LENGTH_UNITS[unit]
    except KeyError:
        raise RotationError(RotationError.LENGTH_UNIT.format(value=unit, valid=", ".join(LENGTH_UNITS))) from None


def to_radians(angles, unit: str) -> np.ndarray:
    """Angles in ``unit`` -> radians, any shape."""
    return np.asarray(angles, dtype=float) * angle_scale(unit)


def from_radians(angles, unit: str) -> np.ndarray:
    """Radians -> angles in ``unit``, any shape."""
    return np.asarray(angles, dtype=float) / angle_scale(unit)


def pose_to_si(pose, length_unit: str = "m", angle_unit: str = "rad") -> np.ndarray:
    """A ``(..., 6)`` pose in edge units -> metres and radians."""
    pose = np.asarray(pose, dtype=float)
    if pose.shape[-1:] != (6,):
        raise RotationError(RotationError.POSE_SHAPE.format(shape=pose.shape))
    scale = np.r_[np.full(3, length_scale(length_unit)), np.full(3, angle_scale(angle_unit))]
    return pose * scale


def pose_from_si(pose, length_unit: str = "m", angle_unit: str = "rad") -> np.ndarray:
    """A ``(..., 6)`` pose in metres and radians -> edge units."""
    scale = np.r_[np.full(3, length_scale(length_unit)), np.full(3, angle_scale(angle_unit))]
    return np.asarray(pose, dtype=float) / scale


def _rx(t):
    c, s, o, z = np.cos(t), np.sin(t), np.ones_like(t), np.zeros_like(t)
    return np.stack([o, z, z, z, c, -s, z, s, c], -1).reshape(t.shape + (3, 3))


def _ry(t):
    c, s, o, z = np.cos(t), np.sin(t), np.ones_like(t), np.zeros_like(t)
    return np.stack([c, z, s, z, o, z, -s, z, c], -1).reshape(t.shape + (3, 3))


def _rz(t):
    c, s, o, z = np.cos(t), np.sin(t), np.ones_like(t), np.zeros_like(t)
    return np.stack([c, -s, z, s, c, z, z, z, o], -1).reshape(t.shape + (3, 3))


def rotation_matrix(angles, convention: str = "utn") -> np.ndarray:
    """``(..., 3)`` angles about X, Y, Z in radians -> ``(..., 3, 3)`` rotation matrices R_BT."""
    check_convention(convention)
    angles = np.asarray(angles, dtype=float)
    if angles.shape[-1:] != (3,):
        raise RotationError(RotationError.ANGLES_SHAPE.format(shape=angles.shape))
    ca, cb, cg = np.moveaxis(np.cos(angles), -1, 0)
    sa, sb, sg = np.moveaxis(np.sin(angles), -1, 0)
    if convention == "utn":  # Ry(beta) Rx(alpha) Rz(gamma), the seeds' TTB written out
        rows = (
            cb * cg + sa * sb * sg,
            sa * sb * cg - cb * sg,
            ca * sb,
            ca * sg,
            ca * cg,
            -sa,
            sa * cb * sg - sb * cg,
            sb * sg + sa * cb * cg,
            ca * cb,
        )
    else:  # Rz(psi) Ry(theta) Rx(phi) with (phi, theta, psi) = (a_x, a_y, a_z)
        rows = (
            cb * cg,
            sa * sb * cg - ca * sg,
            ca * sb * cg + sa * sg,
            cb * sg,
            sa * sb * sg + ca * cg,
            ca * sb * sg - sa * cg,
            -sb,
            sa * cb,
            ca * cb,
        )
    return np.stack(rows, -1).reshape(angles.shape[:-1] + (3, 3))


def angles_from_matrix(R, convention: str = "utn") -> np.ndarray:
    """``(..., 3, 3)`` rotation matrices -> ``(..., 3)`` angles about X, Y, Z (radians).

    The middle angle is returned in [-pi/2, pi/2]; the other two in (-pi, pi]. At the convention's
    gimbal lock the split between the outer two angles is arbitrary (the first is set to 0 there).
    """
    check_convention(convention)
    R = np.asarray(R, dtype=float)
    if convention == "utn":
        alpha = np.arcsin(np.clip(-R[..., 1, 2], -1.0, 1.0))
        beta = np.arctan2(R[..., 0, 2], R[..., 2, 2])
        gamma = np.arctan2(R[..., 1, 0], R[..., 1, 1])
        lock = np.hypot(R[..., 0, 2], R[..., 2, 2]) < 1e-12
        if np.any(lock):
            # R = Ry(beta) Rx(±pi/2) Rz(gamma): only beta ∓ gamma is determined; put it all in beta.
            beta = np.where(lock, np.arctan2(-R[..., 2, 0], R[..., 0, 0]), beta)
            gamma = np.where(lock, 0.0, gamma)
        return np.stack([alpha, beta, gamma], -1)
    theta = np.arcsin(np.clip(-R[..., 2, 0], -1.0, 1.0))
    phi = np.arctan2(R[..., 2, 1], R[..., 2, 2])
    psi = np.arctan2(R[..., 1, 0], R[..., 0, 0])
    lock = np.hypot(R[..., 2, 1], R[..., 2, 2]) < 1e-12
    if np.any(lock):
        phi = np.where(lock, 0.0, phi)
        psi = np.where(lock, np.arctan2(-R[..., 0, 1], R[..., 1, 1]), psi)
    return np.stack([phi, theta, psi], -1)


def convert_angles(angles, source: str, target: str) -> np.ndarray:
    """Re-express ``(..., 3)`` angles of one convention in another (same rotation)."""
    if check_convention(source) == check_convention(target):
        return np.asarray(angles, dtype=float).copy()
    return angles_from_matrix(rotation_matrix(angles, source), target)


def angular_velocity_map(angles, convention: str = "utn") -> np.ndarray:
    """``(..., 3, 3)`` matrix E_W with ω_W = E_W(angles) · d(angles)/dt (world-frame angular velocity).

    Columns are the rotation axes of each angle expressed in the base frame.
    """
    check_convention(convention)
    angles = np.asarray(angles, dtype=float)
    ax, ay, az = angles[..., 0], angles[..., 1], angles[..., 2]
    ex = np.broadcast_to(np.array([1.0, 0.0, 0.0]), angles.shape)
    ey = np.broadcast_to(np.array([0.0, 1.0, 0.0]), angles.shape)
    ez = np.broadcast_to(np.array([0.0, 0.0, 1.0]), angles.shape)
    if convention == "utn":  # Ry(b) Rx(a) Rz(g): b about Y_B; a about Ry·X; g about Ry·Rx·Z
        Ry = _ry(ay)
        w_a = Ry @ ex[..., None]
        w_b = ey[..., None]
        w_g = Ry @ _rx(ax) @ ez[..., None]
    else:  # Rz(psi) Ry(theta) Rx(phi): psi about Z_B; theta about Rz·Y; phi about Rz·Ry·X
        Rz = _rz(az)
        w_g = ez[..., None]
        w_b = Rz @ ey[..., None]
        w_a = Rz @ _ry(ay) @ ex[..., None]
    return np.concatenate([w_a, w_b, w_g], axis=-1)


def quaternion_to_matrix(q) -> np.ndarray:
    """``(..., 4)`` quaternions [w, x, y, z] (normalised here; any non-zero length) -> ``(..., 3, 3)``
    rotation matrices (Hamilton convention, as Drake's ``Quaternion``)."""
    q = np.asarray(q, dtype=float)
    if q.shape[-1:] != (4,):
        raise RotationError(RotationError.QUATERNION_SHAPE.format(shape=q.shape))
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    w, x, y, z = np.moveaxis(q, -1, 0)
    return np.stack(
        [
            1 - 2 * (y * y + z * z),
            2 * (x * y - w * z),
            2 * (x * z + w * y),
            2 * (x * y + w * z),
            1 - 2 * (x * x + z * z),
            2 * (y * z - w * x),
            2 * (x * z - w * y),
            2 * (y * z + w * x),
            1 - 2 * (x * x + y * y),
        ],
        axis=-1,
    ).reshape(q.shape[:-1] + (3, 3))


def wrap_angle(x) -> np.ndarray:
    """Angles ``x`` (radians, any shape) wrapped to [-pi, pi)."""
    return (np.asarray(x) + np.pi) % (2 * np.pi) - np.pi
