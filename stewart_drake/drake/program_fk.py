"""Forward kinematics as a Drake ``MathematicalProgram``, and the assembly-mode search confirmed by it.

``ProgramFK`` states the forward kinematics of one platform as a MathematicalProgram: the plate pose
as decision variables (position p_BC and either a unit quaternion or the first two columns of R_BT
with orthonormality constraints; the third column is their cross product, so det R = +1), and the six
leg equations |p_BC + R_BT (p_TTi − p_TC) − p_BBi|² = L_i² as constraints, solved by SNOPT or IPOPT
from an initial guess. It finds one solution near the guess, like Newton, through a different
formulation and solver: ``assembly_modes`` here runs the numpy multi-start search of
``core/assembly_modes`` with this program as its polish, which confirms (``certified``) each mode.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from pydrake.common.eigen_geometry import Quaternion
from pydrake.math import RotationMatrix
from pydrake.solvers import IpoptSolver, MathematicalProgram, SnoptSolver, SolverOptions

from stewart_drake.core import assembly_modes as search
from stewart_drake.core.geometry import Platform
from stewart_drake.core.newton_fk import leg_geometry, validate_lengths
from stewart_drake.core.rotations import angles_from_matrix, check_convention, rotation_matrix
from stewart_drake.errors import FkInputError

SOLVERS = ("snopt", "ipopt")
ROTATION_PARAMETRISATIONS = ("quaternion", "matrix")


@dataclass(frozen=True)
class ProgramSolution:
    """One ``ProgramFK.solve`` result. ``residual`` (m) is re-evaluated in numpy from the returned
    pose, independently of the solver's own report."""

    pose: np.ndarray  # (6,) m, rad, convention
    position: np.ndarray  # (3,) p_BC
    rotation: np.ndarray  # (3, 3) R_BT
    residual: float
    success: bool
    solver: str
    solution_result: str
    solve_time_s: float


