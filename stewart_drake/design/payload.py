"""A payload rigidly fixed to the plate: a point mass merged into the plate's mass properties."""

from __future__ import annotations

import numpy as np

from stewart_drake.core.geometry import Platform
from stewart_drake.errors import PayloadError


def with_payload(platform: Platform, mass: float, p_TP=(0.0, 0.0, 0.0), option: str = "--payload") -> Platform:
    """``platform`` whose plate carries a point mass ``mass`` (kg) at ``p_TP`` (3,) metres in the plate
    frame T: total mass, centre of mass and inertia about it (parallel-axis theorem).

    The plate's anchors lie in the plane z_T = 0 and the plate occupies z_T >= 0, so a payload with
    z_T < 0 would sit among the legs: refused (``PayloadError``, naming ``option``).
    """
    p = np.asarray(p_TP, dtype=float).reshape(3)
    if not np.isfinite(mass) or mass < 0:
        raise PayloadError(PayloadError.MASS.format(option=option, value=mass))
    if not np.all(np.isfinite(p)):
        raise PayloadError(PayloadError.COM_NOT_FINITE.format(option=option, value=p.tolist()))
    if p[2] < 0:
        raise PayloadError(PayloadError.COM_BELOW.format(option=option, z=p[2]))
    if mass == 0:
        return platform
    m0, c0 = platform.mass, platform.com
    m = m0 + mass
    com = (m0 * c0 + mass * p) / m
    I = platform.inertia.copy()
    for mk, ck in ((m0, c0), (mass, p)):
        d = ck - com
        I = I + mk * (d @ d * np.eye(3) - np.outer(d, d))
    return platform.replace(mass=m, com=com, inertia=I)


def payload_wrench(platform: Platform, R, mass: float, p_TP, gravity: float) -> np.ndarray:
    """``(..., 6)`` the payload's weight as a wrench [f (N); m about the rotation centre (N·m)] in the base
    frame, for plate orientations ``R`` (..., 3, 3)."""
    r = np.einsum("...ij,j->...i", R, np.asarray(p_TP, dtype=float) - platform.rotation_centre)
    f = np.broadcast_to(np.array([0.0, 0.0, -mass * gravity]), r.shape)
    return np.concatenate([f, np.cross(r, f)], axis=-1)
