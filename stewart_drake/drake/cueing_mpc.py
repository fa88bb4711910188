"""Model-predictive motion cueing: platform poses from a vehicle ``Drive`` by one quadratic program per sample.

Plain (not frequency-splitting) MPC. The prediction model is linear and about the home pose:

- the platform's pose offset p (6,) from home (m, rad, ``utn`` angles) is a double integrator per degree of
  freedom with the pose accelerations a (6,) as inputs, held over each prediction step;
- the rider's head is at the rotation centre, so the platform's specific-force deviation from rest is
  f_p = a_xyz + g (−pitch, roll, 0) (tilt coordination, small angles) and its angular velocity ω_p = ṗ_rpy;
- the vestibular models (``control.cueing.vestibular``: otolith on each specific-force axis, semicircular canal on
  each angular-velocity axis) run on the error between the vehicle's and the platform's motion, so the cost holds
  the *perceived* error: linear models, perceived(vehicle) − perceived(platform) = model(vehicle − platform).

The continuous system (p, v, vestibular error states; inputs a and the vehicle's motion r) is discretised
exactly (zero-order hold) at the prediction step, and the horizon is condensed: the decision variables are the
``horizon`` × 6 pose accelerations. The cost's Hessian is then constant and only its linear term changes with
the state and the vehicle's motion; the hard constraints are the leg lengths (stroke less a margin), leg speeds
and leg accelerations, each linearised along the horizon about the previous solution's poses with the exact
Jacobian ∂L/∂q of ``core.kinematics`` (leg acceleration without its J̇ q̇ term). One ``MathematicalProgram`` serves
the whole run: each sample updates the cost's and the constraint's coefficients and solves again (OSQP, warm
started from the previous sample's solution).

The first input is applied for one drive sample; the new pose is then re-checked with the exact inverse kinematics
(stroke, leg speed; joint cones where ``limits`` give them). If the check fails (linearisation error) or the
program has no solution (a horizon linearised about a far-off plan can be infeasible), the program is solved again
with the margins tightened (``FALLBACK_TIGHTENING``) and only the first step's limits kept; if that fails too, the
step is scaled toward the previous pose (halving, down to holding it still), which is inside by induction from the
home pose. The poses are therefore never outside the workspace.

A real-time simulator does not know the vehicle's future: without ``preview`` the program predicts the present
motion decaying to rest (``decay``; or held); with it a recorded drive's future is seen.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from pydrake.solvers import ClarabelSolver, MathematicalProgram, OsqpSolver, SolverOptions
from scipy.linalg import expm

from stewart_drake.control.cueing.drive import GRAVITY, Drive
from stewart_drake.control.cueing.guard import DEFAULT_MAX_ACCEL, DEFAULT_MAX_SPEED
from stewart_drake.control.cueing.vestibular import RATE_THRESHOLD, canal_ss, otolith_ss
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import (
    check_stroke,
    inverse_jacobian_of_legs,
    leg_lengths,
    leg_vectors,
    length_jacobian_of,
    plate_offsets,
)
from stewart_drake.core.rotations import angular_velocity_map, rotation_matrix
from stewart_drake.errors import CueingError
from stewart_drake.workspace.limits import Limits, raw_margins

SOLVERS = {"osqp": OsqpSolver, "clarabel": ClarabelSolver}
FALLBACK_TIGHTENING = 4.0  # the re-solve's stroke (and cone) margin is this many times the program's, rates ÷ 1.25
TILT_RATE = 0.9 * float(RATE_THRESHOLD[0])  # rad/s: 2.7 °/s, below the threshold by more than OSQP's 1e-3 tolerance
MAX_HORIZON = 200  # prediction steps: the condensed program is dense in 6 × horizon inputs
CONE_MARGIN = 0.01  # rad kept from a joint cone in the program
HALVINGS = 6  # scaled steps tried (1/2 .. 1/64) before the pose is held


@dataclass(frozen=True)
class MpcParams:
    """The MPC's horizon, weights, limits and solver (SI units).

    Attributes:
        horizon: prediction steps (default 10).
        step: prediction step, s (default 0.15: a 1.5 s horizon).
        w_force: weight on the perceived specific-force error, per m/s².
        w_rate: weight on the perceived angular-velocity error, per rad/s.
        w_position: washout weight on the translation offset from home, per m.
        w_angle: washout weight on the angles from home, per rad.
        w_velocity: weight on the pose rates, per m/s (rad/s).
        w_acceleration: weight on the pose accelerations (inputs), per m/s² (rad/s²).
        stroke_margin: leg-length margin kept from each stroke end in the program, m.
        max_leg_speed: leg speed limit, m/s; ``None``: the platform's ``legs.max_speed``, else the guard's
            ``DEFAULT_MAX_SPEED``.
        max_leg_acceleration: leg acceleration limit, m/s² (default the guard's ``DEFAULT_MAX_ACCEL``, 1 g).
        max_tilt_rate: limit on the roll and pitch rates, rad/s (default ``TILT_RATE``, 0.9 × the 3 °/s roll-rate
            perception threshold of ``vestibular.RATE_THRESHOLD``: tilt coordination below what the canals notice);
            ``None``: none (the canal model in the cost alone shapes the tilt).
        preview: the program sees the drive's future (recorded drives) instead of predicting it.
        decay: without ``preview``, the vehicle's present motion is predicted to decay to rest with this time
            constant, s (default 0.5 s; ``None``: held over the horizon, which plans for a cue that lasts).
        solver: ``"osqp"`` or ``"clarabel"`` (both ship with Drake).
    """

    horizon: int = 10
    step: float = 0.15
    w_force: float = 1.0
    w_rate: float = 3.0
    w_position: float = 1.5
    w_angle: float = 0.3
    w_velocity: float = 0.5
    w_acceleration: float = 0.05
    stroke_margin: float = 0.005
    max_leg_speed: float | None = None
    max_leg_acceleration: float = DEFAULT_MAX_ACCEL
    max_tilt_rate: float | None = TILT_RATE
    preview: bool = False
    decay: float | None = 0.5
    solver: str = "osqp"
    solver_options: dict = field(
        default_factory=lambda: {"eps_abs": 1e-3, "eps_rel": 1e-3, "polishing": 0, "max_iter": 500}
    )

    def __post_init__(self):
        def bad(name, rule):
            raise CueingError(CueingError.PARAM.format(name=f"mpc {name}", rule=rule, value=getattr(self, name)))

        if not (isinstance(self.horizon, int) and 1 <= self.horizon <= MAX_HORIZON):
            bad("horizon", f"a whole number of steps in 1..{MAX_HORIZON}")

        def number(v) -> bool:
            return isinstance(v, (int, float)) and not isinstance(v, bool) and np.isfinite(v)

        for name in ("step", "w_force", "w_rate", "max_leg_acceleration"):
            if not (number(getattr(self, name)) and getattr(self, name) > 0):
                bad(name, "a positive number")
        for name in ("w_position", "w_angle", "w_velocity", "w_acceleration", "stroke_margin"):
            if not (number(getattr(self, name)) and getattr(self, name) >= 0):
                bad(name, "a number >= 0")
        for name in ("max_leg_speed", "max_tilt_rate", "decay"):
            v = getattr(self, name)
            if v is not None and not (number(v) and v > 0):
                bad(name, "a positive number or None")
        if not isinstance(self.preview, bool):
            bad("preview", "true or false")
        if self.solver not in SOLVERS:
            bad("solver", "one of " + ", ".join(SOLVERS))


@dataclass(frozen=True)
class MpcRun:
    """One MPC cueing run over a drive of N samples (K = N − 1 solves).

    Attributes:
        t: ``(N,)`` s, the drive's times.
        poses: ``(N, 6)`` commanded poses (m, rad, ``utn``), poses[0] the home pose.
        solve_times: ``(K,)`` s, wall time of each sample's whole step (linearise, update, solve, re-check).
        cpu_times: ``(K,)`` s, the same steps' CPU time on the calling thread (what one free core would take,
            on a machine whose other work stretches the wall time).
        stroke_violation: ``(K,)`` m, per solve the exact IK's largest leg excess past a stroke end of the pose
            it commands (max(L_min − L, L − L_max) over the legs): ≤ 0 on every sample.
        leg_speed: ``(K,)`` m/s, per solve the largest exact leg speed of the pose it commands.
        fallbacks: how many samples took each fallback (``"tightened"``, ``"scaled"``).
    """

    t: np.ndarray
    poses: np.ndarray
    solve_times: np.ndarray
    cpu_times: np.ndarray
    stroke_violation: np.ndarray
    leg_speed: np.ndarray
    fallbacks: dict


def leg_speed_limit(platform: Platform, params: MpcParams) -> float:
    """The leg speed limit the MPC keeps, m/s: ``params.max_leg_speed``, else the platform's, else the guard's
    ``DEFAULT_MAX_SPEED``."""
    if params.max_leg_speed is not None:
        return float(params.max_leg_speed)
    return float(platform.legs.max_speed) if platform.legs.max_speed is not None else DEFAULT_MAX_SPEED


def vestibular_system() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(A, B, C, D)``: the six vestibular channels (otolith on f_x, f_y, f_z; canal on ω_x, ω_y, ω_z) as one
    continuous system from the 6 motion inputs [f (m/s²), ω (rad/s)] to the 6 perceived outputs."""
    blocks = [otolith_ss(i) for i in range(3)] + [canal_ss(i) for i in range(3)]
    n = [np.atleast_2d(b[0]).shape[0] for b in blocks]
    A = np.zeros((sum(n), sum(n)))
    B = np.zeros((sum(n), 6))
    C = np.zeros((6, sum(n)))
    D = np.zeros((6, 6))
    s = 0
    for i, (a, b, c, d) in enumerate(blocks):
        A[s : s + n[i], s : s + n[i]] = a
        B[s : s + n[i], i] = np.ravel(b)
        C[i, s : s + n[i]] = np.ravel(c)
        D[i, i] = np.ravel(d)[0]
        s += n[i]
    return A, B, C, D


