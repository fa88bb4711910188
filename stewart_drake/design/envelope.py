"""Actuator sizing over a duty envelope: a set of poses with bounds on the Cartesian velocity and
acceleration, instead of a trajectory.

Envelope (SI inside): poses ``(n, 6)`` (a list or a grid over a box), and symmetric per-axis bounds
|V_j| <= v_max_j on V = [v_C; ω] (velocity of the rotation centre, angular velocity, both in the base
frame) and |Ȧ_j| <= a_max_j on [a_C; ω̇]. Velocity and acceleration are independent.

Worst case, per pose and leg. The inverse dynamics is affine in the acceleration and quadratic in the
velocity: F_i = c_i(q) + G_i(q)·[a_C; ω̇] + Vᵀ Q_i(q) V. Hence, exactly,

    max F_i = c_i + Σ_j |G_ij| a_max_j + max_{|V|<=v_max} Vᵀ Q_i V,

the last term by enumeration of the velocity box's faces (``boxquad``); min F_i likewise. For the
plate alone Q depends on ω only (d = 3); with the legs' masses on all of V (d = 6). Peak |F_i| =
max(max F_i, −min F_i) is attained by a vertex of the acceleration box and the velocity returned.
Leg speed L̇_i = J⁻¹_i V gives max |L̇_i| = Σ_j |J⁻¹_ij| v_max_j exactly. Leg acceleration
L̈_i = J⁻¹_i [a_C; ω̇] + ωᵀ S_i ω + |P_i (v_C + ω × r_i)|² / L_i (S_i the centripetal term, P_i = I − u_i u_iᵀ):
each part is maximised separately (the last, convex, at a vertex), a rigorous upper bound. Power
|F_i L̇_i| <= peak |F_i| · peak |L̇_i|, an upper bound.

Per-axis allowed acceleration: for each axis j alone (others zero) and the worst velocity inside the
envelope, the largest |Ȧ_j| for which every leg stays within ±max_force (0 when even Ȧ = 0 exceeds it).
"""

from dataclasses import dataclass, field

import numpy as np

from stewart_drake.core.argcheck import as_poses
from stewart_drake.core.dynamics import (
    G_EARTH,
    euler_rate_derivative,
    generalized_force,
    leg_forces,
    leg_forces_from_jacobians,
    leg_forces_with_legs,
    skew,
)
from stewart_drake.core.geometry import Platform, load_yaml_config
from stewart_drake.core.kinematics import (
    check_stroke,
    condition_number,
    leg_lengths,
    length_jacobian,
)
from stewart_drake.core.rotations import (
    angle_scale,
    angular_velocity_map,
    check_convention,
    length_scale,
    rotation_matrix,
)
from stewart_drake.core.sanity import check_poses
from stewart_drake.design.boxquad import box_quadratic_max
from stewart_drake.errors import EnvelopeError, StewartError

MAX_POSES = 10_000_000  # envelope poses held in memory at once (work is chunked; results are (n, 6) arrays)
MAX_CONDITION = 1e8  # as dynamics.MAX_CONDITION: leg forces are meaningless beyond it
CHUNK = 4096


# ----------------------------------------------------------------------------------------------
# YAML schema (edge units).


@dataclass
class BoxConfig:
    """A grid of poses: ``steps[j]`` values from ``min[j]`` to ``max[j]`` per coordinate (1: min only)."""

    min: list[float] = field(default_factory=list)
    max: list[float] = field(default_factory=list)
    steps: list[int] = field(default_factory=list)


@dataclass
class BoundsConfig:
    """Symmetric per-axis bounds in the base frame: ``linear`` (x, y, z; length unit per s or s²) and
    ``angular`` (about x, y, z; angle unit per s or s²)."""

    linear: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    angular: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])


@dataclass
class EnvelopeConfig:
    """A duty envelope as written in YAML: ``poses`` (list) or ``box`` (grid), plus ``velocity`` and
    ``acceleration`` bounds."""

    name: str = ""
    length_unit: str = "m"
    angle_unit: str = "rad"
    convention: str = "utn"
    poses: list[list[float]] = field(default_factory=list)
    box: BoxConfig | None = None
    velocity: BoundsConfig = field(default_factory=BoundsConfig)
    acceleration: BoundsConfig = field(default_factory=BoundsConfig)


