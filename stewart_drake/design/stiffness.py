"""Cartesian stiffness and compliance of the platform about its rotation centre C.

Coordinates: a small displacement δx = [δp (m); δθ (rad)] of the plate (δp of C, δθ the rotation
vector, R → exp([δθ]×) R, both in the base frame B). The legs are axial springs k_i (N/m) holding
their lengths: F_i = F_i0 − k_i δL_i. The total wrench on the plate [f; m about C] is

    w(x) = Σ_i F_i(x) a_i(x) + w_ext(x),   a_i = [u_i; r_i × u_i]  (the rows of J⁻¹ = A),

zero at the static equilibrium, and the stiffness is K = −∂w/∂x (restoring wrench = −K δx):

    K = Aᵀ diag(k) A  −  Σ_i F_i ∂a_i/∂x  −  ∂w_ext/∂x,

with, for P_i = (1 − u_i u_iᵀ)/L_i,
    ∂u_i/∂x = [P_i, −P_i [r_i]×],   ∂(r_i × u_i)/∂x = [[r_i]× P_i, [u_i]×[r_i]× − [r_i]× P_i [r_i]×],
and for the plate's (and payload's) weight f_g at r_cm: ∂w_ext/∂δθ = [[0], [f_g]× [r_cm]×]. The first
term alone is the zero-load stiffness; the others form the geometric (load-dependent) stiffness.
With the legs' masses (``legs=True``) the static forces include the legs' weight, and the legs load
the plate at its anchors: that wrench's derivative is taken by central differences (step ``FD_STEP``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from stewart_drake.core.argcheck import as_poses, as_real_array, shape_text
from stewart_drake.core.dynamics import G_EARTH, leg_forces, leg_forces_with_legs, skew
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import inverse_jacobian
from stewart_drake.core.rotations import angles_from_matrix, rotation_matrix
from stewart_drake.errors import SHAPE, ShapeError, StiffnessError

FD_STEP = 1e-6  # m and rad: central-difference step for the legs' weight term (error ~ step²)


def leg_stiffness_vector(value, option: str = "--leg-stiffness") -> np.ndarray:
    """``(6,)`` positive finite leg stiffnesses (N/m) from a number or six numbers; ``StiffnessError``
    naming ``option`` otherwise."""
    if value is None:
        raise StiffnessError(StiffnessError.MISSING.format(option=option))
    k = as_real_array(value, option)
    if k.shape not in ((), (6,)):
        raise ShapeError(SHAPE.format(name=option, shape="() or (6,)", got=shape_text(k.shape)))
    k = np.broadcast_to(k, (6,)).copy()
    if not np.all(np.isfinite(k)) or np.any(k <= 0):
        raise StiffnessError(StiffnessError.NOT_POSITIVE.format(option=option, value=np.asarray(value).tolist()))
    return k


def displace(pose, dx, convention: str = "utn") -> np.ndarray:
    """``(..., 6)`` pose q displaced by δx = [δp; δθ] (..., 6): p + δp, R → exp([δθ]×) R."""
    pose = np.asarray(pose, dtype=float)
    dx = np.asarray(dx, dtype=float)
    pose, dx = np.broadcast_arrays(pose, dx)
    R = Rotation.from_rotvec(dx[..., 3:].reshape(-1, 3)).as_matrix().reshape(dx.shape[:-1] + (3, 3)) @ rotation_matrix(
        pose[..., 3:], convention
    )
    return np.concatenate([pose[..., :3] + dx[..., :3], angles_from_matrix(R, convention)], -1)


def static_leg_forces(
    platform: Platform, q, convention: str = "utn", legs: bool = False, gravity: float = G_EARTH
) -> np.ndarray:
    """``(..., 6)`` leg forces (N) holding the plate at rest at poses q."""
    q = as_poses(q)
    z = np.zeros(q.shape)
    if legs:
        return leg_forces_with_legs(platform, q, z, z, convention, gravity=gravity)
    return leg_forces(platform, q, z, z, convention, gravity=gravity)


def legs_weight_wrench(platform: Platform, q, convention: str = "utn", gravity: float = G_EARTH) -> np.ndarray:
    """``(..., 6)`` the wrench [f; m about C] (base frame) the legs' weight applies to the plate at its
    anchors when at rest at q: −Aᵀ (F_with legs − F_plate alone)."""
    A = inverse_jacobian(platform, q, convention)
    dF = static_leg_forces(platform, q, convention, True, gravity) - static_leg_forces(
        platform, q, convention, False, gravity
    )
    return -np.einsum("...ji,...j->...i", A, dF)


def geometric_stiffness(u, r, L) -> np.ndarray:
    """``(..., 6, 6, 6)``: each leg's geometric-stiffness matrix D_i (per unit axial force, the loaded
    stiffness is K − Σ F_i D_i) from its unit vectors ``u`` (..., 6, 3), plate-anchor arms ``r`` (..., 6, 3) m
    and lengths ``L`` (..., 6) m."""
    D = np.zeros(u.shape[:-1] + (6, 6))
    D[..., :3, :3], D[..., :3, 3:], D[..., 3:, :3], D[..., 3:, 3:] = geometric_stiffness_blocks(u, r, L)
    return D


def geometric_stiffness_blocks(u, r, L) -> tuple:
    """D_i's four (..., 6, 3, 3) blocks ``(P, −P [r]×, [r]× P, [u]×[r]× − [r]× P [r]×)``, P = (1 − u uᵀ)/L (arguments
    as ``geometric_stiffness``)."""
    P = (np.eye(3) - u[..., :, None] * u[..., None, :]) / L[..., None, None]
    Sr, Su = skew(r), skew(u)
    SrP = Sr @ P
    return P, -P @ Sr, SrP, Su @ Sr - SrP @ Sr


def geometric_load_term(F, u, r, L) -> np.ndarray:
    """``(..., 6, 6)`` Σ_i F_i D_i, the loaded stiffness's geometric part for leg forces ``F`` (..., 6) N (other
    arguments as ``geometric_stiffness``): ``einsum("...k,...kij->...ij", F, D)`` contracted block by block, the
    same sums in the same order (bit for bit), without building D (..., 6, 6, 6) (a third of the cost)."""
    out = np.empty(np.shape(F) + (6,))
    blocks = geometric_stiffness_blocks(u, r, L)
    for (i, j), B in zip(((0, 0), (0, 3), (3, 0), (3, 3)), blocks, strict=True):
        out[..., i : i + 3, j : j + 3] = np.einsum("...k,...kij->...ij", F, B)
    return out


def stiffness_matrix(
    platform: Platform, q, k, convention: str = "utn", gravity: float = G_EARTH, legs: bool = False, loaded: bool = True
) -> np.ndarray:
    """``(..., 6, 6)`` K (N/m, N/rad, N·m/m, N·m/rad) at poses q ``(..., 6)`` for leg stiffnesses k ``(6,)``
    N/m (or one number for all). ``loaded=False`` gives Aᵀ diag(k) A (as does zero gravity, through the full expression)."""
    q = as_poses(q)
    k = np.broadcast_to(np.asarray(k, dtype=float), (6,))
    R = rotation_matrix(q[..., 3:], convention)
    r = np.einsum("...ij,kj->...ki", R, platform.top_anchors_per_leg - platform.rotation_centre)
    l = q[..., None, :3] + r - platform.base_anchors
    L = np.linalg.norm(l, axis=-1)
    u = l / L[..., None]
    A = np.concatenate([u, np.cross(r, u)], -1)
    K = np.einsum("...ki,k,...kj->...ij", A, k, A)
    if not loaded:
        return K
    F = static_leg_forces(platform, q, convention, legs, gravity)
    K = K - geometric_load_term(F, u, r, L)
    r_cm = np.einsum("...ij,j->...i", R, platform.com - platform.rotation_centre)
    f_g = np.array([0.0, 0.0, -platform.mass * gravity])
    K[..., 3:, 3:] -= skew(np.broadcast_to(f_g, r_cm.shape)) @ skew(r_cm)
    if legs:
        h = FD_STEP
        cols = [
            (
                legs_weight_wrench(platform, displace(q, h * e, convention), convention, gravity)
                - legs_weight_wrench(platform, displace(q, -h * e, convention), convention, gravity)
            )
            / (2 * h)
            for e in np.eye(6)
        ]
        K = K - np.stack(cols, -1)
    return K


def static_wrench(platform: Platform, q0, dx, k, convention: str = "utn", gravity: float = G_EARTH) -> np.ndarray:
    """``(..., 6)`` total wrench on the plate (legs massless) displaced by δx from its equilibrium at q0,
    legs as springs holding their lengths at q0: Σ (F_i0 − k_i δL_i) a_i + weight. Zero at δx = 0."""
    F0 = static_leg_forces(platform, q0, convention, False, gravity)
    q = displace(q0, dx, convention)
    R = rotation_matrix(q[..., 3:], convention)
    r = np.einsum("...ij,kj->...ki", R, platform.top_anchors_per_leg - platform.rotation_centre)
    l = q[..., None, :3] + r - platform.base_anchors
    L = np.linalg.norm(l, axis=-1)
    L0 = np.linalg.norm(
        as_poses(q0)[..., None, :3]
        + np.einsum(
            "...ij,kj->...ki",
            rotation_matrix(as_poses(q0)[..., 3:], convention),
            platform.top_anchors_per_leg - platform.rotation_centre,
        )
        - platform.base_anchors,
        axis=-1,
    )
    u = l / L[..., None]
    F = F0 - np.asarray(k) * (L - L0)
    w = np.einsum("...k,...ki->...i", F, np.concatenate([u, np.cross(r, u)], -1))
    r_cm = np.einsum("...ij,j->...i", R, platform.com - platform.rotation_centre)
    f_g = np.broadcast_to(np.array([0.0, 0.0, -platform.mass * gravity]), r_cm.shape)
    return w + np.concatenate([f_g, np.cross(r_cm, f_g)], -1)


@dataclass(frozen=True)
class Principal:
    """Principal stiffnesses from the compliance C = K⁻¹: ``translational`` (3,) N/m, ascending (softest
    first), = 1 / eig(C_pp) under a pure force at C; ``rotational`` (3,) N·m/rad under a pure moment;
    ``translational_dirs``, ``rotational_dirs`` (3, 3), columns the directions (base frame)."""

    translational: np.ndarray
    translational_dirs: np.ndarray
    rotational: np.ndarray
    rotational_dirs: np.ndarray


def compliance(K) -> np.ndarray:
    """``(..., 6, 6)`` C = K⁻¹ (m/N, rad/N, m/(N·m), rad/(N·m))."""
    return np.linalg.inv(K)


def principal_stiffness(K) -> Principal:
    """Principal stiffnesses and directions of ``(..., 6, 6)`` K (see ``Principal``); the blocks of the
    compliance are symmetrised (K is symmetric at an equilibrium)."""
    C = compliance(K)
    out = []
    for blk in (C[..., :3, :3], C[..., 3:, 3:]):
        blk = 0.5 * (blk + np.swapaxes(blk, -1, -2))
        ev, vec = np.linalg.eigh(blk)  # ascending compliance: stiffest first
        out += [1.0 / ev[..., ::-1], vec[..., :, ::-1]]
    return Principal(*out)


def deflection(K, wrench) -> np.ndarray:
    """``(..., 6)`` static deflection δx = K⁻¹ w [m; rad] under an added load wrench w (..., 6)."""
    return np.linalg.solve(K, np.asarray(wrench, dtype=float)[..., None])[..., 0]
