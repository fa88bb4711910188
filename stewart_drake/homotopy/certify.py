"""A posteriori existence-and-uniqueness certificates for real forward-kinematics solutions.

The real system G: R⁸ → R⁸ in Study coordinates x = (e, g) (``study``) with the chart e·e = 1:
G_i(x) = xᵀ Q_i x − c_i (i < 7: six legs with c_i = 0 and the Study quadric; i = 7: e·e − 1). Every
G_i is quadratic, so for any x₀ and d, exactly

    G(x₀ + d) = G(x₀) + A d + q(d),   A = DG(x₀),   q(d)_i = dᵀ Q_i d.

Krawczyk/Kantorovich argument (Moore 1977, Rall 1981): take any matrix Y (a computed A⁻¹) and the
Newton-like map N(x) = x − Y G(x). With bounds
  b ≥ ‖Y G(x₀)‖,  κ ≥ ‖I − Y A‖,  K ≥ sup_{‖d‖=1} ‖Y q(d)‖   (2-norms)
we have ‖N(x₀+d) − x₀‖ ≤ b + κ r + K r² and ‖N(x₀+d₁) − N(x₀+d₂)‖ ≤ (κ + 2 K r) ‖d₁ − d₂‖ for
‖d‖ ≤ r. If (1 − κ)² > 4 K b, the radius r₋ = 2b / (1 − κ + √((1 − κ)² − 4Kb)) makes N a contraction
of the closed ball B(x₀, r₋) into itself, and κ < 1 makes Y invertible: G has exactly one zero in
B(x₀, r₋), and no other in the open ball of radius r_u = (1 − κ) / (2K) (N is a contraction there).
The same bounds hold over C⁸ with the Hermitian norm, so the zero is also the only complex solution
in that ball — and being the limit of real iterates, it is real: a real pose.

Rounding: the bounds are computed in floating point. Every quantity is a sum of at most 64 products
of numbers that are themselves within a few roundings of the exact system's coefficients (the
anchors and lengths as given, scaled by a power-free length scale), so each computed entry is within
n·u·(the same sum with absolute values), n ≤ 100, u = 2⁻⁵³ (Higham, Accuracy and Stability, §3.1).
We add ERR = 1e-12 (≈ 90 times that bound) times the absolute-value sums to b, κ and K, and use
Frobenius norms (≥ 2-norms). This is a justified safety margin, not interval arithmetic.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

ERR = 1e-12  # relative rounding allowance, see the module docstring


@dataclass(frozen=True)
class Certificate:
    """Per-solution certificate arrays ``(k,)``: ``certified`` (the test passed), ``radius`` r₋
    (an exact zero lies within it, Study coordinates with ‖e‖ = 1, g in length-scale units),
    ``uniqueness`` r_u (no other zero within it), ``b``, ``kappa``, ``K`` (the bounds used)."""

    certified: np.ndarray
    radius: np.ndarray
    uniqueness: np.ndarray
    b: np.ndarray
    kappa: np.ndarray
    K: np.ndarray


def real_forms(Q7: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The eight quadratic forms ``(8, 8, 8)`` and constants ``(8,)`` of G: the seven of ``Q7`` (legs,
    Study quadric) and the chart e·e − 1."""
    Q = np.zeros((8, 8, 8))
    Q[:7] = Q7
    Q[7, :4, :4] = np.eye(4)
    c = np.zeros(8)
    c[7] = 1.0
    return Q, c


def value_and_jacobian(x: np.ndarray, Q: np.ndarray, c: np.ndarray):
    """G ``(k, 8)`` and DG ``(k, 8, 8)`` at ``(k, 8)`` points."""
    Qx = np.einsum("ijl,kl->kij", Q, x)
    return np.einsum("kij,kj->ki", Qx, x) - c, 2 * Qx


def newton_real(x: np.ndarray, Q: np.ndarray, c: np.ndarray, iterations: int = 6) -> np.ndarray:
    """Newton iterations on G from ``(k, 8)`` real points."""
    for _ in range(iterations):
        G, A = value_and_jacobian(x, Q, c)
        x = x - np.linalg.solve(A, G[..., None])[..., 0]
    return x


def certify(x0: np.ndarray, Q: np.ndarray, c: np.ndarray) -> Certificate:
    """Certificates for real points x0 ``(k, 8)`` of G (forms Q ``(8, 8, 8)``, constants c ``(8,)``)."""
    x0 = np.asarray(x0, dtype=float)
    G, A = value_and_jacobian(x0, Q, c)
    ax = np.abs(x0)
    absQ = np.abs(Q)
    G_mag = np.einsum("ijl,kj,kl->ki", absQ, ax, ax) + np.abs(c)
    A_mag = 2 * np.einsum("ijl,kl->kij", absQ, ax)
    with np.errstate(all="ignore"):
        Y = np.linalg.inv(A)
    aY = np.abs(Y)
    # b >= ||Y G_exact||: |Y G| <= |Y| (|G| + err) entrywise, plus the product's own rounding.
    YG = np.einsum("kij,kj->ki", aY, np.abs(G) + ERR * G_mag)
    b = np.linalg.norm(YG * (1 + ERR), axis=1)
    C = np.eye(8) - Y @ A
    C_err = ERR * (np.eye(8) + aY @ A_mag)
    kappa = np.sqrt(np.sum((np.abs(C) + C_err) ** 2, axis=(1, 2)))
    M = np.einsum("kri,ijl->krjl", Y, Q)
    M_err = ERR * np.einsum("kri,ijl->krjl", aY, absQ)
    K = np.sqrt(np.sum((np.abs(M) + M_err) ** 2, axis=(1, 2, 3))) * (1 + ERR)
    with np.errstate(all="ignore"):
        disc = (1 - kappa) ** 2 - 4 * K * b
        ok = np.isfinite(disc) & (kappa < 1) & (disc > 0) & np.all(np.isfinite(Y), axis=(1, 2))
        r = np.where(ok, 2 * b / ((1 - kappa) + np.sqrt(np.maximum(disc, 0))), np.inf) * (1 + 1e-9)
        ru = np.where(ok, (1 - kappa) / (2 * K), 0.0)
    return Certificate(ok, r, ru, b, kappa, K)


def pose_bounds(x: np.ndarray, r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Bounds ``(k,)`` on the position error (in length-scale units) and rotation angle error (rad)
    of the pose of an exact zero within r of x ``(k, 8)`` (‖e‖ = 1): with |δe|, |δg| <= r,
    |p* − p| <= [r (1 + r) + |g| r] / (1 − r)² + |g| ((1 − r)⁻² − 1), and the unit quaternions differ
    by at most 2r / (1 − r), so the rotation angle by at most 4 asin(min(1, r / (1 − r)))."""
    g = np.linalg.norm(x[:, 4:], axis=1)
    with np.errstate(all="ignore"):
        dp = (r * (1 + r) + g * r) / (1 - r) ** 2 + g * ((1 - r) ** -2 - 1)
        da = 4 * np.arcsin(np.minimum(1.0, r / (1 - r)))
    return np.where(r < 1, dp, np.inf), np.where(r < 1, da, np.inf)
