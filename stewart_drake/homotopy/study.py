"""Forward kinematics of a Stewart–Gough platform as a square polynomial system in Study coordinates.

The plate pose (R_BT, p_BC) is written with Study's soma coordinates x = (e, g) ∈ P⁷: e a quaternion
(rotation, not normalised), g a quaternion with p_BC = g ē / (e·e) (a pure quaternion: the Study
quadric g·e = 0). For leg i with plate anchor a_i = p_TTi − p_TC and base anchor b_i = p_BBi (pure
quaternions), |p + R a_i − b_i|² = |g + e a_i − b_i e|² / (e·e), so the leg equation is

    f_i(x) = u_i·u_i − s_i e·e = 0,   u_i = g + B_i e,   B_i = R(a_i) − L(b_i),   s_i = L_i²,

where L(q), R(q) are the 4×4 matrices of left / right quaternion multiplication and "·" is the
bilinear (non-conjugating) dot product of C⁴. With the Study quadric f_6 = g·e and an affine chart
f_7 = v·x − 1 (v a fixed random complex vector: the projective space is seen through a random chart,
so paths whose pose goes to infinity — e·e → 0 — stay bounded) this is 8 quadratic/linear equations
in x ∈ C⁸. Every equation is a quadratic form in x (plus a constant), so D²f is constant.

Root count: a general 6-6 platform has 40 isolated complex solutions (Wampler 1996, Husty 1996,
Raghavan 1993; Dietmaier 1998 found 40 real); the 3-6 family (plate anchors coincident in three
pairs) has 16. The equations are linear in the parameters (a_i, b_i, s_i), so the straight segment
between two parameter points stays inside the family (coincidences are kept): the basis of the
parameter homotopy in ``track``.

Units: the caller scales lengths by a platform length scale (``study_parameters``) so that the
numbers are of order one; poses are converted back to metres by ``poses_from_study``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stewart_drake.core.geometry import Platform
from stewart_drake.core.joints import coincident_groups

GENERAL = "6-6"
THREE_SIX = "3-6"  # plate anchors coincide in three pairs
SIX_THREE = "6-3"  # base anchors coincide in three pairs (solved as the inverse 3-6 motion)
ROOT_COUNT = {GENERAL: 40, THREE_SIX: 16, SIX_THREE: 16}
# Anchors closer than COINCIDENT_TOL x length_scale are one joint to the solver: relative, in the scaled
# units it tracks paths in (``study_parameters``), where the 16-path 3-6 / 6-3 families need the anchors to
# coincide up to rounding; so much tighter than the platform's absolute MIN_ANCHOR_SEPARATION (1e-6 m).
COINCIDENT_TOL = 1e-9


def left_matrix(q: np.ndarray) -> np.ndarray:
    """``(..., 4, 4)`` L(q) with q*r = L(q) r (Hamilton product, q = (w, x, y, z) ``(..., 4)``)."""
    w, x, y, z = np.moveaxis(np.asarray(q), -1, 0)
    return np.stack(
        [
            np.stack([w, -x, -y, -z], -1),
            np.stack([x, w, -z, y], -1),
            np.stack([y, z, w, -x], -1),
            np.stack([z, -y, x, w], -1),
        ],
        -2,
    )


def right_matrix(q: np.ndarray) -> np.ndarray:
    """``(..., 4, 4)`` R(q) with r*q = R(q) r."""
    w, x, y, z = np.moveaxis(np.asarray(q), -1, 0)
    return np.stack(
        [
            np.stack([w, -x, -y, -z], -1),
            np.stack([x, w, z, -y], -1),
            np.stack([y, -z, w, x], -1),
            np.stack([z, y, -x, w], -1),
        ],
        -2,
    )


def pure(v: np.ndarray) -> np.ndarray:
    """``(..., 4)`` the pure quaternion (0, v) of ``(..., 3)`` vectors."""
    v = np.asarray(v)
    return np.concatenate([np.zeros(v.shape[:-1] + (1,), v.dtype), v], -1)


def leg_matrices(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``(..., 6, 4, 4)`` B_i = R(a_i) − L(b_i) for plate anchors a ``(..., 6, 3)`` and base anchors b."""
    return right_matrix(pure(a)) - left_matrix(pure(b))


