"""Closed-form inverse kinematics, vectorised over ``(..., 6)`` poses.

A pose ``q = [px, py, pz, a_x, a_y, a_z]`` (metres, radians, see ``rotations``) places the plate's
rotation centre C at p_BC = (px, py, pz) with orientation R_BT(a; convention). The plate anchor of
leg i is then p_BTi = p_BC + R_BT (p_TTi - p_TC), the leg vector l_i = p_BTi - p_BBi and its length
L_i = |l_i|.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from stewart_drake.core.argcheck import as_poses, first_index
from stewart_drake.core.rotations import angular_velocity_map, rotation_matrix
from stewart_drake.core.small_linalg import approximate_inverse
from stewart_drake.core.vec3 import cross
from stewart_drake.errors import SINGULAR_POSE, SingularPoseError, UnreachablePoseError, counted

if TYPE_CHECKING:  # annotations only: geometry imports sanity, which imports this module
    from stewart_drake.core.geometry import Platform


def plate_anchors(platform: Platform, poses, convention: str = "utn") -> np.ndarray:
    """``(..., 6, 3)`` p_BTi: each leg's plate anchor in the base frame (metres)."""
    q = as_poses(poses)
    R = rotation_matrix(q[..., 3:], convention)
    r_T = platform.top_anchors_per_leg - platform.rotation_centre  # (6, 3)
    return q[..., None, :3] + np.einsum("...jk,ik->...ij", R, r_T)


def leg_vectors(platform: Platform, poses, convention: str = "utn") -> np.ndarray:
    """``(..., 6, 3)`` l_i = p_BTi - p_BBi (metres)."""
    return plate_anchors(platform, poses, convention) - platform.base_anchors


CHUNK = 1 << 14  # poses per block in leg_lengths: keeps the temporaries in cache


def leg_lengths(platform: Platform, poses, convention: str = "utn") -> np.ndarray:
    """``(..., 6)`` leg lengths L_i (metres) for ``(..., 6)`` poses.

    The hot path of workspace sweeps: evaluated in blocks of ``CHUNK`` poses, one (n, 6) array per
    coordinate, accumulated in place.
    """
    q = as_poses(poses)
    flat = q.reshape(-1, 6)
    out = np.empty((flat.shape[0], 6))
    r_T = platform.top_anchors_per_leg - platform.rotation_centre  # (6, 3)
    base = platform.base_anchors  # (6, 3)
    for s in range(0, flat.shape[0], CHUNK):
        blk = flat[s : s + CHUNK]
        R = rotation_matrix(blk[:, 3:], convention)  # (n, 3, 3)
        acc = np.zeros((blk.shape[0], 6))
        for k in range(3):  # coordinate k of every leg vector: (R r_T)_k + p_k - b_k
            c = np.multiply.outer(R[:, k, 0], r_T[:, 0])
            c += np.multiply.outer(R[:, k, 1], r_T[:, 1])
            c += np.multiply.outer(R[:, k, 2], r_T[:, 2])
            c += blk[:, k, None] - base[:, k]
            c *= c
            acc += c
        np.sqrt(acc, out=out[s : s + CHUNK])
    return out.reshape(q.shape)


def leg_unit_vectors(platform: Platform, poses, convention: str = "utn") -> np.ndarray:
    """``(..., 6, 3)`` u_i = l_i / L_i, pointing from base anchor to plate anchor."""
    l = leg_vectors(platform, poses, convention)
    return l / np.linalg.norm(l, axis=-1, keepdims=True)


def inverse_jacobian(platform: Platform, poses, convention: str = "utn") -> np.ndarray:
    """``(..., 6, 6)`` J⁻¹ with dL/dt = J⁻¹ · [v_BC; ω_B]: the velocity of the rotation centre and the
    plate's angular velocity, both in the base frame. Row i is [u_iᵀ, (r_i × u_i)ᵀ], r_i = R (p_TTi - p_TC).
    """
    q = as_poses(poses)
    r = plate_offsets(platform, rotation_matrix(q[..., 3:], convention))
    return inverse_jacobian_of_legs(q[..., None, :3] + r - platform.base_anchors, r)


def plate_offsets(platform: Platform, R) -> np.ndarray:
    """``(..., 6, 3)`` r_i = R (p_TTi − p_TC) (m, base frame): each leg's plate anchor from the rotation centre,
    for ``(..., 3, 3)`` plate orientations R_BT (one home for the Jacobians and the inverse dynamics)."""
    return np.einsum("...jk,ik->...ij", R, platform.top_anchors_per_leg - platform.rotation_centre)


def inverse_jacobian_of_legs(l, r) -> np.ndarray:
    """``(..., 6, 6)`` J⁻¹ (``inverse_jacobian``) from the leg vectors ``l`` (..., 6, 3) (m) and the plate
    offsets ``r`` (..., 6, 3) (m, r_i = R (p_TTi − p_TC)): rows [u_iᵀ, (r_i × u_i)ᵀ], for a caller that has them."""
    u = l / np.linalg.norm(l, axis=-1, keepdims=True)
    return np.concatenate([u, cross(r, u)], axis=-1)


