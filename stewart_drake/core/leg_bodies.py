"""The geometry of a platform's leg bodies (numpy only): their sizes, the home frames of the universal
joints, and the closed-form joint positions at a pose.

Leg i is a cylinder on a universal joint at the base anchor p_BBi and a piston sliding in it, whose tip
is the plate anchor. The cylinder's zero-angle frame C_i has z along the leg at the home pose and x
horizontal; Drake's ``UniversalJoint`` turns it by R = Rx(q0) Ry(q1). The Drake model
(``core/sdf_models.platform_sdf``), the legs' inverse dynamics (``dynamics.leg_forces_with_legs``) and
the viewers share these definitions.
"""

from __future__ import annotations

import numpy as np

from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_vectors


def leg_dimensions(platform: Platform) -> dict:
    """Cylinder/piston radii and lengths (metres), the YAML values or their defaults."""
    legs = platform.legs
    cl = legs.cylinder_length or platform.L_min / 2
    cr = legs.cylinder_radius or platform.L_min / 40
    pr = legs.piston_radius or 0.6 * cr
    return {"cylinder_length": cl, "cylinder_radius": cr, "piston_length": cl, "piston_radius": pr}


def leg_visual_dimensions(platform: Platform) -> dict:
    """Display lengths (metres) of each leg's cylinder and piston, and the joint sphere radius.

    The cylinder runs from the base joint up ``cylinder_length``; the piston from the top joint down
    ``piston_length``. They overlap at every leg length L in [L_min, L_max] when their sum exceeds
    L_max, and neither passes the far joint at L_min when each is at most L_min. Both are
    L_min/2 + L_max/4: the sum L_min + L_max/2 lies halfway between L_max and 2 L_min, leaving an
    overlap of (2 L_min − L_max)/2 at full extension. A stroke with L_max >= 2 L_min cannot satisfy
    both; there each is 0.55 L_max, keeping the overlap (the piston then shows below the base joint)."""
    lo, hi = platform.L_min, platform.L_max
    length = lo / 2 + hi / 4 if hi < 2 * lo else 0.55 * hi
    dims = leg_dimensions(platform)
    return {
        "cylinder_length": length,
        "piston_length": length,
        "cylinder_radius": dims["cylinder_radius"],
        "piston_radius": dims["piston_radius"],
        "joint_radius": 1.6 * dims["cylinder_radius"],
    }


def home_leg_frames(platform: Platform) -> np.ndarray:
    """``(6, 3, 3)`` R_BCi: each cylinder's zero-angle frame; z along the leg at the home pose, x horizontal."""
    u = leg_vectors(platform, platform.home_pose())
    z = u / np.linalg.norm(u, axis=-1, keepdims=True)
    x = np.cross([0.0, 0.0, 1.0], z)
    n = np.linalg.norm(x, axis=-1, keepdims=True)
    x = np.where(n > 1e-9, x / np.where(n > 1e-9, n, 1.0), [1.0, 0.0, 0.0])
    y = np.cross(z, x)
    return np.stack([x, y, z], axis=-1)


def leg_joint_positions(platform: Platform, poses, convention: str = "utn") -> tuple[np.ndarray, np.ndarray]:
    """Closed-form joint positions for ``(..., 6)`` poses: universal angles ``(..., 6, 2)`` (radians)
    and prismatic positions ``(..., 6)`` (= leg lengths, metres)."""
    l = leg_vectors(platform, poses, convention)
    L = np.linalg.norm(l, axis=-1)
    d = np.einsum("ikj,...ik->...ij", home_leg_frames(platform), l / L[..., None])  # direction in C_i
    # Drake's UniversalJoint: R_FM = Rx(q0) Ry(q1), so z_M = [sin q1, -sin q0 cos q1, cos q0 cos q1].
    q1 = np.arcsin(np.clip(d[..., 0], -1.0, 1.0))
    q0 = np.arctan2(-d[..., 1], d[..., 2])
    return np.stack([q0, q1], axis=-1), L
