"""The Drake plant of the seed-003 3R leg (its SDF from ``core/sdf_models.leg_sdf``, generated row by row
from the DH table), and checks of the numpy forward and inverse kinematics against Drake.

Frames ``dh_0`` .. ``dh_3`` of the model are the DH frames; ``dh_3`` is the foot tip. Joints ``hip`` and
``knee`` are revolute (angle = q_i), ``ankle`` fixed.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant
from pydrake.solvers import SnoptSolver, SolverOptions

from stewart_drake.core.sdf_models import leg_sdf
from stewart_drake.mechanisms.leg3r import Leg3R, check_branch, frame_transforms

# drake_ik accepts a solution whose foot (by Drake's FK) is this close to the target. With tight
# tolerances SNOPT lands at ~1e-16 m typically but sometimes stops ("cannot be improved") at up to a few
# 1e-8 m near a stretched leg; 0.1 µm is far below any leg's precision.
GAP_TOL_M = 1e-7


class LegPlant:
    """A finalized continuous ``MultibodyPlant`` of the leg, a context, and its DH frames."""

    def __init__(self, leg: Leg3R):
        self.leg = leg
        self.plant = MultibodyPlant(0.0)
        Parser(self.plant).AddModelsFromString(leg_sdf(leg), "sdf")
        self.plant.Finalize()
        self.context = self.plant.CreateDefaultContext()
        self.frames = [self.plant.GetFrameByName(f"dh_{i}") for i in range(4)]
        self.joints = [self.plant.GetJointByName("hip"), self.plant.GetJointByName("knee")]

    def set_q(self, q) -> None:
        for j, v in zip(self.joints, q):
            j.set_angle(self.context, float(v))

    def foot_transform(self, q) -> np.ndarray:
        """``(4, 4)`` X_{dh_0, dh_3} (the foot) computed by Drake at joint angles ``q`` (2,)."""
        self.set_q(q)
        return self.plant.CalcRelativeTransform(self.context, self.frames[0], self.frames[3]).GetAsMatrix4()

    def frame_transforms(self, q) -> np.ndarray:
        """``(4, 4, 4)`` X_{dh_0, dh_i} computed by Drake at joint angles ``q`` (2,)."""
        self.set_q(q)
        return np.stack(
            [self.plant.CalcRelativeTransform(self.context, self.frames[0], f).GetAsMatrix4() for f in self.frames]
        )


@lru_cache(maxsize=4)
def leg_plant(leg: Leg3R) -> LegPlant:
    """The ``LegPlant`` of ``leg``, parsed once per process (the checks below set every joint before they read)."""
    return LegPlant(leg)


def drake_fk_errors(leg: Leg3R, q) -> np.ndarray:
    """``(n,)`` worst element-wise difference between Drake's X_{dh_0, dh_i} and the numpy DH products
    T_0^i (i = 0..3) for joint angles ``q`` (n, 2)."""
    h = leg_plant(leg)
    q = np.atleast_2d(q)
    ours = frame_transforms(leg, q)
    return np.array([np.abs(h.frame_transforms(q[k]) - ours[k]).max() for k in range(len(q))])


def drake_ik(leg: Leg3R, targets, branch: str, tol: float = 1e-14) -> tuple[np.ndarray, np.ndarray]:
    """Drake's ``InverseKinematics`` for foot targets (n, 2) [Px, Py] in frame ``dh_0``: returns the
    joint angles ``(n, 2)`` and the foot's remaining distance to the target by Drake's FK ``(n,)`` (m).

    The knee is restricted to the branch's side (virtual knee angle q2 + phi >= 0 for "a", <= 0 for
    "b"); joint limits are ignored so that both branches exist everywhere. SNOPT starts from the thigh
    pointing at the target and the knee in the middle of its branch (q2 + phi = ±90°), not from the
    answer; q1 is boxed to ±180° about that start. Raises ``RuntimeError`` naming the target if the
    foot ends farther than ``GAP_TOL_M`` from it.
    """
    sign = check_branch(branch)
    _, phi = leg.shank
    h = leg_plant(leg)
    solver, options = SnoptSolver(), SolverOptions()
    options.SetOption(solver.solver_id(), "Major feasibility tolerance", tol)
    options.SetOption(solver.solver_id(), "Major optimality tolerance", tol)
    targets = np.atleast_2d(targets)
    out, gaps = np.empty((len(targets), 2)), np.empty(len(targets))
    # One program for every target, its two constraints' bounds set per target: the same problem as a program
    # built per target (the same variables and constraints in the same order), without rebuilding it.
    ik = InverseKinematics(h.plant, with_joint_limits=False)
    foot_at = ik.AddPositionConstraint(h.frames[3], np.zeros(3), h.frames[0], np.zeros(3), np.zeros(3)).evaluator()
    prog = ik.get_mutable_prog()
    box = prog.AddBoundingBoxConstraint(np.zeros(2), np.zeros(2), ik.q()).evaluator()
    for k, t in enumerate(targets):
        guess = np.array([np.arctan2(t[0], -t[1]), -phi + sign * np.pi / 2])
        lo = np.array([guess[0] - np.pi, -phi if sign > 0 else -phi - np.pi])
        hi = np.array([guess[0] + np.pi, -phi + np.pi if sign > 0 else -phi])
        p = np.array([t[0], t[1], 0.0])
        foot_at.set_bounds(p, p)
        box.set_bounds(lo, hi)
        result = solver.Solve(prog, guess, options)
        qk = result.GetSolution(ik.q())
        gap = np.linalg.norm(h.foot_transform(qk)[:2, 3] - t) if np.all(np.isfinite(qk)) else np.inf
        if not gap <= GAP_TOL_M:
            raise RuntimeError(
                f"Drake InverseKinematics failed at target {k} {t.tolist()} (branch {branch}): "
                f"foot {gap:.3g} m from the target ({result.get_solution_result()})"
            )
        out[k], gaps[k] = qk, gap
    return out, gaps
