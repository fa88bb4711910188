"""Workspace limits and per-pose margins: ``Limits`` says which limits are on (stroke, joint cones,
leg-leg collision, dexterity), and each limit gives a signed margin per pose (>= 0 inside, in the
limit's unit from ``LIMIT_UNITS``) for any ``(..., 6)`` poses. Plain numpy, no Drake; metres and radians.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from stewart_drake.core.geometry import Platform, base_joints
from stewart_drake.core.kinematics import condition_number, inverse_jacobian_of_legs, leg_vectors, scaled_condition
from stewart_drake.core.rotations import check_convention, rotation_matrix
from stewart_drake.errors import WorkspaceError

LIMIT_NAMES = ("stroke", "base_joint", "top_joint", "collision", "dexterity")
LIMIT_UNITS = {"stroke": "m", "base_joint": "rad", "top_joint": "rad", "collision": "m", "dexterity": "1"}
AXES = ("x", "y", "z")
_BLOCK = 4096  # poses per block in the collision kernel


@dataclass(frozen=True)
class Limits:
    """Which limits bound the workspace. ``None`` switches a limit off.

    stroke        bool           leg lengths within the platform's [L_min, L_max]
    base_cone     float | None   max angle (rad) between a leg and its base joint axis
    top_cone      float | None   max angle (rad) between a leg and its plate joint axis
    base_axes     (6, 3) | None  neutral axis of each base joint in B (default +Z, the base normal)
    top_axes      (6, 3) | None  neutral axis of each plate joint in T (default +Z, the plate normal)
    leg_diameter  float | None   leg cylinder diameter (m) for leg-leg collision
    max_condition float | None   Jacobian condition-number bound (dexterity)
    """

    stroke: bool = True
    base_cone: float | None = None
    top_cone: float | None = None
    base_axes: np.ndarray | None = None
    top_axes: np.ndarray | None = None
    leg_diameter: float | None = None
    max_condition: float | None = None

    def __post_init__(self):
        for name in ("base_cone", "top_cone"):
            v = getattr(self, name)
            if v is not None and not (0 < v <= math.pi):
                raise WorkspaceError(WorkspaceError.CONE.format(name=name, value=v))
        if self.leg_diameter is not None and not (np.isfinite(self.leg_diameter) and self.leg_diameter > 0):
            raise WorkspaceError(WorkspaceError.LEG_DIAMETER.format(value=self.leg_diameter))
        if self.max_condition is not None and not (self.max_condition > 1):
            raise WorkspaceError(WorkspaceError.MAX_CONDITION.format(value=self.max_condition))
        for name in ("base_axes", "top_axes"):
            v = getattr(self, name)
            if v is None:
                continue
            a = np.array(v, dtype=float)
            n = np.linalg.norm(a, axis=-1) if a.shape == (6, 3) else None
            if n is None or not np.all(n > 1e-12):
                raise WorkspaceError(WorkspaceError.AXES.format(name=name, shape=np.shape(v)))
            object.__setattr__(self, name, a / n[:, None])

    @property
    def active(self) -> tuple[str, ...]:
        """Names of the limits switched on, in ``LIMIT_NAMES`` order."""
        on = {
            "stroke": self.stroke,
            "base_joint": self.base_cone is not None,
            "top_joint": self.top_cone is not None,
            "collision": self.leg_diameter is not None,
            "dexterity": self.max_condition is not None,
        }
        return tuple(n for n in LIMIT_NAMES if on[n])


def segment_distances(P1, Q1, P2, Q2) -> np.ndarray:
    """``(...)`` shortest distance between segments P1Q1 and P2Q2 (``(..., 3)`` each, metres).

    Clamped closest-point parameters (Ericson, *Real-Time Collision Detection* §5.1.9); parallel
    segments take s = 0. Segments must have non-zero length.
    """
    gap = _closest_gap(P1, Q1, P2, Q2)
    return np.sqrt(gap[0] * gap[0] + gap[1] * gap[1] + gap[2] * gap[2])


def segment_gaps(P1, Q1, P2, Q2) -> np.ndarray:
    """``(..., 3)`` the vector from segment P2Q2's closest point to P1Q1's (``segment_distances``' points): its
    direction separates the two segments (the synthesis proof's clearance bound uses it)."""
    return np.moveaxis(_closest_gap(P1, Q1, P2, Q2), 0, -1)


def _closest_gap(P1, Q1, P2, Q2) -> np.ndarray:
    """``(3, ...)`` components first: closest point of P1Q1 minus closest point of P2Q2."""
    P1, Q1, P2, Q2 = (
        np.moveaxis(v, -1, 0) for v in np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (P1, Q1, P2, Q2)))
    )
    d1, d2, r = Q1 - P1, Q2 - P2, P1 - P2  # (3, ...) components first: cheaper than einsum on a length-3 axis

    def dot(u, v):
        return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]

    a, e, b, c, f = dot(d1, d1), dot(d2, d2), dot(d1, d2), dot(d1, r), dot(d2, r)
    denom = a * e - b * b
    parallel = denom <= 1e-12 * a * e
    s = np.where(parallel, 0.0, np.clip((b * f - c * e) / np.where(parallel, 1.0, denom), 0.0, 1.0))
    t = (b * s + f) / e
    s = np.where(t < 0, np.clip(-c / a, 0.0, 1.0), np.where(t > 1, np.clip((b - c) / a, 0.0, 1.0), s))
    t = np.clip(t, 0.0, 1.0)
    return r + s * d1 - t * d2


