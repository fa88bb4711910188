"""The 3R planar leg (seed 003) as functions: ``leg_fk`` (the foot for joint angles, by the DH table) and
``leg_ik`` (the joint angles, both elbow branches, for a foot position and optionally its orientation)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stewart_drake.api.result import Result
from stewart_drake.core.argcheck import as_choice, as_real
from stewart_drake.errors import OPTION_JOINT_ANGLES, OPTION_JOINT_OVERFLOW, OPTION_TARGET, LegError
from stewart_drake.mechanisms.leg3r import (
    Leg3R,
    foot,
    forward_kinematics,
    inverse_kinematics,
    inverse_kinematics_3r,
    limit_violations,
    within_limits,
)

__all__ = ["leg_fk", "leg_ik", "LegFKResult", "LegIKResult"]


def make_leg(l1: float | None = None, l2: float | None = None, l3: float | None = None) -> Leg3R:
    """The seed-003 leg with the lengths given (m); the others at their defaults (80, 80, 30 mm)."""
    dims = {n: as_real(v, n) for n, v in (("l1", l1), ("l2", l2), ("l3", l3)) if v is not None}
    return Leg3R(**dims)


@dataclass(repr=False)
class LegFKResult(Result):
    """The foot of the 3R leg for joint angles (``leg_fk``).

    Attributes:
        q: ``(2,)`` hip and knee angles q1, q2, rad.
        foot: ``(2,)`` the foot's position Px, Py, m.
        gamma: the foot's orientation q1 + q2 + alpha, rad.
        T03: ``(4, 4)`` the foot frame in the hip frame (DH product), m.
        within_limits: q1 and q2 inside their joint limits.
        limit_violations: ``{"index", "joint", "value_rad", "limit_rad", "excess_rad"}`` per joint outside.
    """

    q: np.ndarray
    foot: np.ndarray
    gamma: float
    T03: np.ndarray
    within_limits: bool
    limit_violations: list

    @property
    def ok(self) -> bool:
        """The joint angles are inside their limits."""
        return self.within_limits

    def _fields(self) -> dict:
        return {
            "q": self.q,
            "foot": self.foot,
            "gamma": self.gamma,
            "T03": self.T03,
            "within_limits": self.within_limits,
            "limit_violations": self.limit_violations,
        }


@dataclass(repr=False)
class LegIKResult(Result):
    """The joint angles of the 3R leg for a foot position (``leg_ik``).

    Attributes:
        target: ``(2,)`` the foot position asked for, m.
        gamma: the foot orientation asked for, rad, or None (then each solution is ``[q1, q2]``).
        solutions: branch (``"a"``: knee angle >= 0, ``"b"``: <= 0) -> ``{"q": [q1, q2(, q3)] rad,
            "within_limits"}``.
    """

    target: np.ndarray
    gamma: float | None
    solutions: dict

    @property
    def ok(self) -> bool:
        """At least one branch is inside the joint limits."""
        return any(s["within_limits"] for s in self.solutions.values())

    def _fields(self) -> dict:
        return {"target": self.target, "gamma": self.gamma, "solutions": self.solutions}


def leg_fk(
    q1: float, q2: float, *, l1: float | None = None, l2: float | None = None, l3: float | None = None
) -> LegFKResult:
    """The foot's position and orientation for the hip and knee angles (the seed's DH table).

    Args:
        q1: hip angle, rad.
        q2: knee angle, rad.
        l1: thigh length, m (default 0.080).
        l2: shank length, m (default 0.080).
        l3: foot length, m (default 0.030).

    Returns:
        The foot, its frame and whether the angles are inside the joint limits (``ok``).

    Raises:
        StewartError: a length that is not positive, angles that are not finite or whose sum overflows.
    """
    return solve_leg_fk(np.array([as_real(q1, "q1"), as_real(q2, "q2")], dtype=float), make_leg(l1, l2, l3))


def solve_leg_fk(q: np.ndarray, leg: Leg3R, shown=None, unit: str = "rad", scale: float = 1.0) -> LegFKResult:
    """``leg_fk`` of ``q`` (2,) rad; errors show ``shown`` (the angles as typed, in ``unit``, ``scale`` rad
    each: ``stewart-drake leg fk``'s) or ``q``, and refuse a foot angle that is no number in ``unit``."""
    shown = q.tolist() if shown is None else shown
    if not np.all(np.isfinite(q)):
        raise LegError(OPTION_JOINT_ANGLES.format(value=shown))
    f = foot(leg, q)
    if not np.isfinite(f[2] / scale):  # angles near the float range: their sum in the user's unit is no number
        raise LegError(OPTION_JOINT_OVERFLOW.format(value=shown, unit=unit))
    return LegFKResult(
        q,
        np.asarray(f[:2]),
        float(f[2]),
        forward_kinematics(leg, q),
        bool(within_limits(leg, q)),
        limit_violations(leg, q),
    )


def leg_ik(
    px: float,
    py: float,
    *,
    gamma: float | None = None,
    branch: str = "both",
    l1: float | None = None,
    l2: float | None = None,
    l3: float | None = None,
) -> LegIKResult:
    """The joint angles that put the foot at ``(px, py)``, for one or both elbow branches.

    Args:
        px: foot x, m.
        py: foot y, m.
        gamma: also the foot orientation, rad: the seed's 3R method (corrected), which returns q3 too.
        branch: ``"a"`` (knee angle >= 0), ``"b"`` (<= 0) or ``"both"``.
        l1: thigh length, m (default 0.080).
        l2: shank length, m (default 0.080).
        l3: foot length, m (default 0.030).

    Returns:
        The solution of each branch asked for and whether it is inside the joint limits.

    Raises:
        StewartError: a length that is not positive, a target that is not finite or out of reach, an unknown
            branch.
    """
    leg = make_leg(l1, l2, l3)
    t = np.array([as_real(px, "px"), as_real(py, "py")], dtype=float)
    gamma = None if gamma is None else as_real(gamma, "gamma")
    branch = as_choice(branch, "branch", ("a", "b", "both"))
    if not np.all(np.isfinite(t)):
        raise LegError(OPTION_TARGET.format(value=t.tolist()))
    sols = {}
    for b in ("a", "b") if branch == "both" else (branch,):
        q = inverse_kinematics(leg, t, b) if gamma is None else inverse_kinematics_3r(leg, np.r_[t, gamma], b)
        sols[b] = {"q": np.asarray(q), "within_limits": bool(within_limits(leg, q[:2]))}
    return LegIKResult(t, None if gamma is None else float(gamma), sols)