@dataclass(frozen=True)
class Architecture:
    """The architecture class of a platform, as the solver sees it.

    kind   "6-6" (general, including planar and symmetric 6-6), "3-6" (plate anchors coincide in three
           pairs) or "6-3" (base anchors coincide in three pairs)
    order  ``(6,)`` leg permutation that puts coincident pairs at (0, 1), (2, 3), (4, 5)
    joints (distinct base joints, distinct plate joints): a "6-6" with fewer than six on a side (e.g. the
           3-3 octahedral platform) is solved with the general start system, its extra paths ending at infinity
    """

    kind: str
    order: np.ndarray
    joints: tuple = (6, 6)

    @property
    def root_count(self) -> int:
        return ROOT_COUNT[self.kind]

    def describe(self) -> str:
        if self.kind == GENERAL and self.joints != (6, 6):
            return f"6-6 family with shared joints ({self.joints[0]} base, {self.joints[1]} plate joints): 40 paths"
        text = {
            GENERAL: "general 6-6 (six distinct plate and six distinct base joints): 40 paths",
            THREE_SIX: "3-6 (plate joints shared by leg pairs): 16 paths",
            SIX_THREE: "6-3 (base joints shared by leg pairs; solved as the inverse 3-6 motion): 16 paths",
        }
        return text[self.kind]


def _pairs(points: np.ndarray, tol: float):
    """Three disjoint coincident pairs of the ``(6, 3)`` points as a leg order (each pair's lower leg
    first, pairs in the order of their lower legs), or None."""
    first, index = coincident_groups(points, tol)
    if len(first) != 3 or np.any(np.bincount(index) != 2):
        return None
    return np.argsort(index, kind="stable")


def length_scale(platform: Platform) -> float:
    """Metres per unit of the scaled system: the largest anchor distance from its frame origin."""
    a = platform.top_anchors_per_leg - platform.rotation_centre
    return float(max(np.abs(a).max(), np.abs(platform.base_anchors).max(), 1e-3))


def architecture(platform: Platform) -> Architecture:
    """Classify the platform from its anchors: 3-6 when the plate anchors of the legs coincide in
    three pairs (and the base anchors are distinct), 6-3 when the base anchors do, else 6-6."""
    tol = COINCIDENT_TOL * length_scale(platform)
    top = _pairs(platform.top_anchors_per_leg, tol)
    base = _pairs(platform.base_anchors, tol)
    if top is not None and base is None:
        return Architecture(THREE_SIX, top)
    if base is not None and top is None:
        return Architecture(SIX_THREE, base)
    joints = tuple(len(coincident_groups(pts, tol)[0]) for pts in (platform.base_anchors, platform.top_anchors_per_leg))
    return Architecture(GENERAL, np.arange(6), joints)


def study_parameters(platform: Platform, lengths: np.ndarray, arch: Architecture):
    """Scaled family parameters for ``(..., 6)`` lengths (m): (a ``(6, 3)``, b ``(6, 3)``, s ``(..., 6)``,
    scale). Legs are reordered by ``arch.order``; for 6-3 the roles of plate and base are swapped
    (the inverse motion T→B is a 3-6 problem)."""
    k = length_scale(platform)
    a = (platform.top_anchors_per_leg - platform.rotation_centre)[arch.order] / k
    b = platform.base_anchors[arch.order] / k
    if arch.kind == SIX_THREE:
        a, b = b, a
    s = (np.asarray(lengths, dtype=float)[..., arch.order] / k) ** 2
    return a, b, s, k


def evaluate(x: np.ndarray, B: np.ndarray, s: np.ndarray, v: np.ndarray):
    """System value and Jacobian at x ``(n, 8)`` for per-row parameters B ``(n, 6, 4, 4)``, s ``(n, 6)``
    and chart v ``(8,)``. Returns F ``(n, 8)``, J ``(n, 8, 8)``."""
    e, g = x[:, :4], x[:, 4:]
    u = g[:, None, :] + np.einsum("nijk,nk->nij", B, e)
    ee = np.einsum("nk,nk->n", e, e)
    n = len(x)
    F = np.empty((n, 8), dtype=x.dtype)
    F[:, :6] = np.einsum("nij,nij->ni", u, u) - s * ee[:, None]
    F[:, 6] = np.einsum("nk,nk->n", g, e)
    F[:, 7] = x @ v - 1
    J = np.empty((n, 8, 8), dtype=x.dtype)
    J[:, :6, :4] = 2 * (np.einsum("nijk,nij->nik", B, u) - s[..., None] * e[:, None, :])
    J[:, :6, 4:] = 2 * u
    J[:, 6, :4] = g
    J[:, 6, 4:] = e
    J[:, 7, :] = v
    return F, J