def leg_pairs(platform: Platform) -> np.ndarray:
    """``(k, 2)`` leg index pairs (0-based, in row order) that can collide: every pair sharing neither a
    plate joint (``leg_top``) nor a base joint (``geometry.base_joints``)."""
    leg_base = base_joints(platform)[1]
    i, j = np.triu_indices(6, 1)
    apart = (platform.leg_top[i] != platform.leg_top[j]) & (leg_base[i] != leg_base[j])
    return np.stack([i[apart], j[apart]], axis=-1).astype(np.intp)


def leg_axis_distances(platform: Platform, l) -> np.ndarray:
    """``(..., k)`` the shortest distance (m) between the two leg axes (base anchor to plate anchor) of each row of
    ``leg_pairs`` for leg vectors ``l`` ``(..., 6, 3)``; ``(..., 1)`` of inf when no pair can collide. The
    collision margin is this less the leg diameter."""
    l = np.asarray(l, dtype=float)
    pairs = leg_pairs(platform)
    if not len(pairs):
        return np.full(l.shape[:-2] + (1,), np.inf)
    B = platform.base_anchors
    P = (B + l).reshape(-1, 6, 3)  # plate anchors in B
    d = np.empty((len(P), len(pairs)))
    for k in range(0, len(P), _BLOCK):  # blocks that stay in cache: ~6x faster than one pass
        Pk = P[k : k + _BLOCK]
        d[k : k + _BLOCK] = segment_distances(B[pairs[:, 0]], Pk[:, pairs[:, 0]], B[pairs[:, 1]], Pk[:, pairs[:, 1]])
    return d.reshape(l.shape[:-2] + (len(pairs),))


def raw_margins(platform: Platform, l, R, limits: Limits, poses=None, convention: str = "utn", offsets=None) -> dict:
    """Per-element margins ``{name: (..., k)}`` (>= 0 inside) from leg vectors ``l`` ``(..., 6, 3)`` and
    plate rotations ``R`` ``(..., 3, 3)`` (or one ``(3, 3)``): k = 6 legs (stroke, joints), the rows of
    ``leg_pairs`` (collision), or 1 (dexterity, which needs ``poses``, or the plate offsets ``offsets``
    ``(..., 6, 3)`` r_i = R (p_TTi − p_TC) of those ``l``: the same numbers without recomputing R)."""
    out = {}
    L = np.sqrt(np.einsum("...k,...k->...", l, l))
    if limits.stroke:
        out["stroke"] = np.minimum(L - platform.L_min, platform.L_max - L)
    if limits.base_cone is not None or limits.top_cone is not None:
        u = l / L[..., None]
        if limits.base_cone is not None:
            axes = limits.base_axes if limits.base_axes is not None else np.array([0.0, 0.0, 1.0])
            ang = np.arccos(np.clip(np.einsum("...ik,...ik->...i", u, np.broadcast_to(axes, u.shape)), -1, 1))
            out["base_joint"] = limits.base_cone - ang
        if limits.top_cone is not None:
            axes_T = limits.top_axes if limits.top_axes is not None else np.tile([0.0, 0.0, 1.0], (6, 1))
            n = np.einsum("...jk,ik->...ij", R, axes_T)  # (..., 6, 3) plate joint axes in B
            ang = np.arccos(np.clip(np.einsum("...ik,...ik->...i", u, n), -1, 1))
            out["top_joint"] = limits.top_cone - ang
    if limits.leg_diameter is not None:
        out["collision"] = leg_axis_distances(platform, l) - limits.leg_diameter
    if limits.max_condition is not None:
        if offsets is not None:
            kappa = scaled_condition(platform, inverse_jacobian_of_legs(l, offsets))
        elif poses is not None:
            kappa = condition_number(platform, poses, convention)
        else:
            raise WorkspaceError(WorkspaceError.DEXTERITY_POSES)
        out["dexterity"] = (limits.max_condition - kappa)[..., None]
    return out


def margins_from_legs(platform: Platform, l, R, limits: Limits, poses=None, convention="utn") -> dict:
    """``{name: (margin (...), index (...))}``: the worst element of each ``raw_margins`` entry; index is
    the worst leg (0-based) or, for collision, the worst row of ``leg_pairs``."""
    return {
        n: (m.min(axis=-1), m.argmin(axis=-1))
        for n, m in raw_margins(platform, l, R, limits, poses, convention).items()
    }


def limit_margins(platform: Platform, poses, limits: Limits = Limits(), convention: str = "utn") -> dict:
    """Signed margins of ``(..., 6)`` poses to each active limit: ``{name: (margin (...), index (...))}``;
    a pose is inside where every margin is >= 0. Units in ``LIMIT_UNITS``; ``index`` as in
    ``margins_from_legs`` (worst leg, 0-based, or worst row of ``leg_pairs``)."""
    check_convention(convention)
    q = np.asarray(poses, dtype=float)
    l = leg_vectors(platform, q, convention)
    R = rotation_matrix(q[..., 3:], convention)
    return margins_from_legs(platform, l, R, limits, q, convention)


def classify(platform: Platform, poses, limits: Limits = Limits(), convention: str = "utn") -> np.ndarray:
    """``(...)`` True where a ``(..., 6)`` pose satisfies every active limit."""
    margins = limit_margins(platform, poses, limits, convention)
    inside = np.ones(np.shape(poses)[:-1], bool)
    for m, _ in margins.values():
        inside &= m >= 0
    return inside


def check_orientation(orientation) -> np.ndarray:
    """``(3,)`` finite float angles (rad) about X, Y, Z, or ``WorkspaceError`` naming the value."""
    o = np.asarray(orientation, dtype=float)
    if o.shape != (3,) or not np.all(np.isfinite(o)):
        raise WorkspaceError(WorkspaceError.ORIENTATION.format(value=np.asarray(orientation).tolist()))
    return o