@dataclass(frozen=True)
class Envelope:
    """An envelope in SI: ``poses`` (n, 6) m/rad, ``v_max`` (6,) [m/s; rad/s], ``a_max`` (6,)
    [m/s²; rad/s²], the Euler ``convention`` of the poses, ``source`` (file name) and ``units`` (the
    file's length and angle units), for messages."""

    poses: np.ndarray
    v_max: np.ndarray
    a_max: np.ndarray
    convention: str = "utn"
    source: str = "envelope"
    units: tuple = ("m", "rad")

    def shown(self, k: int) -> str:
        """Pose k (0-based) as the file wrote it: ``pose k+1 [..] (mm, deg)``."""
        scale = np.r_[np.full(3, length_scale(self.units[0])), np.full(3, angle_scale(self.units[1]))]
        return f"pose {k + 1} {np.round(self.poses[k] / scale, 6).tolist()} ({self.units[0]}, {self.units[1]})"


def _numbers(values, n, where, integer=False):
    try:
        arr = np.array(values, dtype=float)
    except (TypeError, ValueError):
        raise EnvelopeError(EnvelopeError.NOT_NUMBERS.format(where=where, value=values)) from None
    if arr.shape != (n,):
        raise EnvelopeError(EnvelopeError.COUNT.format(where=where, n=n, value=values))
    if not np.all(np.isfinite(arr)):
        raise EnvelopeError(EnvelopeError.NOT_FINITE.format(where=where, value=values))
    if integer and np.any(arr != np.round(arr)):
        raise EnvelopeError(EnvelopeError.NOT_INTEGERS.format(where=where, value=values))
    return arr


def envelope_from_config(cfg: EnvelopeConfig, source: str = "envelope") -> Envelope:
    """Validate and convert to SI. Errors name the file and the field (``EnvelopeError``); poses are
    counted from 1 in messages."""
    try:
        kl, ka = length_scale(cfg.length_unit), angle_scale(cfg.angle_unit)
        check_convention(cfg.convention)
    except ValueError as e:
        raise EnvelopeError(EnvelopeError.IN_FILE.format(source=source, problem=e)) from None
    scale = np.r_[np.full(3, kl), np.full(3, ka)]
    if bool(cfg.poses) == (cfg.box is not None):
        raise EnvelopeError(EnvelopeError.ONE_OF.format(source=source))
    if cfg.box is not None:
        lo = _numbers(cfg.box.min, 6, f"{source}: box.min")
        hi = _numbers(cfg.box.max, 6, f"{source}: box.max")
        steps = _numbers(cfg.box.steps, 6, f"{source}: box.steps", integer=True).astype(int)
        if np.any(steps < 1):
            raise EnvelopeError(EnvelopeError.STEPS.format(source=source, value=cfg.box.steps))
        if np.any(hi < lo):
            j = int(np.argmax(hi < lo))
            raise EnvelopeError(
                EnvelopeError.BOX_ORDER.format(source=source, j=j, hi=cfg.box.max[j], lo=cfg.box.min[j])
            )
        n = int(np.prod(steps.astype(float)))
        if n > MAX_POSES:
            raise EnvelopeError(
                EnvelopeError.BOX_TOO_LARGE.format(source=source, steps=cfg.box.steps, n=n, limit=MAX_POSES)
            )
        axes = [np.linspace(lo[j], hi[j], steps[j]) if steps[j] > 1 else lo[j : j + 1] for j in range(6)]
        poses = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 6)
    else:
        if len(cfg.poses) > MAX_POSES:
            raise EnvelopeError(EnvelopeError.TOO_MANY_POSES.format(source=source, n=len(cfg.poses), limit=MAX_POSES))
        poses = np.array([_numbers(p, 6, f"{source}: poses (pose {k + 1})") for k, p in enumerate(cfg.poses)])
    bounds = {}
    for name, b in (("velocity", cfg.velocity), ("acceleration", cfg.acceleration)):
        lin = _numbers(b.linear, 3, f"{source}: {name}.linear")
        ang = _numbers(b.angular, 3, f"{source}: {name}.angular")
        for part, arr in (("linear", lin), ("angular", ang)):
            if np.any(arr < 0):
                raise EnvelopeError(
                    EnvelopeError.NEGATIVE_BOUND.format(source=source, name=name, part=part, value=arr.tolist())
                )
        bounds[name] = np.r_[lin * kl, ang * ka]
    return Envelope(
        poses * scale,
        bounds["velocity"],
        bounds["acceleration"],
        cfg.convention,
        source,
        (cfg.length_unit, cfg.angle_unit),
    )