def error_model() -> dict:
    """The continuous prediction model, state x = [p (6), v (6), e (vestibular error states)]:
    ẋ = A x + Ba a + Br r, perceived error y = C x + Da a + Dr r, with r = [f − g e_z (3), ω (3)] the
    vehicle's motion. The platform's motion is s = Sx x + Sa a (specific-force deviation, angular velocity)."""
    Av, Bv, Cv, Dv = vestibular_system()
    nv = Av.shape[0]
    Sx = np.zeros((6, 12))
    Sx[0, 4] = -GRAVITY  # f_x = a_x − g·pitch
    Sx[1, 3] = GRAVITY  # f_y = a_y + g·roll
    Sx[3:, 9:12] = np.eye(3)  # ω = rates of roll, pitch, yaw
    Sa = np.zeros((6, 6))
    Sa[:3, :3] = np.eye(3)
    n = 12 + nv
    A = np.zeros((n, n))
    A[:6, 6:12] = np.eye(6)
    A[12:, :12] = -Bv @ Sx
    A[12:, 12:] = Av
    Ba = np.zeros((n, 6))
    Ba[6:12] = np.eye(6)
    Ba[12:] = -Bv @ Sa
    Br = np.zeros((n, 6))
    Br[12:] = Bv
    C = np.zeros((6, n))
    C[:, :12] = -Dv @ Sx
    C[:, 12:] = Cv
    return {"A": A, "Ba": Ba, "Br": Br, "C": C, "Da": -Dv @ Sa, "Dr": Dv, "n": n}


