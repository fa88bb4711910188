"""Forward kinematics with Drake's MathematicalProgram, and every assembly mode for a leg-length set.

``ProgramFK`` states the forward kinematics of one platform as a MathematicalProgram: the plate pose
as decision variables (position p_BC and either a unit quaternion or the first two columns of R_BT
with orthonormality constraints; the third column is their cross product, so det R = +1), and the six
leg equations |p_BC + R_BT (p_TTi − p_TC) − p_BBi|² = L_i² as constraints, solved by SNOPT or IPOPT
from an initial guess. It finds one solution near the guess, like Newton, through a different
formulation and solver: we use it to polish and independently confirm the Newton solutions.

``assembly_modes`` finds the real solutions ("assembly modes") for one set of lengths:

1. **Generate** — seeded multi-start: random orientations R (uniform on SO(3)) each paired with the
   position that best fits the six leg equations for that R (they are linear in p once the first is
   subtracted from the others), then the batched Newton of ``fk.newton_core`` from every start.
   For a platform whose base anchors and plate anchors are both planar (z = 0), the mirror image of
   every solution about the base plane is also a solution; with ``use_symmetry`` it is added directly.
2. **Deduplicate** — solutions closer than ``dedupe_tol`` (position and rotation matrix) are one.
3. **Polish and confirm** — each distinct solution is re-solved by ``ProgramFK`` from that point; it is
   ``certified`` when the program reports success, its leg residual is below 1e-9 m and it lands on the
   same solution. A final Newton step brings the residual to the rounding floor.
4. Rounds of starts continue until the theoretical maximum number of solutions is found (then the set
   is provably complete), or ``patience`` rounds in a row find nothing new, or ``max_rounds``.

What this guarantees, and what not:
- Every returned mode satisfies the six leg equations to its reported ``residual`` (< 1e-12 m), and its
  Jacobian is non-singular (``sigma_min`` > 0), so an exact solution lies within about
  residual / sigma_min of it. This is a numerical, not an interval-arithmetic, proof.
- ``complete`` is True only when the number of distinct modes found equals the known upper bound on
  the number of isolated (complex) solutions: 40 for a general 6-6 platform (Dietmaier 1998 shows all
  40 can be real), 16 when the legs share three plate (or base) joints in pairs (3-6). Then no
  solution was missed. Otherwise the search is probabilistic: a mode whose basin of attraction is tiny may be
  missed; more starts (``n_starts``, ``max_rounds``) lower that risk but never to zero. The complete
  solver is ``stewart_drake.homotopy`` (parameter homotopy, every path classified, certified modes);
  this search remains as an independent second method.
- A platform whose solution set is not finite (an architecturally singular design, self-motions)
  returns finitely many sample points of it.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from stewart_drake.errors import ForwardKinematicsError
from stewart_drake.core.newton_fk import (
    CONVERGED,
    _analyse_jinv,
    _legs,
    anchor_scale,
    legs_and_jacobian,
    newton_core,
    validate_lengths,
)
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import check_stroke, plate_anchors
from stewart_drake.core.rotations import angles_from_matrix, check_convention, rotation_matrix

SOLVERS = ("snopt", "ipopt")
ROTATION_PARAMETRISATIONS = ("quaternion", "matrix")
CERTIFY_RESIDUAL = 1e-9  # m: a program solution with a larger leg residual is not a confirmation


# ----------------------------------------------------------------------------------------------
# Dietmaier's 40-real-solution geometry


def dietmaier_platform() -> tuple[Platform, np.ndarray]:
    """Dietmaier's (1998) general 6-6 Stewart–Gough platform with 40 real assembly modes, and its
    leg lengths ``(6,)``. Dimensionless units read as metres; the anchors are not planar.

    Source of the numbers: we could not read the paper itself; the coordinates below (base anchors,
    plate anchors, leg lengths) appear in a Stewart-platform example in Drake's C++ sources (a
    mixed-integer rotation-constraint demo, found by code search; the file does not name Dietmaier)
    and match the values usually quoted for Dietmaier's example. The result confirms them:
    ``assembly_modes`` finds 40 real, distinct, non-singular solutions (``tests/test_forward.py``),
    which only a 40-real-solution geometry can give. The stroke [0.5, 1.6] m is our choice (it holds
    every leg); the home pose is a placeholder (the geometry has no natural one)."""
    base = np.array(
        [
            [0.0, 0.0, 0.0],
            [1.107915, 0.0, 0.0],
            [0.549094, 0.756063, 0.0],
            [0.735077, -0.223935, 0.525991],
            [0.514188, -0.526063, -0.368418],
            [0.590473, 0.094733, -0.205018],
        ]
    )
    top = np.array(
        [
            [0.0, 0.0, 0.0],
            [0.542805, 0.0, 0.0],
            [0.956919, -0.528915, 0.0],
            [0.665885, -0.353482, 1.402538],
            [0.478359, 1.158742, 0.107672],
            [-0.137087, -0.235121, 0.353913],
        ]
    )
    lengths = np.array([1.0, 0.645275, 1.086284, 1.503439, 1.281933, 0.771071])
    p = _kinematic_platform("dietmaier-1998", "Dietmaier 1998: general 6-6 platform with 40 real assembly modes", base, top, (0.5, 1.6))
    return p, lengths


def _kinematic_platform(name: str, description: str, p_BBi, p_TTj, stroke) -> Platform:
    """A massless 6-6 platform (anchors ``(6, 3)`` m, leg i on plate anchor i, stroke ``(2,)`` m, home
    height 1 m): geometry only, for the FK solvers' reference cases."""
    return Platform(name=name, description=description, base_anchors=p_BBi, top_anchors=p_TTj, leg_top=np.arange(6),
                    stroke=np.asarray(stroke, dtype=float), mass=0.0, com=np.zeros(3), inertia=np.zeros((3, 3)), home_height=1.0)


