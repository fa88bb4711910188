"""The plate's motion in the engines' free-body terms (numpy only), from poses q, q̇, q̈ in pose coordinates.

The engines carry the plate as a free body whose link frame is T (origin p_BT = p_BC − R p_TC, C the rotation
centre); legs carry two universal angles and a length each (``leg_bodies.leg_joint_positions``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stewart_drake.core.argcheck import as_poses
from stewart_drake.core.dynamics import plate_motion
from stewart_drake.core.leg_bodies import leg_joint_positions
from stewart_drake.core.rotations import check_convention
from stewart_drake.core.vec3 import cross


@dataclass(frozen=True)
class PlateState:
    """The plate as a free body for ``(n, 6)`` samples, all in the base frame W = B (SI):
    ``R`` (n, 3, 3) R_WT, ``p`` (n, 3) T's origin, ``v`` (n, 3) its velocity, ``a`` (n, 3) its acceleration,
    ``w`` (n, 3) the angular velocity, ``wd`` (n, 3) the angular acceleration; ``angles`` (n, 6, 2) the
    universal-joint angles (rad) and ``lengths`` (n, 6) the leg lengths (m)."""

    R: np.ndarray
    p: np.ndarray
    v: np.ndarray
    a: np.ndarray
    w: np.ndarray
    wd: np.ndarray
    angles: np.ndarray
    lengths: np.ndarray


def plate_state(platform, q, qd=None, qdd=None, convention: str = "utn") -> PlateState:
    """``PlateState`` of ``(n, 6)`` poses q (m, rad) and their rates q̇, q̈ (zero when omitted)."""
    check_convention(convention)
    q = np.atleast_2d(as_poses(q))
    qd = np.zeros_like(q) if qd is None else np.atleast_2d(as_poses(qd, "qd", "qd sample"))
    qdd = np.zeros_like(q) if qdd is None else np.atleast_2d(as_poses(qdd, "qdd", "qdd sample"))
    mo = plate_motion(platform, q, qd, qdd, convention)
    R, w, wd = mo["R"], mo["omega"], mo["omega_dot"]
    r = np.einsum("...ij,j->...i", R, platform.rotation_centre)  # C − T in W
    p = q[:, :3] - r
    v = qd[:, :3] - cross(w, r)
    a = qdd[:, :3] - cross(wd, r) - cross(w, cross(w, r))
    angles, lengths = leg_joint_positions(platform, q, convention)
    return PlateState(R, p, v, a, w, wd, angles, lengths)


class ConstrainedSolve:
    """The leg forces of an engine's model from its constrained inverse dynamics ``system(st, k) -> ([B Gᵀ], τ)``
    (the unknowns: the six actuator forces first, then the closures' forces), shared by both engines."""

    def leg_forces(self, q, qd, qdd, convention: str = "utn") -> np.ndarray:
        """``(n, 6)`` actuator forces (N, > 0 pushes the plate away) along ``(n, 6)`` q, q̇, q̈, legs' inertia included."""
        st = plate_state(self.platform, q, qd, qdd, convention)
        out = np.empty(st.lengths.shape)
        for k in range(len(out)):
            out[k] = self.actuator_forces(st, k)
        return out

    def actuator_forces(self, st, k: int) -> np.ndarray:
        """Sample ``k``'s ``(6,)`` actuator forces (N) of a ``plate.PlateState``."""
        A, tau = self.system(st, k)
        return np.linalg.solve(A, tau)[:6]

    def condition(self, st, k: int) -> float:
        """The condition number of sample ``k``'s [B Gᵀ]."""
        return float(np.linalg.cond(self.system(st, k)[0]))
