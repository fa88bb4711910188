"""Cross-checks of the closed-form kinematics against Drake's own computations on the closed-loop plant.

(a) ``anchor_frames``: the anchor frames read back from the parsed plant vs the ``Platform``'s anchors;
(b) ``drake_ik_lengths``: Drake's ``InverseKinematics`` on the plant with the plate pinned at a pose
    (its floating joint locked) returns prismatic positions, i.e. leg lengths;
(c) ``drake_fk_tip_errors``: with the joints set to the closed-form solution, Drake's forward
    kinematics places each piston tip on its plate anchor.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.solvers import SnoptSolver, SolverOptions

from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.drake.platform_model import build_plant, prismatic_joints, prismatic_positions, set_pose, set_poses


@dataclass
class PlantHandle:
    """A finalized closed-loop plant of a platform and a context to work in."""

    platform: Platform
    plant: object
    context: object


def make_plant(platform: Platform) -> PlantHandle:
    """The platform's closed-loop plant without visual geometry (nothing is shown: the same kinematics)."""
    plant, _ = build_plant(platform, visuals=False)
    return PlantHandle(platform, plant, plant.CreateDefaultContext())


def anchor_frames(h: PlantHandle) -> tuple[np.ndarray, np.ndarray]:
    """``(6, 3)`` p_BBi and ``(6, 3)`` p_TTi as read from the plant's frames ``base_anchor_i``/``top_anchor_i``."""
    base = np.array(
        [h.plant.GetFrameByName(f"base_anchor_{i + 1}").GetFixedPoseInBodyFrame().translation() for i in range(6)]
    )
    top = np.array(
        [h.plant.GetFrameByName(f"top_anchor_{i + 1}").GetFixedPoseInBodyFrame().translation() for i in range(6)]
    )
    return base, top


def drake_fk_tip_errors(h: PlantHandle, poses, convention: str = "utn") -> np.ndarray:
    """``(n, 6)`` |p_W piston tip − p_W plate anchor| (metres) with every joint set by ``model.set_pose``."""
    poses = np.atleast_2d(poses)
    tips = [h.plant.GetFrameByName(f"piston_{i + 1}") for i in range(6)]
    anchors = [h.plant.GetFrameByName(f"top_anchor_{i + 1}") for i in range(6)]
    out = np.empty((len(poses), 6))
    for k in set_poses(h.plant, h.context, h.platform, poses, convention):
        for i in range(6):
            tip = tips[i].CalcPoseInWorld(h.context).translation()
            anchor = anchors[i].CalcPoseInWorld(h.context).translation()
            out[k, i] = np.linalg.norm(tip - anchor)
    return out


def drake_ik_lengths(h: PlantHandle, poses, convention: str = "utn", tol: float = 1e-10) -> np.ndarray:
    """``(n, 6)`` leg lengths (metres) found by Drake's ``InverseKinematics``.

    For each pose the plate's floating joint is set to the pose and locked; the legs start from the
    home configuration (not from the answer) and the solver must close the six ball constraints.
    Raises ``RuntimeError`` naming the pose if the solver fails.
    """
    plant, ctx, p = h.plant, h.context, h.platform
    poses = np.atleast_2d(poses)
    top = plant.GetJointByName("top")
    solver = SnoptSolver()
    options = SolverOptions()
    options.SetOption(solver.solver_id(), "Major feasibility tolerance", tol)
    options.SetOption(solver.solver_id(), "Major optimality tolerance", tol)
    set_pose(plant, ctx, p, p.home_pose())  # set_pose sets every position: the home state is the same for all poses
    q_home = plant.GetPositions(ctx).copy()
    leg_idx = np.r_[
        [plant.GetJointByName(f"universal_{i + 1}").position_start() + j for i in range(6) for j in range(2)],
        [plant.GetJointByName(f"prismatic_{i + 1}").position_start() for i in range(6)],
    ]
    legs = prismatic_joints(plant)
    out = np.empty((len(poses), 6))
    for k in set_poses(plant, ctx, p, poses, convention):  # the plate at pose k (legs too, overwritten below)
        top.Lock(ctx)
        ik = InverseKinematics(plant, ctx)
        q = ik.q()
        guess = plant.GetPositions(ctx).copy()
        guess[leg_idx] = q_home[leg_idx]
        ik.get_mutable_prog().AddQuadraticErrorCost(np.eye(len(leg_idx)) * 1e-6, q_home[leg_idx], q[leg_idx])
        result = solver.Solve(ik.prog(), guess, options)
        top.Unlock(ctx)
        if not result.is_success():
            raise RuntimeError(
                f"Drake InverseKinematics failed at pose {k} {poses[k].tolist()}: {result.get_solution_result()}"
            )
        plant.SetPositions(ctx, result.GetSolution(q))
        out[k] = prismatic_positions(plant, ctx, legs)
    return out


def compare_ik_with_drake(platform: Platform, poses, convention: str = "utn") -> dict:
    """Worst errors (metres) of the three checks over ``(n, 6)`` poses: keys ``anchors``, ``ik``, ``fk``."""
    h = make_plant(platform)
    base, top = anchor_frames(h)
    anchors = max(np.abs(base - platform.base_anchors).max(), np.abs(top - platform.top_anchors_per_leg).max())
    L = leg_lengths(platform, poses, convention)
    ik = np.abs(drake_ik_lengths(h, poses, convention) - L).max()
    fk = drake_fk_tip_errors(h, poses, convention).max()
    return {"anchors": float(anchors), "ik": float(ik), "fk": float(fk)}
