"""The calibration model: the parameters of a built platform and the residuals of each measurement kind.

Geometric parameters θ (metres), in this order (``Layout.names``):

- each physical base joint p_BBj (3 each: legs that share a joint on a 6-3 platform keep sharing it);
- each plate joint p_TTj (3 each: the three shared joints of a 3-6 platform stay three);
- each leg sensor's zero offset o_i (6): joint-to-joint length L_i = g_i × reading_i + o_i;
- optionally (``gains``) each sensor's gain g_i, as (g_i − 1) × L_ref (6, metres: the length error the gain
  makes at the mid-stroke reading L_ref, so that θ holds lengths only);
- for ``points`` data, each target's plate-frame position p_TSk (3 each).

Per-pose nuisance ξ_k (``points`` and ``inclinometer`` only, where the pose is not measured): the pose as
p_BC = p0_k + dp and R_BT = exp([δ]ₓ)·R0_k about a reference pose (p0_k, R0_k); dp in m, δ in rad.

Residuals of pose k, whitened (unit variance under the stated noise; ``Noise``) and times √w_k:

- ``pose``: L_i(θ, q_k) − (r_ki + o_i) for the six legs, whitened with W_k = σ_l² I + J_k Σ_q J_kᵀ, the
  measured pose's noise (σ_p per axis, σ_a per rotation axis) carried to the legs by the inverse Jacobian
  J_k (errors in variables to first order);
- ``points``: the six legs (σ_l) and p_BC + R_BT (p_TSk − p_TC) − y_k for each target (σ_p per axis);
- ``inclinometer``: the six legs (σ_l) and the two tilts ``tilts(R_BT)`` − measured (σ_a).

Jacobians are central differences of these vectorised residuals (``pose_blocks``), by pose block.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy.optimize import least_squares

from stewart_drake.calibration.measurements import Measurements
from stewart_drake.core.geometry import Platform, base_joints
from stewart_drake.core.kinematics import anchor_radius, inverse_jacobian, leg_lengths
from stewart_drake.core.newton_fk import forward_kinematics
from stewart_drake.core.rotations import angles_from_matrix, rotation_matrix

AXES = "xyz"
FD_STEP = 1e-6  # m or rad: central differences; truncation ~h² (1e-12 m), rounding ~1e-16 m / h (1e-10 m)
# The σ a weight uses when the stated one is below it (σ = 0: noise-free synthetic data). Ten times the
# central-difference Jacobian's rounding (~1e-10 m, FD_STEP) for lengths; the same number in rad for angles
# (an angle times the ~0.1–1 m lever arms of the presets is then ~0.1–1 nm).
NOISE_FLOOR = 1e-9


@dataclass(frozen=True)
class Noise:
    """Measurement noise, one σ per component: ``length`` (a leg sensor reading, m), ``position`` (a
    tracked position, per axis, m), ``angle`` (a measured orientation, per rotation axis, or a tilt, rad)."""

    length: float = 1e-6
    position: float = 10e-6
    angle: float = 20e-6

    def to_dict(self) -> dict:
        return {"length_m": self.length, "position_m": self.position, "angle_rad": self.angle}

    def floored(self) -> Noise:
        """The σ the weights use: each component at least ``NOISE_FLOOR`` (m or rad); a weight divides by it."""
        return Noise(*(max(v, NOISE_FLOOR) for v in (self.length, self.position, self.angle)))

    def below_floor(self) -> list[str]:
        """The components stated below ``NOISE_FLOOR`` (``["length", ...]``), which ``floored`` raises."""
        return [
            k
            for k, v in zip(("length", "position", "angle"), (self.length, self.position, self.angle))
            if v < NOISE_FLOOR
        ]


def exp_so3(w: np.ndarray) -> np.ndarray:
    """``(..., 3, 3)`` rotation exp([w]ₓ) of rotation vectors ``(..., 3)`` rad (Rodrigues)."""
    w = np.asarray(w, dtype=float)
    t = np.linalg.norm(w, axis=-1)[..., None, None]
    K = np.zeros(w.shape[:-1] + (3, 3))
    K[..., 0, 1], K[..., 0, 2], K[..., 1, 2] = -w[..., 2], w[..., 1], -w[..., 0]
    K = K - np.swapaxes(K, -1, -2)
    small = t < 1e-8
    ts = np.where(small, 1.0, t)
    a = np.where(small, 1.0 - t**2 / 6, np.sin(ts) / ts)
    b = np.where(small, 0.5 - t**2 / 24, (1 - np.cos(ts)) / ts**2)
    return np.eye(3) + a * K + b * (K @ K)


def rotation_angle(Ra: np.ndarray, Rb: np.ndarray) -> np.ndarray:
    """``(...)`` the angle (rad) of the rotation Raᵀ Rb."""
    c = (np.einsum("...ij,...ij->...", Ra, Rb) - 1) / 2
    return np.arccos(np.clip(c, -1.0, 1.0))


def tilts(R: np.ndarray) -> np.ndarray:
    """``(..., 2)`` the plate's tilt (rad) for R_BT ``(..., 3, 3)``: with R_BT = Rz(γ)·Ry(β)·Rx(α), (α, β),
    read from u = R_BTᵀ e_z (the base's vertical, i.e. gravity, in the plate frame): α = atan2(u_y, u_z),
    β = atan2(−u_x, √(u_y² + u_z²)); independent of the yaw γ (what a two-axis inclinometer can see)."""
    u = R[..., 2, :]
    return np.stack([np.arctan2(u[..., 1], u[..., 2]), np.arctan2(-u[..., 0], np.hypot(u[..., 1], u[..., 2]))], -1)


@dataclass(frozen=True, eq=False)
class Layout:
    """The parameter vector of a platform for one measurement kind (see the module docstring)."""

    nominal: Platform
    kind: str
    n_targets: int = 0
    gains: bool = False

    @cached_property
    def base(self) -> tuple[np.ndarray, np.ndarray]:
        """``(first leg of each base joint, base joint of each leg)`` (``geometry.base_joints``), found once
        per layout (the residuals read it at every evaluation); read-only."""
        first, leg_joint = base_joints(self.nominal)
        first.flags.writeable = leg_joint.flags.writeable = False
        return first, leg_joint

    @property
    def n_base(self) -> int:
        return len(self.base[0])

    @property
    def n_top(self) -> int:
        return len(self.nominal.top_anchors)

    @property
    def size(self) -> int:
        """The number of geometric parameters (42 on a 6-6 without targets and gains; 33 on a 3-6)."""
        return 3 * self.n_base + 3 * self.n_top + 6 + 6 * self.gains + 3 * self.n_targets

    @property
    def reference_length(self) -> float:
        """L_ref (m): the mid-stroke length that scales the gain parameters."""
        return float(self.nominal.stroke.mean())

    @property
    def names(self) -> tuple[str, ...]:
        out = [f"base joint {j + 1} {a}" for j in range(self.n_base) for a in AXES]
        out += [f"plate joint {j + 1} {a}" for j in range(self.n_top) for a in AXES]
        out += [f"leg {i + 1} offset" for i in range(6)]
        out += [f"leg {i + 1} gain" for i in range(6) if self.gains]
        out += [f"target {k + 1} {a}" for k in range(self.n_targets) for a in AXES]
        return tuple(out)

    @property
    def nuisance(self) -> int:
        """Unknowns per pose besides θ: 6 (the pose) when the pose is not measured, else 0."""
        return 0 if self.kind == "pose" else 6

    def theta(self, platform: Platform, targets=None) -> np.ndarray:
        """θ of ``platform`` (same architecture as the nominal) with ``targets`` ``(K, 3)`` plate-frame
        target positions (m) for ``points``."""
        first, _ = self.base
        parts = [platform.base_anchors[first].ravel(), platform.top_anchors.ravel(), platform.length_offset]
        if self.gains:
            parts.append((platform.length_gain - 1.0) * self.reference_length)
        if self.n_targets:
            parts.append(np.asarray(targets, dtype=float).reshape(self.n_targets * 3))
        return np.concatenate(parts)

    def split(self, theta) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(base joints (m, 3), plate joints (k, 3), offsets (6,), targets (K, 3))`` of ``(..., P)`` θ;
        leading axes kept."""
        theta = np.asarray(theta, dtype=float)
        lead = theta.shape[:-1]
        a, b = 3 * self.n_base, 3 * self.n_base + 3 * self.n_top
        c = b + 6 + 6 * self.gains
        return (
            theta[..., :a].reshape(lead + (self.n_base, 3)),
            theta[..., a:b].reshape(lead + (self.n_top, 3)),
            theta[..., b : b + 6],
            theta[..., c:].reshape(lead + (self.n_targets, 3)),
        )

    def gain(self, theta) -> np.ndarray:
        """``(..., 6)`` the sensor gains g_i of ``(..., P)`` θ (ones without ``gains``: the nominal's)."""
        theta = np.asarray(theta, dtype=float)
        if not self.gains:
            return np.broadcast_to(self.nominal.length_gain, theta.shape[:-1] + (6,))
        b = 3 * self.n_base + 3 * self.n_top + 6
        return 1.0 + theta[..., b : b + 6] / self.reference_length

    def scales(self) -> np.ndarray:
        """``(P,)`` what one unit of each parameter is: 1 (metres) or, for a gain, 1 / L_ref per metre."""
        out = np.ones(self.size)
        if self.gains:
            b = 3 * self.n_base + 3 * self.n_top + 6
            out[b : b + 6] = 1.0 / self.reference_length
        return out

    def platform(self, theta, name: str | None = None) -> Platform:
        """The nominal platform with the geometry θ: joints moved (shared joints together), offsets set."""
        B, T, o, _ = self.split(theta)
        _, leg_joint = self.base
        changes = {"length_offset": [float(v) for v in o]}
        if self.gains:
            changes["length_gain"] = [float(v) for v in self.gain(theta)]
        legs = type(self.nominal.legs)(**{**vars(self.nominal.legs), **changes})
        return self.nominal.replace(base_anchors=B[leg_joint], top_anchors=T, legs=legs, name=name or self.nominal.name)

    def rows(self) -> int:
        """Residual rows per pose."""
        return {"pose": 6, "points": 6 + 3 * self.n_targets, "inclinometer": 8}[self.kind]

    def scale(self) -> float:
        """A characteristic length (m) of the platform: its anchor radius (angles × this ≈ metres)."""
        return anchor_radius(self.nominal)


@dataclass(frozen=True, eq=False)
class Problem:
    """What the residuals need besides θ and ξ: the layout, the measurements, the noise, the reference
    poses (p0 ``(n, 3)``, R0 ``(n, 3, 3)``) and, for ``pose`` data, the whitening factors ``(n, 6, 6)``."""

    layout: Layout
    data: Measurements
    noise: Noise
    convention: str
    p0: np.ndarray
    R0: np.ndarray
    whiten: np.ndarray | None = None

    @property
    def n(self) -> int:
        return len(self.data)


def make_problem(layout: Layout, data: Measurements, noise: Noise, convention: str = "utn", platform=None) -> Problem:
    """The ``Problem`` of ``data``: reference poses from the measured poses (``pose``) or the forward
    kinematics of ``platform`` (default the nominal) at the readings; the ``pose`` whitening at them."""
    platform = platform or layout.nominal
    noise = noise.floored()
    if data.kind == "pose":
        q = data.poses
        R0 = rotation_matrix(q[:, 3:], convention)
        p0 = q[:, :3]
        Jinv = inverse_jacobian(platform, q, convention)  # (n, 6, 6): dL = Jinv [v; ω]
        Ju, Jw = Jinv[..., :3], Jinv[..., 3:]
        W = (
            noise.length**2 * np.eye(6)
            + noise.position**2 * Ju @ np.swapaxes(Ju, -1, -2)
            + noise.angle**2 * Jw @ np.swapaxes(Jw, -1, -2)
        )
        whiten = np.linalg.inv(np.linalg.cholesky(W))  # e_w = Lc⁻¹ e has unit covariance
        return Problem(layout, data, noise, convention, p0, R0, whiten)
    p0, R0, _ = solve_poses(platform, data.readings, None, convention)
    return Problem(layout, data, noise, convention, p0, R0)


def solve_poses(platform: Platform, readings, initial=None, convention: str = "utn"):
    """``(p (n, 3), R (n, 3, 3), solved (n,))``: the forward kinematics of ``platform`` at sensor ``readings``
    (m) by Newton from ``initial`` ``(n, 6)`` poses (None: home, the assembly mode nearest it). Where Newton does
    not converge (lengths near the edge of the assembly set, or none there), ``solved`` is False and the pose is
    the least-squares fit of the legs from the start (``scipy.optimize.least_squares``): the nearest pose the
    geometry allows, a usable reference for a fit that moves the pose anyway."""
    L = platform.lengths_from_readings(readings)
    r = forward_kinematics(platform, L, initial, convention, check_singularity=False, max_iter=60)
    p, R, solved = r.iterate[..., :3].copy(), r.rotation.copy(), np.asarray(r.converged, bool).copy()
    q0 = np.broadcast_to(platform.home_pose() if initial is None else np.asarray(initial, float), (len(L), 6))
    for i in np.flatnonzero(~solved):
        R0 = rotation_matrix(q0[i, 3:], convention)

        def legs(x, i=i, R0=R0):
            pk, Rk = q0[i, :3] + x[:3], exp_so3(x[3:]) @ R0
            return (
                np.linalg.norm(
                    pk + (platform.top_anchors_per_leg - platform.rotation_centre) @ Rk.T - platform.base_anchors,
                    axis=-1,
                )
                - L[i]
            )

        x = least_squares(legs, np.zeros(6), x_scale=np.r_[np.ones(3), np.full(3, 1 / anchor_radius(platform))]).x
        p[i], R[i] = q0[i, :3] + x[:3], exp_so3(x[3:]) @ R0
    return p, R, solved


def initial_targets(problem: Problem) -> np.ndarray:
    """``(K, 3)`` plate-frame target positions: the mean of R0ᵀ (y − p0) + p_TC over the poses."""
    d = problem.data
    local = np.einsum("nji,nkj->nki", problem.R0, d.targets - problem.p0[:, None, :])
    return local.mean(axis=0) + problem.layout.nominal.rotation_centre


def pose_residuals(problem: Problem, theta, xi=None) -> np.ndarray:
    """``(..., n, rows)`` whitened residuals of every pose for θ ``(..., P)`` and nuisance ξ ``(..., n, 6)``
    (None: zero), √w applied. Leading axes broadcast (the Jacobian evaluates many perturbations at once)."""
    lay, d, nz = problem.layout, problem.data, problem.noise
    B, T, o, S = lay.split(theta)
    _, leg_joint = lay.base
    c = lay.nominal.rotation_centre
    if xi is None or lay.nuisance == 0:
        p, R = problem.p0, problem.R0
    else:
        xi = np.asarray(xi, dtype=float)
        p = problem.p0 + xi[..., :3]
        R = exp_so3(xi[..., 3:]) @ problem.R0
    # leg vectors (..., n, 6, 3): p + R (t_leg − c) − b_leg
    t_leg = T[..., lay.nominal.leg_top, :] - c  # (..., 6, 3)
    l = p[..., None, :] + np.einsum("...nij,...kj->...nki", R, t_leg) - B[..., None, leg_joint, :]
    L = np.linalg.norm(l, axis=-1)
    e_leg = L - (d.readings * lay.gain(theta)[..., None, :] + o[..., None, :])
    sw = np.sqrt(d.weights)[:, None]
    if lay.kind == "pose":
        return np.einsum("nij,...nj->...ni", problem.whiten, e_leg) * sw
    if lay.kind == "points":
        y = p[..., None, :] + np.einsum("...nij,...kj->...nki", R, S - c)
        extra = (y - d.targets).reshape(y.shape[:-2] + (-1,)) / nz.position
    else:
        dt = tilts(R) - d.tilts
        extra = ((dt + np.pi) % (2 * np.pi) - np.pi) / nz.angle
    lead = np.broadcast_shapes(e_leg.shape[:-1], extra.shape[:-1])
    full = np.concatenate(
        [np.broadcast_to(e_leg / nz.length, lead + (6,)), np.broadcast_to(extra, lead + extra.shape[-1:])], axis=-1
    )
    return full * sw


def pose_blocks(problem: Problem, theta, xi=None, h: float = FD_STEP) -> tuple[np.ndarray, np.ndarray]:
    """Central-difference Jacobian blocks at (θ, ξ): ``(n, rows, P)`` d(residuals of pose k)/dθ and
    ``(n, rows, 6)`` d(residuals of pose k)/dξ_k (zeros for ``pose`` data: no nuisance)."""
    theta = np.asarray(theta, dtype=float)
    P = theta.size
    n = problem.n
    xi = np.zeros((n, 6)) if xi is None else np.asarray(xi, dtype=float)
    E = np.eye(P) * h
    Jg = (pose_residuals(problem, theta + E, xi) - pose_residuals(problem, theta - E, xi)) / (2 * h)  # (P, n, rows)
    Jg = np.moveaxis(Jg, 0, -1)
    rows = Jg.shape[1]
    if problem.layout.nuisance == 0:
        return Jg, np.zeros((n, rows, 6))
    D = np.eye(6) * h
    Jn = (pose_residuals(problem, theta, xi + D[:, None, :]) - pose_residuals(problem, theta, xi - D[:, None, :])) / (
        2 * h
    )
    return Jg, np.moveaxis(Jn, 0, -1)


def reduced_blocks(Jg: np.ndarray, Jn: np.ndarray) -> np.ndarray:
    """``(n, rows, P)`` each pose's θ-Jacobian with its own pose unknowns projected out, A_k = (I − Π_k) J_g,k
    (Π_k the projector on the columns of J_n,k): Σ A_kᵀ A_k is the information on θ once the poses are
    eliminated (the Schur complement), so its SVD is the identifiability of θ alone."""
    if not np.any(Jn):
        return Jg
    U, s, _ = np.linalg.svd(Jn, full_matrices=False)
    keep = s > s.max(axis=-1, keepdims=True) * 1e-10
    U = U * keep[:, None, :]
    return Jg - U @ (np.swapaxes(U, -1, -2) @ Jg)


def measure(platform: Platform, poses, convention: str = "utn", targets=None) -> dict:
    """Noise-free measurements of ``platform`` at ``(n, 6)`` poses: ``readings`` (n, 6) m, ``R`` (n, 3, 3),
    ``tilts`` (n, 2) rad and, with plate-frame ``targets`` (K, 3), ``targets`` (n, K, 3) in B."""
    q = np.asarray(poses, dtype=float)
    R = rotation_matrix(q[:, 3:], convention)
    out = {"readings": platform.readings(leg_lengths(platform, q, convention)), "R": R, "tilts": tilts(R)}
    if targets is not None:
        out["targets"] = q[:, None, :3] + np.einsum("nij,kj->nki", R, np.asarray(targets) - platform.rotation_centre)
    return out


def poses_from_frames(p: np.ndarray, R: np.ndarray, convention: str = "utn") -> np.ndarray:
    """``(n, 6)`` poses of positions ``(n, 3)`` and rotations ``(n, 3, 3)`` in ``convention``."""
    return np.concatenate([p, angles_from_matrix(R, convention)], axis=-1)
