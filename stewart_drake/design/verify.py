"""Independent checks of the design analysis, shared by the tests and the report.

``newton_euler_fd``: leg forces and leg-length rates from the pose function alone — positions and
orientations (scipy's rotations, not the toolkit's) at t + k h, derivatives by eighth-order central
differences, the plate's Newton–Euler equations and a wrench balance whose leg directions come from
the anchors (not the toolkit's Jacobian). ``sample_envelope``: random states inside an envelope.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from stewart_drake.core.geometry import Platform

# Truncation ~ h^8 |q^(9)| (negligible at h = 1e-3 s for smooth trajectories of a few rad/s); rounding
# ~ 1e-16 |x| / h for a first derivative and / h² for a second: ~1e-10 here.
FD_H = 1e-3
_C1 = np.array([1 / 280, -4 / 105, 1 / 5, -4 / 5, 0, 4 / 5, -1 / 5, 4 / 105, -1 / 280])
_C2 = np.array([-1 / 560, 8 / 315, -1 / 5, 8 / 5, -205 / 72, 8 / 5, -1 / 5, 8 / 315, -1 / 560])
_OFFSETS = np.arange(-4, 5)


def utn_rotation(angles) -> np.ndarray:
    """``(n, 3, 3)`` R = Ry(b) Rx(a) Rz(g) by scipy (intrinsic Y, X, Z) for ``(n, 3)`` (a, b, g)."""
    a = np.atleast_2d(angles)
    return Rotation.from_euler("YXZ", np.stack([a[:, 1], a[:, 0], a[:, 2]], -1)).as_matrix()


def newton_euler_fd(platform: Platform, pose_fn, t, gravity: float = 9.81, h: float = FD_H) -> tuple:
    """``(F, L, L̇, L̈)`` each ``(n, 6)`` at times ``t`` (n,) s for a utn-convention ``pose_fn(t) -> (..., 6)``
    (legs massless)."""
    t = np.asarray(t, dtype=float)
    ts = t[:, None] + _OFFSETS * h
    q = pose_fn(ts)
    R = utn_rotation(q[..., 3:].reshape(-1, 3)).reshape(q.shape[:2] + (3, 3))
    p_cm = q[..., :3] + np.einsum("nkij,j->nki", R, platform.com - platform.rotation_centre)
    anchors = q[..., None, :3] + np.einsum("nkij,lj->nkli", R, platform.top_anchors_per_leg - platform.rotation_centre)
    L = np.linalg.norm(anchors - platform.base_anchors, axis=-1)
    Rd = np.einsum("k,nkij->nij", _C1, R) / h
    Rdd = np.einsum("k,nkij->nij", _C2, R) / h**2
    R0 = R[:, 4]
    W = Rd @ np.swapaxes(R0, -1, -2)  # [ω]× = Ṙ Rᵀ
    w = np.stack([W[:, 2, 1], W[:, 0, 2], W[:, 1, 0]], -1)
    Wd = Rdd @ np.swapaxes(R0, -1, -2) + Rd @ np.swapaxes(Rd, -1, -2)  # d/dt (Ṙ Rᵀ)
    wd = np.stack([Wd[:, 2, 1], Wd[:, 0, 2], Wd[:, 1, 0]], -1)
    a_cm = np.einsum("k,nki->ni", _C2, p_cm) / h**2
    f = platform.mass * (a_cm + [0.0, 0.0, gravity])
    I_W = R0 @ platform.inertia @ np.swapaxes(R0, -1, -2)
    tau = np.einsum("nij,nj->ni", I_W, wd) + np.cross(w, np.einsum("nij,nj->ni", I_W, w))
    a0 = anchors[:, 4]
    u = (a0 - platform.base_anchors) / L[:, 4, :, None]
    Wmat = np.concatenate([u, np.cross(a0 - p_cm[:, 4, None], u)], -1)  # wrench about the centre of mass
    F = np.linalg.solve(np.swapaxes(Wmat, -1, -2), np.concatenate([f, tau], -1)[..., None])[..., 0]
    Ld = np.einsum("k,nkl->nl", _C1, L) / h
    Ldd = np.einsum("k,nkl->nl", _C2, L) / h**2
    return F, L[:, 4], Ld, Ldd


def sample_box(rng, n: int, bound) -> np.ndarray:
    """``(n, d)`` points of the closed box |x_j| <= bound_j: each coordinate uniform, or (probability 1/2)
    on one of its faces, so that vertices and faces, where affine terms peak, are visited."""
    bound = np.asarray(bound, dtype=float)
    x = rng.uniform(-1, 1, (n, len(bound)))
    x = np.where(rng.random(x.shape) < 0.5, np.sign(x), x)
    return x * bound
