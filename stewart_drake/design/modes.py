"""Natural frequencies and mode shapes about a static equilibrium, from the 6×6 stiffness K about the
rotation centre C (``stiffness``) and the 6×6 spatial inertia about C, in the same coordinates
δx = [δp; δθ] (base frame):

    M_C δẍ + C_d δẋ + K δx = 0,   C_d = Aᵀ diag(c) A (leg dampers, c in N·s/m).

Undamped: the generalised eigenproblem K φ = ω² M_C φ (``scipy.linalg.eigh``; K is symmetric at an
equilibrium). Damped: the eigenvalues λ of the first-order form; natural frequency |λ|/2π, damping
ratio −Re λ / |λ|. With the legs' masses (``legs=True``) M_C is the plate's plus the legs' reflected
inertia, taken from the toolkit's inverse dynamics with legs (unit Cartesian accelerations at rest,
no gravity): column j of M_C is Aᵀ F(ȧ = e_j).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg

from stewart_drake.core.argcheck import as_poses
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import inverse_jacobian
from stewart_drake.core.rotations import rotation_matrix
from stewart_drake.design.envelope import cartesian_leg_forces, spatial_inertia_about_C


def spatial_inertia(platform: Platform, q, convention: str = "utn", legs: bool = False) -> np.ndarray:
    """``(6, 6)`` M_C at pose q (6,): kg, kg·m, kg·m². ``legs`` adds the legs' reflected inertia."""
    q = as_poses(q).reshape(6)
    if not legs:
        return spatial_inertia_about_C(platform, rotation_matrix(q[3:], convention))
    A = inverse_jacobian(platform, q, convention)
    E = np.eye(6)
    F = cartesian_leg_forces(
        platform, np.broadcast_to(q, (6, 6)), np.zeros((6, 6)), E, convention, legs=True, gravity=0.0
    )
    M = A.T @ F.T
    return 0.5 * (M + M.T)


@dataclass(frozen=True)
class Modes:
    """``frequencies_hz`` (6,) ascending natural frequencies; ``shapes`` (6, 6) columns the mode shapes
    [δp (m); δθ (rad)], mass-normalised (φᵀ M φ = 1) when undamped, unit 2-norm otherwise;
    ``damping_ratio`` (6,)."""

    frequencies_hz: np.ndarray
    shapes: np.ndarray
    damping_ratio: np.ndarray


def analytic_modes(K, M, C_d=None) -> Modes:
    """Modes of M δẍ + C_d δẋ + K δx = 0 for (6, 6) K, M (and damping C_d, None: undamped)."""
    K, M = np.asarray(K, float), np.asarray(M, float)
    if C_d is None or not np.any(C_d):
        w2, phi = scipy.linalg.eigh(0.5 * (K + K.T), 0.5 * (M + M.T))
        return Modes(np.sqrt(np.maximum(w2, 0.0)) / (2 * np.pi), phi, np.zeros(6))
    Minv = np.linalg.inv(M)
    A = np.block([[np.zeros((6, 6)), np.eye(6)], [-Minv @ K, -Minv @ C_d]])
    lam, vec = np.linalg.eig(A)
    return modes_from_state_eigs(lam, vec[:6])


def modes_from_state_eigs(lam, shapes_pos) -> Modes:
    """Modes from eigenvalues λ (2n,) and their position parts (n, 2n) of a first-order linear system:
    one of each conjugate pair (Im λ >= 0), sorted by |λ|; overdamped real pairs give two entries, and
    the n with the smallest |λ| are kept."""
    lam = np.asarray(lam)
    keep = np.flatnonzero(lam.imag >= 0) if np.any(np.abs(lam.imag) > 0) else np.arange(len(lam))
    order = keep[np.argsort(np.abs(lam[keep]))][: shapes_pos.shape[0]]
    lam_k = lam[order]
    phi = shapes_pos[:, order]
    phi = phi / np.linalg.norm(phi, axis=0)
    wn = np.abs(lam_k)
    zeta = np.where(wn > 0, -lam_k.real / np.where(wn > 0, wn, 1.0), 0.0)
    return Modes(wn / (2 * np.pi), phi, zeta)


def damping_matrix(platform: Platform, q, c, convention: str = "utn") -> np.ndarray:
    """``(6, 6)`` C_d = Aᵀ diag(c) A for leg damping coefficients c (6,) N·s/m."""
    A = inverse_jacobian(platform, q, convention)
    return A.T @ np.diag(np.broadcast_to(np.asarray(c, float), (6,))) @ A


def mac(phi_a, phi_b) -> np.ndarray:
    """Modal assurance criterion |φ_aᴴ φ_b|² / ((φ_aᴴ φ_a)(φ_bᴴ φ_b)) of matching columns (..., n)."""
    num = np.abs(np.sum(np.conj(phi_a) * phi_b, axis=0)) ** 2
    return num / (np.sum(np.abs(phi_a) ** 2, 0) * np.sum(np.abs(phi_b) ** 2, 0))


def subspace_mac(phi_a, phi_b, freqs, rel: float = 1e-6) -> np.ndarray:
    """``(n,)`` MAC per mode, generalised to clusters of (near-)repeated frequencies (within ``rel``),
    where single mode shapes are arbitrary: the smallest cos² of the principal angles between the
    clusters' subspaces, given to each mode of the cluster. Single modes: the ordinary MAC."""
    freqs = np.asarray(freqs, float)
    out = np.empty(len(freqs))
    i = 0
    while i < len(freqs):
        j = i + 1
        while j < len(freqs) and freqs[j] - freqs[i] <= rel * max(freqs[i], 1e-300):
            j += 1
        if j - i == 1:
            out[i] = mac(phi_a[:, i : i + 1], phi_b[:, i : i + 1])[0]
        else:
            qa, _ = np.linalg.qr(phi_a[:, i:j])
            qb, _ = np.linalg.qr(phi_b[:, i:j])
            s = np.linalg.svd(np.conj(qa.T) @ qb, compute_uv=False)
            out[i:j] = np.min(s) ** 2
        i = j
    return out