def discretise(model: dict, h: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(Ad, Bad, Brd)``: the model's exact zero-order-hold discretisation at step ``h`` (s)."""
    n = model["n"]
    M = np.zeros((n + 12, n + 12))
    M[:n, :n] = model["A"]
    M[:n, n : n + 6] = model["Ba"]
    M[:n, n + 6 :] = model["Br"]
    E = expm(M * h)
    return E[:n, :n], E[:n, n : n + 6], E[:n, n + 6 :]


@dataclass(frozen=True)
class Condensed:
    """The horizon condensed onto the inputs U = [a_0 .. a_{N−1}] (6N,): the offsets p_k = Px x0 + Pu U and rates
    v_k = Vx x0 + Vu U stacked for k = 1..N (6N rows; the vehicle's motion moves only the vestibular states), and
    the cost ½ Uᵀ H U + (Gx x0 + Gr Rs)ᵀ U with Rs = [r_0 .. r_{N−1}] (6N,)."""

    Px: np.ndarray
    Pu: np.ndarray
    Vx: np.ndarray
    Vu: np.ndarray
    H: np.ndarray
    Gx: np.ndarray
    Gr: np.ndarray


def condense(model: dict, params: MpcParams) -> Condensed:
    """Stack the discretised model over the horizon and form the cost ½ Uᵀ H U + (Gx x0 + Gr Rs)ᵀ U.

    The cost's terms, each squared and weighted: the perceived error y_k (k = 1..N, with a_{k−1} and r_{k−1}
    feeding through), the pose offsets p_k and rates v_k (washout) and the inputs a_k."""
    N = params.horizon
    Ad, Bad, Brd = discretise(model, params.step)
    n = model["n"]
    X_x = np.zeros((N, n, n))
    X_u = np.zeros((N, n, 6 * N))
    X_r = np.zeros((N, n, 6 * N))
    x_x, x_u, x_r = np.eye(n), np.zeros((n, 6 * N)), np.zeros((n, 6 * N))
    for k in range(N):
        x_x = Ad @ x_x
        x_u = Ad @ x_u
        x_u[:, 6 * k : 6 * k + 6] += Bad
        x_r = Ad @ x_r
        x_r[:, 6 * k : 6 * k + 6] += Brd
        X_x[k], X_u[k], X_r[k] = x_x, x_u, x_r
    I_u = np.eye(6 * N).reshape(N, 6, 6 * N)
    Y_x = np.einsum("ij,kjl->kil", model["C"], X_x)
    Y_u = np.einsum("ij,kjl->kil", model["C"], X_u) + np.einsum("ij,kjl->kil", model["Da"], I_u)
    Y_r = np.einsum("ij,kjl->kil", model["C"], X_r) + np.einsum("ij,kjl->kil", model["Dr"], I_u)
    w_y = np.repeat([params.w_force, params.w_rate], 3)
    w_p = np.repeat([params.w_position, params.w_angle], 3)
    w_v = np.full(6, params.w_velocity)
    # rows of the weighted residual z = Zx x0 + Zu U + Zr Rs: perceived error, offsets, rates, inputs
    Zx = np.concatenate([w_y[:, None] * Y_x, w_p[:, None] * X_x[:, :6], w_v[:, None] * X_x[:, 6:12]], axis=1)
    Zu = np.concatenate([w_y[:, None] * Y_u, w_p[:, None] * X_u[:, :6], w_v[:, None] * X_u[:, 6:12]], axis=1)
    Zr = np.concatenate([w_y[:, None] * Y_r, np.zeros((N, 12, 6 * N))], axis=1)
    Zx, Zu, Zr = (z.reshape(-1, z.shape[-1]) for z in (Zx, Zu, Zr))
    H = 2 * (Zu.T @ Zu + params.w_acceleration**2 * np.eye(6 * N))
    return Condensed(
        Px=X_x[:, :6].reshape(6 * N, n),
        Pu=X_u[:, :6].reshape(6 * N, 6 * N),
        Vx=X_x[:, 6:12].reshape(6 * N, n),
        Vu=X_u[:, 6:12].reshape(6 * N, 6 * N),
        H=0.5 * (H + H.T),
        Gx=2 * Zu.T @ Zx,
        Gr=2 * Zu.T @ Zr,
    )


def legs_and_jacobian(platform: Platform, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(L (..., 6) m, J (..., 6, 6))``: the exact leg lengths of ``(..., 6)`` poses and their Jacobian ∂L/∂q
    (``kinematics.length_jacobian``) from one rotation per pose: the hot path of each sample."""
    R = rotation_matrix(q[..., 3:])
    r = plate_offsets(platform, R)
    legs = q[..., None, :3] + r - platform.base_anchors
    J = length_jacobian_of(inverse_jacobian_of_legs(legs, r), angular_velocity_map(q[..., 3:]))
    return np.sqrt(np.einsum("...k,...k->...", legs, legs)), J


def joint_margins(platform: Platform, poses, limits: Limits | None) -> np.ndarray:
    """``(..., k)`` rad: the joint-cone margins (≥ 0 inside) of ``(..., 6)`` poses that ``limits`` bounds (k = 6
    per cone given, 0 without ``limits`` or cones)."""
    q = np.asarray(poses, dtype=float)
    if limits is None or (limits.base_cone is None and limits.top_cone is None):
        return np.zeros(q.shape[:-1] + (0,))
    cones = Limits(
        stroke=False,
        base_cone=limits.base_cone,
        top_cone=limits.top_cone,
        base_axes=limits.base_axes,
        top_axes=limits.top_axes,
    )
    margins = raw_margins(platform, leg_vectors(platform, q), rotation_matrix(q[..., 3:]), cones)
    return np.concatenate(list(margins.values()), axis=-1)


class CueingProgram:
    """The one ``MathematicalProgram`` of a run: inputs U (6N,), a quadratic cost and one linear constraint whose
    coefficients each sample replaces (``UpdateCoefficients``) before solving again."""

    def __init__(self, cond: Condensed, params: MpcParams, platform: Platform, home: np.ndarray, limits):
        self.cond, self.params, self.platform, self.home, self.limits = cond, params, platform, home, limits
        N = params.horizon
        self.prog = MathematicalProgram()
        self.U = self.prog.NewContinuousVariables(6 * N, "a")
        self.cost = self.prog.AddQuadraticCost(cond.H, np.zeros(6 * N), self.U, is_convex=True).evaluator()
        rows = (18 + 2 * (params.max_tilt_rate is not None) + joint_margins(platform, home, limits).size) * N
        z = np.zeros(rows)
        self.constraint = self.prog.AddLinearConstraint(np.zeros((rows, 6 * N)), z, z, self.U).evaluator()
        self.solver = SOLVERS[params.solver]()
        self.options = SolverOptions()
        for k, v in params.solver_options.items():
            self.options.SetOption(self.solver.solver_id(), k, v)
        self.v_max = leg_speed_limit(platform, params)
        self.blocks = np.eye(6 * N).reshape(N, 6, 6 * N)  # a_k picked from U, k = 0..N−1

    def constraints(self, x0: np.ndarray, qbar: np.ndarray, tight: bool) -> tuple[list, tuple]:
        """The rows lo ≤ A U ≤ hi for state ``x0``, linearised about the offsets ``qbar`` (N, 6) (the predicted
        p_1..p_N): ``([(A (N, m, 6N), lo (N, m), hi (N, m)) per step-wise group], leg acceleration (A, lo, hi))``,
        the groups being stroke, leg speed, tilt rate and joint cones. ``tight`` multiplies the stroke margin (and
        the cones' ``CONE_MARGIN``) by ``FALLBACK_TIGHTENING`` and divides the rate limits by 1.25."""
        c, p, N = self.cond, self.params, self.params.horizon
        margin = FALLBACK_TIGHTENING if tight else 1.0
        shrink = 1.25 if tight else 1.0
        q = self.home + qbar
        L, J = legs_and_jacobian(self.platform, q)  # (N, 6), (N, 6, 6)
        Pu = c.Pu.reshape(N, 6, 6 * N)
        Vu = c.Vu.reshape(N, 6, 6 * N)
        p_free = (c.Px @ x0).reshape(N, 6)
        v_free = (c.Vx @ x0).reshape(N, 6)
        off_L = L + np.einsum("kij,kj->ki", J, p_free - qbar)
        off_V = np.einsum("kij,kj->ki", J, v_free)
        v_max = self.v_max / shrink
        groups = [
            (
                np.einsum("kij,kjl->kil", J, Pu),
                self.platform.L_min + p.stroke_margin * margin - off_L,
                self.platform.L_max - p.stroke_margin * margin - off_L,
            ),
            (np.einsum("kij,kjl->kil", J, Vu), -v_max - off_V, v_max - off_V),
        ]
        if p.max_tilt_rate is not None:
            rate = p.max_tilt_rate / shrink
            groups.append((Vu[:, 3:5], -rate - v_free[:, 3:5], rate - v_free[:, 3:5]))
        m0 = joint_margins(self.platform, q, self.limits)  # (N, k)
        if m0.shape[-1]:
            d = 1e-6  # rad or m: a forward difference of the margins, error ~ d × their curvature (~1)
            G = (joint_margins(self.platform, q[:, None, :] + d * np.eye(6), self.limits) - m0[:, None, :]) / d
            G = np.swapaxes(G, 1, 2)  # (N, k, 6): ∂margin/∂q
            low = CONE_MARGIN * margin - m0 - np.einsum("kij,kj->ki", G, p_free - qbar)
            groups.append((np.einsum("kij,kjl->kil", G, Pu), low, np.full_like(m0, np.inf)))
        a_max = np.full(6 * N, p.max_leg_acceleration / shrink)
        return groups, (np.einsum("kij,kjl->kil", J, self.blocks).reshape(6 * N, 6 * N), -a_max, a_max)

    def solve(self, x0: np.ndarray, Rs: np.ndarray, qbar: np.ndarray, guess: np.ndarray, tight: bool):
        """The inputs U (6N,) for state ``x0`` and vehicle motion ``Rs`` (6N,) under ``constraints(x0, qbar,
        tight)`` (warm started from ``guess``), or None if the solver finds none. ``tight`` also drops the rows of
        steps 2..N but the leg accelerations': the fallback for a horizon made infeasible by a linearisation about
        a far-off plan, whose first step (the one applied) keeps every limit."""
        c, N = self.cond, self.params.horizon
        groups, accel = self.constraints(x0, qbar, tight)
        A = np.concatenate([g[0] for g in groups], axis=1)  # (N, m, 6N): step-major rows
        lo = np.concatenate([g[1] for g in groups], axis=1)
        hi = np.concatenate([g[2] for g in groups], axis=1)
        if tight:
            lo[1:], hi[1:] = -np.inf, np.inf
        self.constraint.UpdateCoefficients(
            np.concatenate([accel[0], A.reshape(-1, 6 * N)]),
            np.concatenate([accel[1], lo.ravel()]),
            np.concatenate([accel[2], hi.ravel()]),
        )
        self.cost.UpdateCoefficients(c.H, c.Gx @ x0 + c.Gr @ Rs, 0.0, True)
        result = self.solver.Solve(self.prog, guess, self.options)
        return result.GetSolution(self.U) if result.is_success() else None


def vehicle_motion(drive: Drive) -> np.ndarray:
    """``(N, 6)`` r = [f − g e_z, ω]: the vehicle's specific-force deviation from rest and angular velocity."""
    return np.concatenate([drive.specific_force - [0.0, 0.0, GRAVITY], drive.angular_velocity], axis=1)


def exact_check(
    platform: Platform, q1, v1, L0, dt: float, v_max: float, limits
) -> tuple[bool, float, float, np.ndarray]:
    """Re-check the pose ``q1`` (6,) reached with pose rate ``v1`` from leg lengths ``L0`` (6,) one step ``dt`` (s)
    earlier, with the exact IK: ``(inside, stroke excess m, leg speed m/s, leg lengths (6,))``. The excess is the
    largest max(L_min − L, L − L_max) (≤ 0 inside); the leg speed the larger of the exact |J(q1) v1| and the leg
    lengths' difference over the step; joint cones where ``limits`` give them."""
    L1, J = legs_and_jacobian(platform, q1)
    excess = float(np.max(np.maximum(platform.L_min - L1, L1 - platform.L_max)))
    speed = float(max(np.max(np.abs(J @ v1)), np.max(np.abs(L1 - L0)) / dt))
    joints = joint_margins(platform, q1, limits)
    inside = excess <= 0.0 and speed <= v_max and bool(np.all(joints >= 0.0))
    return inside, excess, speed, L1


def mpc_cue(
    drive: Drive, platform: Platform, params: MpcParams = MpcParams(), home=None, *, limits: Limits | None = None
) -> MpcRun:
    """Cue ``drive`` on ``platform`` by MPC (see the module's docstring): poses (N, 6) about ``home`` (default the
    platform's home pose), each re-checked with the exact IK; ``limits`` adds joint cones to the stroke.

    Raises:
        UnreachablePoseError: ``home`` is outside the stroke.
    """
    home = platform.home_pose() if home is None else np.asarray(home, dtype=float)
    check_stroke(platform, leg_lengths(platform, home)).raise_first()
    t = np.asarray(drive.t, dtype=float)
    dt = float(t[1] - t[0])
    r = vehicle_motion(drive)
    model = error_model()
    cond = condense(model, params)
    Ad, Bad, Brd = discretise(model, dt)
    program = CueingProgram(cond, params, platform, home, limits)
    N, h, n_s = params.horizon, params.step, t.size
    plan_t = h * np.arange(N + 1)  # the plan's times from its solve
    fade = np.ones(N) if params.decay is None else np.exp(-plan_t[:-1] / params.decay)
    x = np.zeros(model["n"])
    qbar = np.zeros((N, 6))
    U = np.zeros(6 * N)
    poses = np.empty((n_s, 6))
    poses[0] = home
    times, cpu, excess, speed = (np.empty(n_s - 1) for _ in range(4))
    fallbacks = {"tightened": 0, "scaled": 0}
    L0 = leg_lengths(platform, home)
    for i in range(n_s - 1):
        start, start_cpu = time.perf_counter(), time.thread_time()
        if params.preview:
            Rs = np.stack([np.interp(t[i] + plan_t[:-1], t, r[:, j]) for j in range(6)], axis=1).ravel()
        else:
            Rs = (fade[:, None] * r[i]).ravel()
        p0, v0 = x[:6], x[6:12]
        found = None
        for tight in (False, True):
            sol = program.solve(x, Rs, qbar, U, tight)
            if sol is None:
                continue
            p1, v1 = p0 + v0 * dt + 0.5 * sol[:6] * dt * dt, v0 + sol[:6] * dt
            check = exact_check(platform, home + p1, v1, L0, dt, program.v_max, limits)
            found = (sol, p1, v1, check)
            if check[0]:
                fallbacks["tightened"] += tight
                break
        if found is None or not found[3][0]:
            fallbacks["scaled"] += 1
            sol, p1, v1 = (U, p0, np.zeros(6)) if found is None else found[:3]
            for s in [0.5**k for k in range(1, HALVINGS + 1)] + [0.0]:
                check = exact_check(platform, home + p0 + s * (p1 - p0), s * v1, L0, dt, program.v_max, limits)
                if check[0]:
                    break
            found = (sol, p0 + s * (p1 - p0), s * v1, check)
        sol, p1, v1, (_, excess[i], speed[i], L0) = found
        plan = np.concatenate([p0[None], (cond.Px @ x + cond.Pu @ sol).reshape(N, 6)])
        qbar = np.stack([np.interp(plan_t[1:] + dt, plan_t, plan[:, j]) for j in range(6)], axis=1)
        x = Ad @ x + Bad @ ((v1 - v0) / dt) + Brd @ r[i]
        x[:6], x[6:12] = p1, v1
        poses[i + 1] = home + p1
        U = sol
        times[i], cpu[i] = time.perf_counter() - start, time.thread_time() - start_cpu
    return MpcRun(
        t=t,
        poses=poses,
        solve_times=times,
        cpu_times=cpu,
        stroke_violation=excess,
        leg_speed=speed,
        fallbacks=fallbacks,
    )