def length_jacobian(platform: Platform, poses, convention: str = "utn") -> np.ndarray:
    """``(..., 6, 6)`` J = ∂L/∂q: leg-length derivatives with respect to the pose coordinates
    (the seeds' Jacobian, used by the Lagrangian dynamics): J = J⁻¹ · blockdiag(I, E_W(angles))."""
    q = as_poses(poses)
    return length_jacobian_of(inverse_jacobian(platform, q, convention), angular_velocity_map(q[..., 3:], convention))


def length_jacobian_of(Jinv, E) -> np.ndarray:
    """``(..., 6, 6)`` J = ∂L/∂q (``length_jacobian``) from J⁻¹ ``(..., 6, 6)`` and E_W ``(..., 3, 3)``
    (``rotations.angular_velocity_map``), for a caller that has them (the inverse dynamics)."""
    return np.concatenate([Jinv[..., :3], Jinv[..., 3:] @ E], axis=-1)


def anchor_radius(platform: Platform) -> float:
    """The plate's anchor radius max |p_TTj − p_TC| (metres): the length that makes the rotation columns
    of a Jacobian commensurate with its translation columns."""
    return np.max(np.linalg.norm(platform.top_anchors - platform.rotation_centre, axis=1))


def scaled_jacobian(J, scale: float) -> np.ndarray:
    """``(..., 6, 6)`` J with its three rotation columns divided by ``scale`` (the anchor radius, m), so
    that both column blocks are in metres."""
    return np.concatenate([J[..., :3], J[..., 3:] / scale], axis=-1)