def load_envelope(path) -> Envelope:
    """An ``Envelope`` from a YAML file (schema ``EnvelopeConfig``)."""
    try:
        cfg = load_yaml_config(path, EnvelopeConfig, "envelope")
    except StewartError as e:
        raise EnvelopeError(str(e)) from None
    return envelope_from_config(cfg, str(path))


def check_in_workspace(platform: Platform, env: Envelope, stroke: bool = True, conditions: bool = False):
    """``(n, 6)`` leg lengths of the envelope's poses; ``EnvelopeError`` naming the first pose outside the
    stroke (unless ``stroke`` is False: the caller reports it as a result outside limits), on (or near) a
    singularity or at the convention's gimbal lock. With ``conditions`` also the ``(n,)`` scaled condition
    numbers it checked (``core.kinematics.condition_number``): ``(lengths, conditions)``."""
    try:
        check_poses(platform, env.poses, env.convention, what=f"{env.source}: pose")  # finite, near, above the base
    except StewartError as e:
        raise EnvelopeError(str(e)) from None
    L = leg_lengths(platform, env.poses, env.convention)
    v = check_stroke(platform, L).violations() if stroke else None
    if v:
        v = v[0]
        k = v["pose"][0]
        raise EnvelopeError(
            EnvelopeError.OUT_OF_STROKE.format(
                source=env.source,
                pose=env.shown(k),
                leg=v["leg"],
                length_mm=v["length_m"] * 1e3,
                excess_mm=v["excess_m"] * 1e3,
                side="below" if v["side"] == "min" else "above",
            )
        )
    cond = np.empty(len(env.poses))
    for s in range(0, len(env.poses), 1 << 16):
        k = condition_number(platform, env.poses[s : s + (1 << 16)], env.convention)
        bad = ~(k <= MAX_CONDITION)
        if bad.any():
            j = s + int(np.argmax(bad))
            raise EnvelopeError(EnvelopeError.SINGULAR.format(source=env.source, pose=env.shown(j), cond=k[j - s]))
        cond[s : s + len(k)] = k
    return (L, cond) if conditions else L


# ----------------------------------------------------------------------------------------------
# Force terms: F = c + G [a_C; ω̇] + Vᵀ Q V.


def _plate_geometry(platform: Platform, q, convention):
    R = rotation_matrix(q[..., 3:], convention)
    r = np.einsum("...ij,kj->...ki", R, platform.top_anchors_per_leg - platform.rotation_centre)  # (..., 6, 3)
    l = q[..., None, :3] + r - platform.base_anchors
    L = np.linalg.norm(l, axis=-1)
    u = l / L[..., None]
    Jinv = np.concatenate([u, np.cross(r, u)], -1)  # (..., 6, 6): L̇ = J⁻¹ V
    return R, r, u, L, Jinv


def spatial_inertia_about_C(platform: Platform, R) -> np.ndarray:
    """``(..., 6, 6)`` M_C: [f; m_C] = M_C [a_C; ω̇] for the plate at rest, base-frame coordinates
    (M_C = [[m 1, −m [r]×], [m [r]×, I_C]], r = p_C→cm, I_C the inertia about C)."""
    m = platform.mass
    r = np.einsum("...ij,j->...i", R, platform.com - platform.rotation_centre)
    S = skew(r)
    I_W = R @ platform.inertia @ np.swapaxes(R, -1, -2)
    M = np.zeros(r.shape[:-1] + (6, 6))
    M[..., :3, :3] = m * np.eye(3)
    M[..., :3, 3:] = -m * S
    M[..., 3:, :3] = m * S
    M[..., 3:, 3:] = I_W - m * S @ S
    return M


def _plate_terms(platform: Platform, q, convention, gravity):
    """c (..., 6), G (..., 6, 6) [leg, axis], Q (..., 6, 3, 3) over ω, and the geometry."""
    R, r_legs, u, L, Jinv = _plate_geometry(platform, q, convention)
    rhs = plate_wrench_terms(platform, R, gravity)
    X = np.linalg.solve(np.swapaxes(Jinv, -1, -2), rhs)  # J⁻ᵀ [w_g, M_C, H]
    c, G, Q = X[..., 0], X[..., 1:7], X[..., 7:].reshape(X.shape[:-1] + (3, 3))
    return c, G, Q, (R, r_legs, u, L, Jinv)