def _random_ring(rng, radius: float, dz: float | None, n: int = 6) -> np.ndarray:
    """``(n, 3)`` anchors at sorted random angles, radii in [0.6, 1] × ``radius``, z uniform in ±``dz``
    (``None``: z = 0, drawing nothing)."""
    ang = np.sort(rng.uniform(0, 2 * np.pi, n))
    r = radius * rng.uniform(0.6, 1.0, n)
    z = np.zeros(n) if dz is None else rng.uniform(-dz, dz, n)
    return np.stack([r * np.cos(ang), r * np.sin(ang), z], -1)


def _lengths_near_home(p: Platform, rng, angle: float) -> tuple[Platform, np.ndarray]:
    """``(p, lengths (6,))`` of a random pose within ±0.1 m and ±``angle`` rad of ``p``'s home."""
    from stewart_drake.core.kinematics import leg_lengths

    q = p.home_pose() + np.r_[rng.uniform(-0.1, 0.1, 3), rng.uniform(-angle, angle, 3)]
    return p, leg_lengths(p, q)


def general_platform(seed: int = 0) -> tuple[Platform, np.ndarray]:
    """A seeded random general (non-planar, asymmetric) 6-6 platform and the leg lengths ``(6,)`` of a
    pose near its home: base anchors within 1 m of the axis (z within ±0.2 m), plate anchors within
    0.6 m (z within ±0.1 m), home height 1 m. For benchmarks and reports."""
    rng = np.random.default_rng(seed)
    p = _kinematic_platform(f"general-6-6-seed{seed}", "seeded random general 6-6 platform",
                            _random_ring(rng, 1.0, 0.2), _random_ring(rng, 0.6, 0.1), (0.5, 2.0))
    return _lengths_near_home(p, rng, 0.2)


def planar_platform(seed: int = 0) -> tuple[Platform, np.ndarray]:
    """A seeded random planar 6-6 platform (base anchors at z = 0 within 1 m of the axis, plate anchors
    at z = 0 within 0.6 m, at random angles: no symmetry) and the leg lengths ``(6,)`` of a random pose
    near its home (±0.1 m, ±0.3 rad). For tests and benchmarks of the complete solvers."""
    rng = np.random.default_rng(seed)
    p = _kinematic_platform(f"planar-6-6-seed{seed}", "seeded random planar 6-6 platform",
                            _random_ring(rng, 1.0, None), _random_ring(rng, 0.6, None), (0.3, 2.5))
    return _lengths_near_home(p, rng, 0.3)