def singular_value_condition(s) -> np.ndarray:
    """``(...)`` σ_max/σ_min from ``(..., n)`` singular values in descending order; inf where σ_min is 0
    (or the ratio is not finite)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(s[..., -1] > 0, s[..., 0] / s[..., -1], np.inf)


def scaled_condition(platform: Platform, J) -> np.ndarray:
    """``(...)`` 2-norm condition number of a ``(..., 6, 6)`` Jacobian whose last three columns act on
    rotations (J⁻¹ or ∂L/∂q), those columns scaled by the plate's anchor radius (``scaled_jacobian``);
    inf on a singularity."""
    s = np.linalg.svd(scaled_jacobian(J, anchor_radius(platform)), compute_uv=False)
    return singular_value_condition(s)


def condition_at_most(platform: Platform, J, limit: float) -> np.ndarray:
    """``(...)`` bool: ``scaled_condition(platform, J) <= limit`` for ``(..., 6, 6)`` Jacobians — the same
    answers, about a quarter of the cost. Most matrices are decided by an a-posteriori bound from an approximate
    inverse X (any X: ``small_linalg.approximate_inverse``) of the scaled J (A): with r = ‖I − X A‖_F < 1,
    ‖A⁻¹‖₂ ≤ ‖X‖_F / (1 − r), so κ₂(A) ≤ ‖A‖_F ‖X‖_F / (1 − r). Where that bound is ≤ ``limit``/4 (r ≤ 1/2), κ₂ is well below ``limit`` — the
    factor 4 covers the rounding of the bound (relative ~1e-8 at κ ~ 1e8) and of the SVD's own κ — so the SVD
    answers yes there too; every other matrix (near-singular, not finite) is decided by the SVD as before."""
    A = scaled_jacobian(J, anchor_radius(platform))
    ok = np.zeros(A.shape[:-2], dtype=bool)
    with np.errstate(all="ignore"):
        try:
            X = approximate_inverse(A)  # any X: the bound is a-posteriori (one C loop, else np.linalg.inv)
        except np.linalg.LinAlgError:  # an exactly singular matrix in the batch: the SVD decides all
            X = None
        if X is not None:
            r = np.sqrt(np.sum((np.eye(A.shape[-1]) - X @ A) ** 2, axis=(-2, -1)))
            norms = np.sqrt(np.sum(A**2, axis=(-2, -1))) * np.sqrt(np.sum(X**2, axis=(-2, -1)))
            ok = np.asarray((r <= 0.5) & (norms / (1.0 - r) <= limit / 4))  # an array also for one matrix
    rest = ~ok
    if rest.any():
        ok[rest] = scaled_condition(platform, J[rest]) <= limit  # per matrix, as in one batch
    return ok


def condition_above(platform: Platform, J, limit: float) -> np.ndarray:
    """``(...)`` bool: ``scaled_condition(platform, J) > limit`` for ``(..., 6, 6)`` Jacobians — the same answers,
    about half the cost where only the side of a bound is wanted (a workspace's dexterity limit). κ² comes from
    the eigenvalues of AᵀA (A the scaled J, ``np.linalg.eigvalsh``): their error is a few tens of ε·λ_max
    (forming AᵀA and the symmetric solver, both backward stable), so κ² is off by a relative ~1e-14 · κ², and
    any matrix whose κ² lies outside limit² (1 ± δ) with δ = max(1e-6, 1e-11 · limit²) — thousands of times
    that error, and of the SVD's own — is on the same side of the limit for both. The SVD decides the band, a
    matrix whose smallest eigenvalue is not positive, and every matrix when the eigenvalues fail."""
    A = scaled_jacobian(J, anchor_radius(platform))
    out = np.zeros(A.shape[:-2], dtype=bool)
    rest = np.ones(A.shape[:-2], dtype=bool)
    with np.errstate(all="ignore"):
        try:
            lam = np.linalg.eigvalsh(np.swapaxes(A, -1, -2) @ A)  # ascending
        except np.linalg.LinAlgError:  # a matrix that is not finite: the SVD decides all (and says so)
            lam = None
        if lam is not None:
            lim2 = float(limit) ** 2
            slack = max(1e-6, 1e-11 * lim2)
            k2 = lam[..., -1] / lam[..., 0]
            sure = lam[..., 0] > 0
            out = sure & (k2 >= lim2 * (1 + slack))
            rest = ~(out | (sure & (k2 <= lim2 * (1 - slack))))
    if rest.any():
        out[rest] = scaled_condition(platform, J[rest]) > limit  # per matrix, as in one batch
    return out


def condition_number(platform: Platform, poses, convention: str = "utn") -> np.ndarray:
    """``(...)`` scaled condition number (``scaled_condition``) of J⁻¹ at ``(..., 6)`` poses (dL/dt =
    J⁻¹ [v_BC; ω_B]): the platform's own singularities; inf on one."""
    return scaled_condition(platform, inverse_jacobian(platform, poses, convention))


def require_nonsingular(platform: Platform, poses, convention: str = "utn", max_condition: float = 1e8) -> np.ndarray:
    """Condition numbers ``(...)``; raise ``SingularPoseError`` naming the first pose above ``max_condition``."""
    k = condition_number(platform, poses, convention)
    idx = first_index(~(k <= max_condition))
    if idx is not None:
        raise SingularPoseError(SINGULAR_POSE.format(index=counted(idx), cond=float(k[idx]), limit=max_condition))
    return k


@dataclass(frozen=True)
class StrokeCheck:
    """Per-pose, per-leg stroke check. Arrays ``(..., 6)``: ``below`` / ``above`` are the metres by
    which a leg is short of L_min / past L_max (0 where within)."""

    lengths: np.ndarray
    below: np.ndarray
    above: np.ndarray

    @property
    def within(self) -> np.ndarray:
        """``(...)`` True where all six legs are within [L_min, L_max]."""
        return ~np.any((self.below > 0) | (self.above > 0), axis=-1)

    def violations(self) -> list[dict]:
        """Every violation as ``{"pose": index, "leg": 1..6, "length_m", "limit_m", "excess_m", "side"}``."""
        out = []
        for side, arr, lim in (("min", self.below, -1), ("max", self.above, 1)):
            for idx in np.argwhere(arr > 0):
                idx = tuple(int(i) for i in idx)
                out.append(
                    {
                        "pose": list(idx[:-1]),
                        "leg": idx[-1] + 1,
                        "length_m": float(self.lengths[idx]),
                        "limit_m": float(self.lengths[idx] + lim * -arr[idx]),
                        "excess_m": float(arr[idx]),
                        "side": side,
                    }
                )
        return sorted(out, key=lambda v: (v["pose"], v["leg"]))

    def raise_first(self) -> None:
        """Raise ``UnreachablePoseError`` for the first violation, if any."""
        v = self.violations()
        if v:
            v = v[0]
            raise UnreachablePoseError(tuple(v["pose"]), v["leg"], v["length_m"], v["limit_m"], v["side"])


def check_stroke(platform: Platform, lengths) -> StrokeCheck:
    """Compare ``(..., 6)`` leg lengths (metres) with the platform's stroke."""
    L = np.asarray(lengths, dtype=float)
    return StrokeCheck(L, np.maximum(platform.L_min - L, 0.0), np.maximum(L - platform.L_max, 0.0))


def stroke_within(platform: Platform, lengths) -> np.ndarray:
    """``(...)`` bool: ``check_stroke(platform, lengths).within`` for ``(..., 6)`` lengths (m) without the check's
    three arrays (a sampler's test): L_min − L > 0 exactly when L < L_min (and L − L_max > 0 when L > L_max), so a
    leg is out only where it compares out; a NaN length compares out of neither, as there."""
    L = np.asarray(lengths, dtype=float)
    return ~np.any((L < platform.L_min) | (L > platform.L_max), axis=-1)


def inverse_kinematics(platform: Platform, poses, convention: str = "utn", check: bool = True) -> np.ndarray:
    """``(..., 6)`` leg lengths (metres); with ``check`` raise ``UnreachablePoseError`` naming the first
    pose and leg outside the stroke and by how much."""
    L = leg_lengths(platform, poses, convention)
    if check:
        check_stroke(platform, L).raise_first()
    return L