class ProgramFK:
    """Forward kinematics of one platform as a Drake ``MathematicalProgram`` (built once; each
    ``solve`` only changes the leg lengths and the initial guess).

    rotation  "quaternion" (4 variables + unit-norm constraint) or "matrix" (two columns of R_BT +
              three orthonormality constraints; third column = their cross product).
    solver    "snopt" or "ipopt" (both ship in the drake wheel).
    The squared lengths enter through six auxiliary variables fixed by a bounding box, so that the
    program is not rebuilt for new lengths.
    """

    def __init__(self, platform: Platform, rotation: str = "quaternion", solver: str = "snopt", tol: float = 1e-12):
        if rotation not in ROTATION_PARAMETRISATIONS:
            raise FkInputError(FkInputError.ROTATION.format(value=rotation, valid=", ".join(ROTATION_PARAMETRISATIONS)))
        if solver not in SOLVERS:
            raise FkInputError(FkInputError.SOLVER.format(value=solver, valid=", ".join(SOLVERS)))
        self.platform, self.rotation_kind, self.solver_name = platform, rotation, solver
        prog = MathematicalProgram()
        self.p = prog.NewContinuousVariables(3, "p")
        if rotation == "quaternion":
            self.z = prog.NewContinuousVariables(4, "q")
            w, x, y, z = self.z
            R = [
                [w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y)],
                [2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x)],
                [2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z],
            ]
            prog.AddConstraint(w * w + x * x + y * y + z * z, 1.0, 1.0)
        else:
            self.z = prog.NewContinuousVariables(6, "R")
            c0, c1 = list(self.z[:3]), list(self.z[3:])
            c2 = [c0[1] * c1[2] - c0[2] * c1[1], c0[2] * c1[0] - c0[0] * c1[2], c0[0] * c1[1] - c0[1] * c1[0]]
            R = [[c0[j], c1[j], c2[j]] for j in range(3)]
            prog.AddConstraint(sum(c * c for c in c0), 1.0, 1.0)
            prog.AddConstraint(sum(c * c for c in c1), 1.0, 1.0)
            prog.AddConstraint(sum(a * b for a, b in zip(c0, c1)), 0.0, 0.0)
        self.s = prog.NewContinuousVariables(6, "s")
        self._box = prog.AddBoundingBoxConstraint(np.ones(6), np.ones(6), self.s).evaluator()
        t = platform.top_anchors_per_leg - platform.rotation_centre
        for i in range(6):  # written out: numpy's object-array matmul warns on symbolic entries
            e = [
                self.p[j] + sum(R[j][k] * float(t[i, k]) for k in range(3)) - float(platform.base_anchors[i, j])
                for j in range(3)
            ]
            prog.AddConstraint(e[0] * e[0] + e[1] * e[1] + e[2] * e[2] - self.s[i], 0.0, 0.0)
        self.prog = prog
        self.solver = SnoptSolver() if solver == "snopt" else IpoptSolver()
        self.options = SolverOptions()
        if solver == "snopt":
            self.options.SetOption(self.solver.solver_id(), "Major feasibility tolerance", tol)
            self.options.SetOption(self.solver.solver_id(), "Major optimality tolerance", 1e-10)
        else:
            self.options.SetOption(self.solver.solver_id(), "tol", tol)
            self.options.SetOption(self.solver.solver_id(), "constr_viol_tol", tol)
            self.options.SetOption(self.solver.solver_id(), "print_level", 0)
        self._vars = np.concatenate([self.p, self.z, self.s])

    def solve(self, lengths, initial=None, convention: str = "utn", initial_rotation=None) -> ProgramSolution:
        """Solve for ``(6,)`` lengths (m) from ``initial`` (a ``(6,)`` pose, default home) or from
        ``initial`` = p_BC ``(3,)`` with ``initial_rotation`` = R_BT ``(3, 3)``."""
        check_convention(convention)
        L = validate_lengths(lengths)
        if L.shape != (6,):
            raise FkInputError(FkInputError.ONE_SET.format(what="ProgramFK.solve", shape=L.shape))
        if initial_rotation is None:
            q0 = np.asarray(self.platform.home_pose() if initial is None else initial, dtype=float)
            if q0.shape != (6,) or not np.all(np.isfinite(q0)):
                raise FkInputError(FkInputError.INITIAL_SIX.format(value=q0.tolist()))
            p0, R0 = q0[:3], rotation_matrix(q0[3:], convention)
        else:
            p0, R0 = np.asarray(initial, dtype=float), np.asarray(initial_rotation, dtype=float)
        if self.rotation_kind == "quaternion":
            z0 = RotationMatrix(RotationMatrix.ProjectToRotationMatrix(R0)).ToQuaternion().wxyz()
        else:
            z0 = np.concatenate([R0[:, 0], R0[:, 1]])
        self._box.set_bounds(L**2, L**2)
        x0 = np.concatenate([p0, z0, L**2])
        t0 = time.perf_counter()
        res = self.solver.Solve(self.prog, x0, self.options)
        dt = time.perf_counter() - t0
        p = res.GetSolution(self.p)
        z = res.GetSolution(self.z)
        if self.rotation_kind == "quaternion":
            w, x, y, zz = z / np.linalg.norm(z)
            R = RotationMatrix(Quaternion(w, x, y, zz)).matrix()
        else:
            R = RotationMatrix.ProjectToRotationMatrix(np.column_stack([z[:3], z[3:], np.cross(z[:3], z[3:])])).matrix()
        _, _, Lp = leg_geometry(self.platform, p[None], R[None])
        residual = float(np.abs(Lp[0] - L).max())
        pose = np.concatenate([p, angles_from_matrix(R, convention)])
        return ProgramSolution(
            pose, p, R, residual, bool(res.is_success()), self.solver_name, str(res.get_solution_result()), dt
        )


def solve_program(
    platform: Platform,
    lengths,
    initial=None,
    convention: str = "utn",
    rotation: str = "quaternion",
    solver: str = "snopt",
) -> ProgramSolution:
    """One-shot ``ProgramFK(platform, rotation, solver).solve(lengths, initial, convention)``."""
    return ProgramFK(platform, rotation, solver).solve(lengths, initial, convention)


def program_polish(platform: Platform, solver: str = "snopt", convention: str = "utn") -> search.Polish:
    """The polish callable ``core.assembly_modes.assembly_modes`` takes: one quaternion ``ProgramFK`` of
    ``platform`` built once, re-solved from each Newton solution p_BC ``(3,)``, R_BT ``(3, 3)`` for
    lengths ``(6,)``; returns its ``(p, R, success, residual)``."""
    prog = ProgramFK(platform, "quaternion", solver)

    def polish(lengths, p, R):
        sol = prog.solve(lengths, p, convention, initial_rotation=R)
        return sol.position, sol.rotation, sol.success, sol.residual

    return polish


def assembly_modes(
    platform: Platform, lengths, convention: str = "utn", *, polish: str | None = "snopt", **options
) -> search.AssemblyModes:
    """Every real assembly mode found for one ``(6,)`` leg-length set (metres) by
    ``core.assembly_modes.assembly_modes`` (``options``: its keyword arguments), each confirmed by a
    ``ProgramFK`` solved with ``polish`` ("snopt", "ipopt"; None: no confirmation, ``certified`` False)."""
    if polish is not None and polish not in SOLVERS:
        raise FkInputError(FkInputError.POLISH.format(valid=", ".join(SOLVERS), value=polish))
    fn = None if polish is None else program_polish(platform, polish, convention)
    return search.assembly_modes(platform, lengths, convention, polish=fn, **options)
