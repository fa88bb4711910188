"""``leg_model.drake_ik`` solves every target with one program whose bounds it resets, on the leg's plant shared
within the process (``leg_plant``): the answers must be those of a program built afresh per target on a fresh
plant (as it did before), bit for bit — the same problem, the same SNOPT."""

import numpy as np
import pytest
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.solvers import SnoptSolver, SolverOptions

from stewart_drake.drake.leg_model import LegPlant, drake_fk_errors, drake_ik, leg_plant
from stewart_drake.mechanisms.leg3r import Leg3R, check_branch, foot, random_configurations

LEG = Leg3R()


def _fresh_program_per_target(targets, branch, tol=1e-14):
    """The joint angles from a new InverseKinematics program per target (drake_ik's start, box and options)."""
    sign, (_, phi), h = check_branch(branch), LEG.shank, LegPlant(LEG)
    solver, options = SnoptSolver(), SolverOptions()
    options.SetOption(solver.solver_id(), "Major feasibility tolerance", tol)
    options.SetOption(solver.solver_id(), "Major optimality tolerance", tol)
    out = []
    for t in targets:
        guess = np.array([np.arctan2(t[0], -t[1]), -phi + sign * np.pi / 2])
        lo = np.array([guess[0] - np.pi, -phi if sign > 0 else -phi - np.pi])
        hi = np.array([guess[0] + np.pi, -phi + np.pi if sign > 0 else -phi])
        ik = InverseKinematics(h.plant, with_joint_limits=False)
        p = np.array([t[0], t[1], 0.0])
        ik.AddPositionConstraint(h.frames[3], np.zeros(3), h.frames[0], p, p)
        ik.get_mutable_prog().AddBoundingBoxConstraint(lo, hi, ik.q())
        out.append(solver.Solve(ik.prog(), guess, options).GetSolution(ik.q()))
    return np.array(out)


@pytest.mark.parametrize("branch", ["a", "b"])
def test_one_program_equals_a_program_per_target(branch):
    targets = foot(LEG, random_configurations(LEG, 40, seed=9))[:, :2]
    drake_fk_errors(LEG, random_configurations(LEG, 3, seed=1))  # leaves the shared plant's joints elsewhere
    assert leg_plant(LEG) is leg_plant(Leg3R())  # one plant per leg and process, shared by the checks
    q, _ = drake_ik(LEG, targets, branch)
    assert np.ptp(q[:, 0]) > 0.5  # the targets differ: each solve starts from another bound and guess
    np.testing.assert_array_equal(q, _fresh_program_per_target(targets, branch))


def test_foot_transform_is_the_last_dh_frame():
    h = LegPlant(LEG)
    q = random_configurations(LEG, 5, seed=3)
    for qk in q:
        np.testing.assert_array_equal(h.foot_transform(qk), h.frame_transforms(qk)[3])