def plate_wrench_terms(platform: Platform, R, gravity: float = G_EARTH) -> np.ndarray:
    """``(..., 6, 16)`` the plate's wrench terms about C at orientations R (..., 3, 3), base frame: column 0 the
    weight's [f; m] to hold, columns 1..6 the spatial inertia M_C, columns 7..15 the velocity wrench's
    quadratic form in ω (3 × 3, flattened). Leg forces are F = J⁻ᵀ times them (``_plate_terms``); they depend
    on the plate's mass properties and orientation only, not on the anchors."""
    m = platform.mass
    r = np.einsum("...ij,j->...i", R, platform.com - platform.rotation_centre)
    I_W = R @ platform.inertia @ np.swapaxes(R, -1, -2)
    g = np.array([0.0, 0.0, m * gravity])
    w_g = np.concatenate([np.broadcast_to(g, r.shape), np.cross(r, g)], -1)

    def h(w):  # velocity wrench [m ω×(ω×r); ω×I ω + r × m ω×(ω×r)]
        w = np.broadcast_to(w, r.shape)
        f = m * np.cross(w, np.cross(w, r))
        return np.concatenate([f, np.cross(w, np.einsum("...ij,...j->...i", I_W, w)) + np.cross(r, f)], -1)

    E = np.eye(3)
    Hw = np.empty(r.shape[:-1] + (6, 3, 3))
    diag = [h(E[j]) for j in range(3)]
    for j in range(3):
        Hw[..., j, j] = diag[j]
        for k in range(j + 1, 3):
            Hw[..., j, k] = Hw[..., k, j] = 0.5 * (h(E[j] + E[k]) - diag[j] - diag[k])
    return np.concatenate([w_g[..., None], spatial_inertia_about_C(platform, R), Hw.reshape(r.shape[:-1] + (6, 9))], -1)


def cartesian_to_euler(q, V, Vd, convention):
    """q̇, q̈ (..., 6) for Cartesian [v_C; ω], [a_C; ω̇] at poses q."""
    E = angular_velocity_map(q[..., 3:], convention)
    rates = np.linalg.solve(E, V[..., 3:, None])[..., 0]
    acc = np.linalg.solve(E, (Vd[..., 3:] - euler_rate_derivative(q[..., 3:], rates, convention))[..., None])[..., 0]
    return np.concatenate([V[..., :3], rates], -1), np.concatenate([Vd[..., :3], acc], -1)


def cartesian_leg_forces(
    platform: Platform, q, V, Vd, convention: str = "utn", legs: bool = False, gravity: float = G_EARTH
) -> np.ndarray:
    """``(..., 6)`` leg forces (N) at poses q for Cartesian velocity V = [v_C; ω] and acceleration
    [a_C; ω̇] (base frame), by the toolkit's inverse dynamics in Euler coordinates."""
    q, V, Vd = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (q, V, Vd)))
    qd, qdd = cartesian_to_euler(q, V, Vd, convention)
    fn = leg_forces_with_legs if legs else leg_forces
    return fn(platform, q, qd, qdd, convention, gravity=gravity)


def cartesian_leg_forces_at(
    platform: Platform, poses, k, V, Vd, convention: str = "utn", gravity: float = G_EARTH
) -> np.ndarray:
    """``(n, 6)`` leg forces (N) of the plate alone at poses ``poses[k]`` for n samples that share a few
    distinct ``poses`` (m, 6) (``k`` (n,) indices into them): ``cartesian_leg_forces(platform, poses[k], V, Vd)``
    bit for bit, its pose-only work (E_W, J = ∂L/∂q and J's condition check) done once per distinct pose and
    gathered (each step works matrix by matrix, so a gathered row is the row computed in place). For a random
    check of an envelope's poses, where that work was most of the cost."""
    check_convention(convention)
    poses = as_poses(poses)
    k = np.asarray(k)
    q = poses[k]
    V, Vd = (as_poses(a, name, f"{name} sample") for a, name in ((V, "V"), (Vd, "Vd")))
    E = angular_velocity_map(poses[:, 3:], convention)[k]
    rates = np.linalg.solve(E, V[..., 3:, None])[..., 0]
    acc = np.linalg.solve(E, (Vd[..., 3:] - euler_rate_derivative(q[..., 3:], rates, convention, E))[..., None])[..., 0]
    qd, qdd = np.concatenate([V[..., :3], rates], -1), np.concatenate([Vd[..., :3], acc], -1)
    Q = generalized_force(platform, q, qd, qdd, convention, True, gravity)
    return leg_forces_from_jacobians(platform, length_jacobian(platform, poses, convention), Q, rows=k)