def max_solutions(platform: Platform) -> int:
    """Upper bound on the number of isolated complex forward-kinematics solutions: 16 when the plate
    or the base has only three distinct joints each shared by two legs (3-6 / 6-3), else 40."""
    n_base = len(np.unique(np.round(platform.base_anchors, 12), axis=0))
    if len(platform.top_anchors) == 3 or n_base == 3:
        return 16
    return 40


def is_planar(platform: Platform, tol: float = 1e-12) -> bool:
    """True when all base anchors have z = 0 in B and all plate anchors have z = p_TC,z in T: then
    the mirror image of a solution about the base plane is a solution too."""
    return bool(
        np.all(np.abs(platform.base_anchors[:, 2]) <= tol)
        and np.all(np.abs(platform.top_anchors[:, 2] - platform.rotation_centre[2]) <= tol)
    )


# ----------------------------------------------------------------------------------------------
# MathematicalProgram


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
        from pydrake.solvers import IpoptSolver, MathematicalProgram, SnoptSolver, SolverOptions

        if rotation not in ROTATION_PARAMETRISATIONS:
            raise ValueError(f"unknown rotation parametrisation {rotation!r}; expected one of {', '.join(ROTATION_PARAMETRISATIONS)}")
        if solver not in SOLVERS:
            raise ValueError(f"unknown solver {solver!r}; expected one of {', '.join(SOLVERS)}")
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
        from pydrake.math import RotationMatrix

        check_convention(convention)
        L = validate_lengths(lengths)
        if L.shape != (6,):
            raise ValueError(f"ProgramFK.solve takes one length set of shape (6,), got {L.shape}")
        if initial_rotation is None:
            q0 = np.asarray(self.platform.home_pose() if initial is None else initial, dtype=float)
            if q0.shape != (6,) or not np.all(np.isfinite(q0)):
                raise ValueError(f"initial pose must be 6 finite numbers, got {q0.tolist()}")
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
            R = RotationMatrix(_quat(w, x, y, zz)).matrix()
        else:
            R = RotationMatrix.ProjectToRotationMatrix(np.column_stack([z[:3], z[3:], np.cross(z[:3], z[3:])])).matrix()
        _, _, Lp = _legs(self.platform, p[None], R[None])
        residual = float(np.abs(Lp[0] - L).max())
        pose = np.concatenate([p, angles_from_matrix(R, convention)])
        return ProgramSolution(pose, p, R, residual, bool(res.is_success()), self.solver_name, str(res.get_solution_result()), dt)


def _quat(w, x, y, z):
    from pydrake.common.eigen_geometry import Quaternion

    return Quaternion(w, x, y, z)


def solve_program(platform: Platform, lengths, initial=None, convention: str = "utn", rotation: str = "quaternion", solver: str = "snopt") -> ProgramSolution:
    """One-shot ``ProgramFK(platform, rotation, solver).solve(lengths, initial, convention)``."""
    return ProgramFK(platform, rotation, solver).solve(lengths, initial, convention)


# ----------------------------------------------------------------------------------------------
# All assembly modes


@dataclass(frozen=True)
class AssemblyMode:
    """One real solution of the forward kinematics.

    pose (6,) m/rad in ``convention``; position (3,) p_BC; rotation (3, 3) R_BT; residual (m) max leg
    error; det_sign: sign of det J⁻¹ (the singularity-free region the mode lies in); condition: 2-norm
    condition number of the scaled J⁻¹; sigma_min: its smallest singular value (singularity distance);
    above_base: every plate anchor has z > 0 in B; within_stroke: the lengths are within the stroke (a
    property of the input, the same for every mode); certified: MathematicalProgram confirmed it;
    distance_to_home: |Δp| / anchor radius + rotation angle (rad) from the home pose.
    """

    pose: np.ndarray
    position: np.ndarray
    rotation: np.ndarray
    residual: float
    det_sign: int
    condition: float
    sigma_min: float
    above_base: bool
    within_stroke: bool
    certified: bool
    distance_to_home: float

    def to_dict(self) -> dict:
        return {
            "pose": self.pose.tolist(),
            "residual_m": self.residual,
            "det_sign": self.det_sign,
            "condition": self.condition,
            "sigma_min": self.sigma_min,
            "above_base": self.above_base,
            "within_stroke": self.within_stroke,
            "certified": self.certified,
            "distance_to_home": self.distance_to_home,
        }


