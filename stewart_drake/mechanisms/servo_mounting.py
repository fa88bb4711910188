"""The frames of the RC-servo hexapod's Drake model (numpy only): where each servo's joint sits, which
way it turns, and the joint angles that correspond to pulse widths and arm elevations.

The servo joint's axis is the direction in which an increasing pulse turns the horn (``-shaft_i``), so
the joint angle is the servo's mechanical angle, zero with the arm horizontal along ``beta_i``. Nothing
here encodes the seed's odd/even rule: the mirroring comes out of the mounting.
"""

from __future__ import annotations

import numpy as np

from stewart_drake.mechanisms.servo import ServoHexapod, arm_tips


def frame_from_zx(z, x_hint) -> np.ndarray:
    """``(3, 3)`` a rotation matrix whose z column is ``z`` (3,) and x column is ``x_hint`` (3,) made
    orthogonal to it (another horizontal-ish axis when ``x_hint`` is parallel to ``z``)."""
    z = np.asarray(z, float) / np.linalg.norm(z)
    x = np.asarray(x_hint, float) - (np.asarray(x_hint, float) @ z) * z
    if np.linalg.norm(x) < 1e-9:
        x = np.cross([0.0, 1.0, 0.0], z) if abs(z[1]) < 0.9 else np.cross([1.0, 0.0, 0.0], z)
    x /= np.linalg.norm(x)
    return np.stack([x, np.cross(z, x), z], axis=-1)


def pivot_frames(hexapod: ServoHexapod) -> np.ndarray:
    """``(6, 3, 3)`` R_B,pivot_i: x along the arm at zero angle (beta_i), z = the pulse-increasing axis."""
    b = hexapod.arm_directions
    x = np.stack([np.cos(b), np.sin(b), np.zeros(6)], -1)
    z = -hexapod.shaft_directions
    return np.stack([x, np.cross(z, x), z], axis=-1)


def servo_joint_home(hexapod: ServoHexapod) -> np.ndarray:
    """``(6,)`` the servo joint angles that put each arm at alpha0 (radians), from the mounting alone."""
    up = pivot_frames(hexapod)[:, :, 1] @ [0.0, 0.0, 1.0]  # +1 where the joint raises the arm
    return up * hexapod.home_angles


def rod_frames(hexapod: ServoHexapod) -> np.ndarray:
    """``(6, 3, 3)`` R_B,rod_i at home: z from the arm tip to the anchor."""
    tip = arm_tips(hexapod, hexapod.home_angles)
    q = hexapod.platform_anchors + [0.0, 0.0, hexapod.home_height]
    return np.stack([frame_from_zx(q[i] - tip[i], pivot_frames(hexapod)[i][:, 0]) for i in range(6)])


def pulse_joint_angles(hexapod: ServoHexapod, pulse_us, joint_home) -> np.ndarray:
    """Servo joint angles ``(..., 6)`` (radians) for pulse widths ``(..., 6)`` (µs): the horn turns
    (W - W0)/r from its home angle ``joint_home`` (6,), in the pulse-increasing sense — the servo's
    physics, with no odd/even rule."""
    return np.asarray(joint_home) + (np.asarray(pulse_us) - hexapod.neutral_us) / hexapod.rate_us_per_rad


def joint_arm_angles(hexapod: ServoHexapod, joint_angles) -> np.ndarray:
    """Arm elevations alpha (..., 6) (radians, eq. 9's angle) from servo joint angles (..., 6)."""
    up = pivot_frames(hexapod)[:, :, 1] @ [0.0, 0.0, 1.0]
    return up * np.asarray(joint_angles)