def _generic_terms(platform: Platform, q, convention, gravity):
    """c, G, Q (..., 6, 6, 6) over the full V, by polarisation of ``cartesian_leg_forces`` with legs."""
    z = np.zeros(q.shape)
    E = np.eye(6)

    def F(V, Vd):
        return cartesian_leg_forces(
            platform, q, np.broadcast_to(V, q.shape), np.broadcast_to(Vd, q.shape), convention, True, gravity
        )

    c = F(z, z)
    G = np.stack([F(z, E[j]) - c for j in range(6)], -1)
    diag = [F(E[j], z) - c for j in range(6)]
    Q = np.empty(q.shape[:-1] + (6, 6, 6))
    for j in range(6):
        Q[..., j, j] = diag[j]
        for k in range(j + 1, 6):
            Q[..., j, k] = Q[..., k, j] = 0.5 * (F(E[j] + E[k], z) - c - diag[j] - diag[k])
    return c, G, Q, _plate_geometry(platform, q, convention)


# ----------------------------------------------------------------------------------------------
# Worst case.


@dataclass(frozen=True)
class EnvelopeSizing:
    """Per pose and leg ``(n, 6)``: ``force_max``/``force_min`` (N, exact extremes), ``peak_force``,
    ``peak_speed`` (m/s, exact), ``peak_accel`` (m/s², upper bound), ``peak_power`` (W, upper bound),
    ``length`` (m); ``allowed_accel`` (n, 6) per Cartesian axis [m/s²; rad/s²]; ``worst``: per leg the
    pose index, acceleration (6,) and velocity (6,) that attain its peak |F| and the signed force."""

    envelope: Envelope
    force_max: np.ndarray
    force_min: np.ndarray
    peak_force: np.ndarray
    peak_speed: np.ndarray
    peak_accel: np.ndarray
    peak_power: np.ndarray
    length: np.ndarray
    allowed_accel: np.ndarray
    worst: list


def _allowed(c, G, qmax, qmin, fmax):
    """(..., 6 axes) largest symmetric |Ȧ_j| with −fmax <= c + G_j Ȧ_j + q <= fmax for every leg."""
    out = np.full(c.shape[:-1] + (6,), np.inf)
    up, lo = (fmax - c - qmax)[..., None], (c + qmin + fmax)[..., None]  # slack above / below, per leg
    with np.errstate(divide="ignore", invalid="ignore"):
        for sgn in (1.0, -1.0):
            g = sgn * G
            lim = np.where(g > 0, up / g, np.where(g < 0, lo / -g, np.inf))
            out = np.minimum(out, lim.min(axis=-2))
    infeasible = np.any((up < 0) | (lo < 0), axis=-2)  # already outside at zero acceleration
    return np.where(infeasible, 0.0, np.maximum(out, 0.0))