@dataclass(frozen=True)
class AssemblyModes:
    """All modes found, sorted by distance to the home pose (the first is the nearest)."""

    modes: list[AssemblyMode]
    lengths: np.ndarray
    max_solutions: int
    starts: int
    rounds: int
    elapsed_s: float
    timings_s: dict = field(default_factory=dict)

    @property
    def complete(self) -> bool:
        """True when the number found equals the theoretical maximum: no solution can be missing."""
        return len(self.modes) == self.max_solutions

    def poses(self) -> np.ndarray:
        """``(k, 6)`` poses of the modes."""
        return np.array([m.pose for m in self.modes]).reshape(-1, 6)

    def __len__(self) -> int:
        return len(self.modes)


def random_rotations(n: int, rng: np.random.Generator) -> np.ndarray:
    """``(n, 3, 3)`` rotation matrices uniform on SO(3) (normalised Gaussian quaternions)."""
    q = rng.normal(size=(n, 4))
    w, x, y, z = (q / np.linalg.norm(q, axis=-1, keepdims=True)).T
    return np.stack(
        [
            1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
            2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
            2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y),
        ],
        -1,
    ).reshape(n, 3, 3)


def best_position(platform: Platform, R: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """``(n, 3)`` least-squares p_BC for orientations ``(n, 3, 3)``: |p + c_i|² = L_i² with
    c_i = R r_i − p_BBi is linear in p after subtracting leg 1's equation from the others."""
    c = np.swapaxes(R @ (platform.top_anchors_per_leg - platform.rotation_centre).T, -1, -2) - platform.base_anchors
    A = 2 * (c[:, 1:] - c[:, :1])
    cc = np.sum(c * c, axis=-1)
    y = lengths[1:] ** 2 - lengths[0] ** 2 - cc[:, 1:] + cc[:, :1]
    return (np.linalg.pinv(A) @ y[..., None])[..., 0]


def _mirror(p: np.ndarray, R: np.ndarray):
    """Mirror image about the base plane of a planar platform: p -> M p, R -> M R M, M = diag(1, 1, -1)."""
    M = np.array([1.0, 1.0, -1.0])
    return p * M, R * M[:, None] * M[None, :]


def _dedupe(p: np.ndarray, R: np.ndarray, scale: float, tol: float) -> np.ndarray:
    """Indices of distinct solutions (keeps the first of each cluster)."""
    key = np.concatenate([p / scale, R.reshape(len(R), 9)], axis=-1)
    keep = []
    for i in range(len(key)):
        if not keep or np.min(np.max(np.abs(key[keep] - key[i]), axis=-1)) > tol:
            keep.append(i)
    return np.array(keep, dtype=np.intp)


def assembly_modes(
    platform: Platform,
    lengths,
    convention: str = "utn",
    *,
    n_starts: int = 2000,
    max_rounds: int = 10,
    patience: int = 2,
    seed: int = 0,
    polish: str | None = "snopt",
    use_symmetry: bool = True,
    dedupe_tol: float = 1e-6,
    tol: float = 1e-13,
) -> AssemblyModes:
    """Every real assembly mode found for one ``(6,)`` leg-length set (metres); see the module
    docstring for the method and what it guarantees. ``polish`` = "snopt", "ipopt" or None (skip the
    MathematicalProgram confirmation: faster, ``certified`` is then False). Raises
    ``ForwardKinematicsError`` if no mode at all is found."""
    check_convention(convention)
    L = validate_lengths(lengths)
    if L.shape != (6,):
        raise ValueError(f"assembly_modes takes one length set of shape (6,), got {L.shape}")
    if polish is not None and polish not in SOLVERS:
        raise ValueError(f"polish must be one of {', '.join(SOLVERS)} or None, got {polish!r}")
    t_start = time.perf_counter()
    rng = np.random.default_rng(seed)
    scale = anchor_scale(platform)
    size = max(np.abs(platform.base_anchors).max(), scale, L.max())
    n_max = max_solutions(platform)
    mirror = use_symmetry and is_planar(platform)
    P = np.zeros((0, 3))
    RR = np.zeros((0, 3, 3))
    starts = rounds = idle = 0
    t_newton = 0.0
    while rounds < max_rounds and len(P) < n_max and idle < patience:
        rounds += 1
        t0 = time.perf_counter()
        R0 = random_rotations(n_starts, rng)
        p0 = best_position(platform, R0, L)
        if rounds == 1:  # also start from home, so that the mode nearest home is always tried
            h = platform.home_pose()
            R0 = np.concatenate([rotation_matrix(h[3:], "utn")[None], R0])
            p0 = np.concatenate([h[None, :3], p0])
        starts += len(p0)
        p, R, _, _, status = newton_core(
            platform, p0, R0, np.broadcast_to(L, (len(p0), 6)), tol, 40, 0.25 * size, 0.5
        )
        ok = status == CONVERGED
        p, R = p[ok], R[ok]
        if mirror and len(p):
            pm, Rm = _mirror(p, R)
            p, R = np.concatenate([p, pm]), np.concatenate([R, Rm])
        before = len(P)
        P, RR = np.concatenate([P, p]), np.concatenate([RR, R])
        keep = _dedupe(P, RR, size, dedupe_tol)
        P, RR = P[keep], RR[keep]
        idle = idle + 1 if len(P) == before else 0
        t_newton += time.perf_counter() - t0
    if len(P) == 0:
        raise ForwardKinematicsError(
            f"forward kinematics: no assembly found for lengths ({', '.join(f'{v * 1e3:.3f}' for v in L)}) mm "
            f"from {starts} starts — the legs probably cannot be assembled on platform {platform.name!r}"
        )
    t0 = time.perf_counter()
    certified = np.zeros(len(P), bool)
    if polish is not None:
        prog = ProgramFK(platform, "quaternion", polish)
        for k in range(len(P)):
            sol = prog.solve(L, P[k], convention, initial_rotation=RR[k])
            same = np.max(np.abs(np.concatenate([(sol.position - P[k]) / size, (sol.rotation - RR[k]).ravel()]))) < 1e-6
            certified[k] = sol.success and sol.residual <= CERTIFY_RESIDUAL and same
            if certified[k]:
                P[k], RR[k] = sol.position, sol.rotation
        # Final Newton polish from the program's point (quadratic convergence: one or two steps).
        P, RR, _, _, _ = newton_core(platform, P, RR, np.broadcast_to(L, (len(P), 6)), 1e-15, 3, 0.25 * size, 0.5)
    t_polish = time.perf_counter() - t0
    modes = modes_from_solutions(platform, P, RR, L, certified, convention)
    return AssemblyModes(
        modes, L, n_max, starts, rounds, time.perf_counter() - t_start, {"newton": t_newton, "polish": t_polish}
    )


def modes_from_solutions(platform, P, RR, L, certified, convention) -> list[AssemblyMode]:
    """``AssemblyMode``s (sorted nearest home first) for solutions p_BC ``(k, 3)``, R_BT ``(k, 3, 3)`` of
    lengths ``L (6,)``; ``certified`` ``(k,)`` says which the MathematicalProgram confirmed."""
    Lp, Jinv = legs_and_jacobian(platform, P, RR)
    res = np.abs(Lp - L).max(axis=-1)
    an = _analyse_jinv(Jinv, anchor_scale(platform))
    poses = np.concatenate([P, angles_from_matrix(RR, convention)], axis=-1)
    above = np.all(plate_anchors(platform, poses, convention)[..., 2] > 0, axis=-1)
    within = bool(check_stroke(platform, L).within)
    home = platform.home_pose()
    R_home = rotation_matrix(home[3:], "utn")
    cos_angle = np.clip((np.einsum("nij,ij->n", RR, R_home) - 1) / 2, -1, 1)
    dist = np.linalg.norm(P - home[:3], axis=-1) / anchor_scale(platform) + np.arccos(cos_angle)
    modes = [
        AssemblyMode(
            pose=poses[k],
            position=P[k],
            rotation=RR[k],
            residual=float(res[k]),
            det_sign=int(an.det_sign[k]),
            condition=float(an.condition[k]),
            sigma_min=float(an.sigma_min[k]),
            above_base=bool(above[k]),
            within_stroke=within,
            certified=bool(certified[k]),
            distance_to_home=float(dist[k]),
        )
        for k in range(len(P))
    ]
    return sorted(modes, key=lambda m: m.distance_to_home)