def hessian_forms(B: np.ndarray, s: np.ndarray) -> np.ndarray:
    """``(7, 8, 8)`` symmetric Q_i with f_i(x) = xᵀ Q_i x for the six legs and the Study quadric, for one
    parameter point B ``(6, 4, 4)``, s ``(6,)`` (real or complex)."""
    Q = np.zeros((7, 8, 8), dtype=np.result_type(B, s))
    eye = np.eye(4)
    Q[:6, :4, :4] = np.einsum("ikj,ikl->ijl", B, B) - s[:, None, None] * eye
    Q[:6, :4, 4:] = np.swapaxes(B, 1, 2)
    Q[:6, 4:, :4] = B
    Q[:6, 4:, 4:] = eye
    Q[6, :4, 4:] = 0.5 * eye
    Q[6, 4:, :4] = 0.5 * eye
    return Q


def quaternion_rotation(e: np.ndarray) -> np.ndarray:
    """``(..., 3, 3)`` rotation matrix of real quaternions ``(..., 4)`` (any non-zero norm)."""
    e = e / np.linalg.norm(e, axis=-1, keepdims=True)
    w, x, y, z = np.moveaxis(e, -1, 0)
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
        ],
        -2,
    )


def pose_from_study(x: np.ndarray, scale: float, kind: str):
    """p_BC ``(k, 3)`` (m) and R_BT ``(k, 3, 3)`` of real Study points x ``(k, 8)`` of the scaled
    system of class ``kind`` (for 6-3 the solved motion is inverted back)."""
    e, g = x[:, :4], x[:, 4:]
    n = np.einsum("nk,nk->n", e, e)
    R = quaternion_rotation(e)
    p = np.einsum("nij,nj->ni", left_matrix(g), e * np.array([1, -1, -1, -1]))[:, 1:] / n[:, None] * scale
    if kind == SIX_THREE:  # solved T_TB; T_BT = inverse
        R = np.swapaxes(R, 1, 2)
        p = -np.einsum("nij,nj->ni", R, p)
    return p, R


def study_from_pose(p: np.ndarray, R: np.ndarray, scale: float, kind: str) -> np.ndarray:
    """Real Study points ``(k, 8)`` (e unit, w >= 0) of poses p_BC ``(k, 3)`` m, R_BT ``(k, 3, 3)``."""
    if kind == SIX_THREE:
        R = np.swapaxes(R, 1, 2)
        p = -np.einsum("nij,nj->ni", R, p)
    e = quaternion_from_matrix(R)
    g = np.einsum("nij,nj->ni", left_matrix(pure(p / scale)), e)
    return np.concatenate([e, g], -1)


def quaternion_from_matrix(R: np.ndarray) -> np.ndarray:
    """``(k, 4)`` unit quaternions (w >= 0) of rotation matrices ``(k, 3, 3)`` (Shepperd's method)."""
    tr = np.trace(R, axis1=1, axis2=2)
    cand = np.stack([tr, R[:, 0, 0], R[:, 1, 1], R[:, 2, 2]], -1)
    k = np.argmax(cand, -1)
    q = np.empty((len(R), 4))
    for i, Ri in enumerate(R):
        if k[i] == 0:
            w = np.sqrt(1 + tr[i]) / 2
            q[i] = [
                w,
                (Ri[2, 1] - Ri[1, 2]) / (4 * w),
                (Ri[0, 2] - Ri[2, 0]) / (4 * w),
                (Ri[1, 0] - Ri[0, 1]) / (4 * w),
            ]
        else:
            j = k[i] - 1
            a, b = (j + 1) % 3, (j + 2) % 3
            vj = np.sqrt(1 + Ri[j, j] - Ri[a, a] - Ri[b, b]) / 2
            v = np.empty(3)
            v[j] = vj
            v[a] = (Ri[a, j] + Ri[j, a]) / (4 * vj)
            v[b] = (Ri[b, j] + Ri[j, b]) / (4 * vj)
            q[i] = [(Ri[b, a] - Ri[a, b]) / (4 * vj), *v]
    return q * np.where(q[:, :1] < 0, -1.0, 1.0)