def envelope_sizing(
    platform: Platform,
    env: Envelope,
    legs: bool = False,
    gravity: float = G_EARTH,
    chunk: int = CHUNK,
    stroke: bool = True,
) -> EnvelopeSizing:
    """Worst case over the envelope (see the module docstring). Raises ``EnvelopeError`` if a pose leaves
    the workspace (with ``stroke`` False a pose outside the stroke is sized; its lengths are in the result).
    Work is chunked over poses."""
    L_all = check_in_workspace(platform, env, stroke)
    n = len(env.poses)
    out = {
        k: np.empty((n, 6))
        for k in ("force_max", "force_min", "peak_force", "peak_speed", "peak_accel", "allowed_accel")
    }
    worst = [{"peak": -1.0} for _ in range(6)]
    vel_axes = np.flatnonzero(env.v_max > 0) if legs else 3 + np.flatnonzero(env.v_max[3:] > 0)
    b = env.v_max[vel_axes]
    for s in range(0, n, chunk):
        q = env.poses[s : s + chunk]
        c, G, Q, (R, r, u, L, Jinv) = (_generic_terms if legs else _plate_terms)(platform, q, env.convention, gravity)
        if not legs:
            Qv = Q[..., vel_axes - 3, :][..., :, vel_axes - 3]
        else:
            Qv = Q[..., vel_axes, :][..., :, vel_axes]
        qmax, xmax = box_quadratic_max(Qv, b)
        qmin_neg, xmin = box_quadratic_max(-Qv, b)
        lin = np.abs(G) @ env.a_max
        fmax, fmin = c + lin + qmax, c - lin - qmin_neg
        out["force_max"][s : s + chunk] = fmax
        out["force_min"][s : s + chunk] = fmin
        peak = np.maximum(fmax, -fmin)
        out["peak_force"][s : s + chunk] = peak
        out["peak_speed"][s : s + chunk] = np.abs(Jinv) @ env.v_max
        # Leg acceleration bound: linear + centripetal (ω-quadratic, exact max) + convex transverse term.
        S = 0.5 * (r[..., :, None] * u[..., None, :] + u[..., :, None] * r[..., None, :]) - np.sum(r * u, -1)[
            ..., None, None
        ] * np.eye(3)
        wb = env.v_max[3:]
        cmax, _ = box_quadratic_max(S, wb)
        cmin_neg, _ = box_quadratic_max(-S, wb)
        P = np.eye(3) - u[..., :, None] * u[..., None, :]
        B = np.concatenate([P, -P @ skew(r)], -1) / np.sqrt(L)[..., None, None]  # (..., 6, 3, 6)
        signs = np.array(np.meshgrid(*[[-1.0, 1.0]] * 6, indexing="ij")).reshape(6, -1).T[:32]  # ±V give the same value
        conv = np.max(np.sum((B @ (signs * env.v_max).T) ** 2, -2), -1)
        alin = np.abs(Jinv) @ env.a_max
        out["peak_accel"][s : s + chunk] = np.maximum(alin + cmax + conv, alin + cmin_neg)
        out["allowed_accel"][s : s + chunk] = _allowed(c, G, qmax, -qmin_neg, platform.legs.max_force)
        for i in range(6):
            k = int(np.argmax(peak[:, i]))
            if peak[k, i] > worst[i]["peak"]:
                upper = fmax[k, i] >= -fmin[k, i]
                sign = 1.0 if upper else -1.0
                acc = sign * np.sign(G[k, i]) * env.a_max
                V = np.zeros(6)
                V[vel_axes] = (xmax if upper else xmin)[k, i]
                worst[i] = {
                    "peak": float(peak[k, i]),
                    "force": float(fmax[k, i] if upper else fmin[k, i]),
                    "index": s + k,
                    "pose": env.poses[s + k],
                    "accel": acc,
                    "velocity": V,
                }
    power = out["peak_force"] * out["peak_speed"]
    return EnvelopeSizing(
        env,
        out["force_max"],
        out["force_min"],
        out["peak_force"],
        out["peak_speed"],
        out["peak_accel"],
        power,
        L_all,
        out["allowed_accel"],
        worst,
    )


def envelope_peaks(platform: Platform, env: Envelope, gravity: float = G_EARTH, stroke: bool = True) -> tuple:
    """``(peak_force, peak_speed, condition)``, (n, 6) N and m/s and (n,): the plate-only ``envelope_sizing``'s two
    exact peaks, the same arithmetic on the same chunks (bit for bit), without its acceleration bounds and
    worst-case bookkeeping (a third of its cost), and the scaled condition numbers its workspace check computed
    (``condition_number``), for callers that need only these (``synthesis.performance.sampled_performance``)."""
    _, cond = check_in_workspace(platform, env, stroke, conditions=True)
    n = len(env.poses)
    force, speed = np.empty((n, 6)), np.empty((n, 6))
    vel_axes = 3 + np.flatnonzero(env.v_max[3:] > 0)
    b = env.v_max[vel_axes]
    for s in range(0, n, CHUNK):
        c, G, Q, (_, _, _, _, Jinv) = _plate_terms(platform, env.poses[s : s + CHUNK], env.convention, gravity)
        Qv = Q[..., vel_axes - 3, :][..., :, vel_axes - 3]
        qmax, _ = box_quadratic_max(Qv, b)
        qmin_neg, _ = box_quadratic_max(-Qv, b)
        lin = np.abs(G) @ env.a_max
        force[s : s + CHUNK] = np.maximum(c + lin + qmax, -(c - lin - qmin_neg))
        speed[s : s + CHUNK] = np.abs(Jinv) @ env.v_max
    return force, speed, cond
