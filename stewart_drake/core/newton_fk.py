"""Real-time forward kinematics (leg lengths -> pose): batched Newton–Raphson and Jacobian analysis.

Plain numpy, no Drake. Given target leg lengths L* ``(..., 6)`` (metres), Newton iterates on the pose
itself — the rotation centre's position p_BC and the plate's orientation R_BT — not on Euler angles:
each step solves J⁻¹(p, R) · [δp; ω] = L* − L(p, R) with the analytic inverse Jacobian of
``kinematics.inverse_jacobian`` (row i = [u_iᵀ, (r_i × u_i)ᵀ]), then updates p ← p + δp and
R ← exp([ω]×) · R. Working on R avoids the Euler convention's gimbal lock inside the iteration; the
angles ``(a_x, a_y, a_z)`` of the requested convention are computed only at the end
(``rotations.angles_from_matrix``).

Every sample gets its own pose, residual max_i |L_i − L*_i| (m), iteration count and status. A sample
that does not reach the tolerance gets ``converged = False`` and a NaN pose (its last iterate is kept
in ``FKResult.iterate`` for diagnosis): no silent wrong pose. A converged pose whose Jacobian is
ill-conditioned (condition number above ``max_condition``) is flagged ``near_singular`` and, by
default, warned about (``SingularityWarning``): near a singularity two assembly modes meet, so the
pose Newton reached may not be the one the trajectory was following.

What Newton guarantees: a converged sample satisfies the six length equations to ``tol``; the pose
found is *an* assembly mode, normally the one whose basin contains the initial guess (the closest one
when the guess is close). It does not find all assembly modes (see ``assembly_modes.assembly_modes``).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import anchor_radius, inverse_jacobian, scaled_jacobian, singular_value_condition
from stewart_drake.core.rotations import angles_from_matrix, check_convention, rotation_matrix
from stewart_drake.errors import (
    FkInputError,
    ForwardKinematicsError,
    SingularityWarning,
    SingularPoseError,
    counted,
    short_number,
)

# Per-sample status codes (FKResult.status).
CONVERGED = 0
MAX_ITER = 1
DIVERGED = 2
SINGULAR = 3
STATUS_TEXT = {
    CONVERGED: "converged",
    MAX_ITER: "did not converge within the iteration limit",
    DIVERGED: "diverged",
    SINGULAR: "hit a singular Jacobian",
}
# The plate is "lost" (diverged) when its centre is this many platform sizes from the base.
DIVERGENCE_FACTOR = 1e3

NOT_CONVERGED_TEMPLATE = (
    "forward kinematics: lengths sample {index} ({lengths_mm} mm) {reason} after {iterations} iterations: "
    "leg-length residual {residual_mm:.3g} mm > tolerance {tol_mm:.3g} mm{hint}"
)
SINGULAR_TEMPLATE = (
    "{what} {index} is near a singularity: Jacobian condition number {condition:.3g} > {max_condition:.3g}{hint}"
)


# ----------------------------------------------------------------------------------------------
# Jacobian analysis


def anchor_scale(platform: Platform) -> float:
    """The plate's anchor radius max |p_TTj − p_TC| (metres) as a float: ``kinematics.anchor_radius``, the
    length that makes the rotation columns of J⁻¹ commensurate with the translation columns."""
    return float(anchor_radius(platform))


@dataclass(frozen=True)
class JacobianAnalysis:
    """Singularity measures of J⁻¹ (dL/dt = J⁻¹ [v_BC; ω_B]) with its rotation columns divided by the
    anchor radius, so that the matrix is dimensionless. Arrays of shape ``(...)``:

    condition   2-norm condition number σ_max/σ_min (inf on a singularity)
    sigma_min   smallest singular value: the singularity distance. At a singularity it is 0 (a plate
                twist that changes no leg length exists); a leg-length error ε allows a pose error of
                up to ε/σ_min (metres, or metres of arc at the anchor radius).
    det_sign    sign of det(J⁻¹) (+1/−1, 0 on a singularity): constant within an assembly mode's
                singularity-free region, so it tells the regions apart. det J = 1/det J⁻¹ has the same sign.
    """

    condition: np.ndarray
    sigma_min: np.ndarray
    det_sign: np.ndarray

    def near_singular(self, max_condition: float = 1e8) -> np.ndarray:
        """``(...)`` True where the condition number exceeds ``max_condition``."""
        return ~(self.condition <= max_condition)


def analyse_inverse_jacobian(Jinv: np.ndarray, scale: float) -> JacobianAnalysis:
    """``JacobianAnalysis`` of ``(..., 6, 6)`` J⁻¹ with its rotation columns divided by ``scale`` (the
    anchor radius, metres)."""
    Jn = scaled_jacobian(Jinv, scale)
    s = np.linalg.svd(Jn, compute_uv=False)
    return JacobianAnalysis(singular_value_condition(s), s[..., -1], np.sign(np.linalg.det(Jn)))


def frobenius_condition(Jinv: np.ndarray, scale: float) -> np.ndarray:
    """``(n,)`` Frobenius-norm condition number ‖A‖_F ‖A⁻¹‖_F of the scaled ``(n, 6, 6)`` J⁻¹ (inf if
    singular). A cheap, conservative stand-in for the 2-norm condition number κ₂ (one batched inverse
    instead of an SVD): κ₂ <= κ_F <= 6 κ₂ for 6x6 matrices."""
    A = scaled_jacobian(Jinv, scale)
    try:
        Ainv = np.linalg.inv(A)
    except np.linalg.LinAlgError:  # some sample exactly singular: redo one by one
        Ainv = np.full_like(A, np.inf)
        for k in range(len(A)):
            try:
                Ainv[k] = np.linalg.inv(A[k])
            except np.linalg.LinAlgError:
                pass
    with np.errstate(invalid="ignore", over="ignore"):
        k_F = np.sqrt(np.einsum("nij,nij->n", A, A) * np.einsum("nij,nij->n", Ainv, Ainv))
    return np.where(np.isfinite(k_F), k_F, np.inf)


def jacobian_analysis(platform: Platform, poses, convention: str = "utn") -> JacobianAnalysis:
    """Condition number, singularity distance and det sign of J⁻¹ at ``(..., 6)`` poses."""
    return analyse_inverse_jacobian(inverse_jacobian(platform, poses, convention), anchor_scale(platform))


def check_poses_nonsingular(
    platform: Platform, poses, convention: str = "utn", max_condition: float = 1e8, action: str = "raise"
) -> JacobianAnalysis:
    """Analyse ``(..., 6)`` poses; where the condition number exceeds ``max_condition``, ``action`` =
    ``"raise"`` raises ``SingularPoseError`` naming the first such pose, ``"warn"`` warns
    (``SingularityWarning``), ``"ignore"`` does nothing. Returns the analysis."""
    a = jacobian_analysis(platform, poses, convention)
    _report_singular(a.condition, a.near_singular(max_condition), max_condition, action, "pose", "")
    return a


def _check_action(action: str) -> str:
    if action not in ("raise", "warn", "ignore"):
        raise FkInputError(FkInputError.ON_SINGULAR.format(value=action))
    return action


def _report_singular(cond, bad, max_condition, action, what, hint) -> None:
    if _check_action(action) == "ignore" or not np.any(bad):
        return
    idx = tuple(int(i) for i in np.argwhere(bad)[0]) if np.ndim(bad) else ()
    n = int(np.sum(bad))
    more = f" ({n} samples in all)" if n > 1 else ""
    msg = SINGULAR_TEMPLATE.format(
        what=what,
        index=counted(idx),
        condition=float(np.asarray(cond)[idx]),
        max_condition=max_condition,
        hint=hint + more,
    )
    if action == "raise":
        raise SingularPoseError(msg)
    warnings.warn(msg, SingularityWarning, stacklevel=3)


# ----------------------------------------------------------------------------------------------
# Newton


@dataclass(frozen=True)
class FKResult:
    """Batched forward-kinematics result; arrays have the batch shape ``(...)`` of the lengths.

    poses        (..., 6)    [px, py, pz, a_x, a_y, a_z] (m, rad, ``convention``); NaN where not converged
    rotation     (..., 3, 3) R_BT of the final iterate
    iterate      (..., 6)    final iterate as a pose, converged or not (for diagnosis)
    residual     (...)       max_i |L_i(pose) − L*_i| at the final iterate, metres
    iterations   (...)       Newton updates applied
    converged    (...)       residual <= tol
    status       (...)       CONVERGED, MAX_ITER, DIVERGED or SINGULAR (see STATUS_TEXT)
    condition    (...)       Frobenius condition number κ_F of the scaled J⁻¹ at a converged pose (NaN
                             when not converged or not checked); κ₂ <= κ_F <= 6 κ₂, see ``frobenius_condition``
    near_singular (...)      converged but condition > max_condition: the pose is poorly determined
    """

    poses: np.ndarray
    rotation: np.ndarray
    iterate: np.ndarray
    residual: np.ndarray
    iterations: np.ndarray
    converged: np.ndarray
    status: np.ndarray
    condition: np.ndarray
    near_singular: np.ndarray
    lengths: np.ndarray
    tol: float
    convention: str

    def failures(self) -> list[tuple]:
        """Indices of the samples that did not converge."""
        return [tuple(int(i) for i in idx) for idx in np.argwhere(~np.asarray(self.converged))]

    def message(self, index=()) -> str:
        """A one-line explanation of sample ``index``'s outcome."""
        index = tuple(int(i) for i in np.atleast_1d(index)) if np.ndim(self.converged) else ()
        st = int(self.status[index])
        if st == CONVERGED:
            return f"lengths sample {counted(index)}: converged in {int(self.iterations[index])} iterations, residual {float(self.residual[index]) * 1e3:.3g} mm"
        hint = ""
        if st in (MAX_ITER, DIVERGED):
            hint = " — the lengths may admit no assembly (legs too long or too short for the geometry), or the initial pose is too far"
        return NOT_CONVERGED_TEMPLATE.format(
            index=counted(index),
            lengths_mm=", ".join(short_number(v * 1e3) for v in self.lengths[index]),
            reason=STATUS_TEXT[st],
            iterations=int(self.iterations[index]),
            residual_mm=float(self.residual[index]) * 1e3,
            tol_mm=self.tol * 1e3,
            hint=hint,
        )

    def raise_if_failed(self) -> FKResult:
        """Raise ``ForwardKinematicsError`` for the first sample that did not converge; else return self."""
        bad = self.failures()
        if bad:
            more = f" ({len(bad)} of {np.size(self.converged)} samples failed)" if len(bad) > 1 else ""
            raise ForwardKinematicsError(self.message(bad[0]) + more)
        return self


def validate_lengths(lengths) -> np.ndarray:
    """``(..., 6)`` leg lengths as a float array; FkInputError naming the sample and leg if not finite and > 0."""
    L = np.asarray(lengths, dtype=float)
    if L.shape[-1:] != (6,):
        raise FkInputError(FkInputError.LENGTHS_SHAPE.format(shape=L.shape))
    bad = ~(np.isfinite(L) & (L > 0))
    if np.any(bad):
        idx = tuple(int(i) for i in np.argwhere(bad)[0])
        raise FkInputError(
            FkInputError.LENGTH_VALUE.format(index=counted(idx[:-1]), leg=idx[-1] + 1, value=float(L[idx]))
        )
    return L


def _exp_so3(w: np.ndarray) -> np.ndarray:
    """``(n, 3)`` rotation vectors -> ``(n, 3, 3)`` rotation matrices (Rodrigues)."""
    th2 = np.einsum("ni,ni->n", w, w)
    th = np.sqrt(th2)
    small = th < 1e-6
    ths = np.where(small, 1.0, th)
    A = np.where(small, 1.0 - th2 / 6.0, np.sin(ths) / ths)
    B = np.where(small, 0.5 - th2 / 24.0, (1.0 - np.cos(ths)) / ths**2)
    K = np.zeros(w.shape[:-1] + (3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -w[:, 2], w[:, 1], -w[:, 0]
    K[:, 1, 0], K[:, 2, 0], K[:, 2, 1] = w[:, 2], -w[:, 1], w[:, 0]
    return np.eye(3) + A[:, None, None] * K + B[:, None, None] * (K @ K)


def leg_geometry(platform: Platform, p: np.ndarray, R: np.ndarray):
    """For ``(n, 3)`` positions p_BC and ``(n, 3, 3)`` orientations R_BT: r_i = R (p_TTi − p_TC) ``(n, 6, 3)``, leg vectors l_i ``(n, 6, 3)`` and lengths ``(n, 6)``."""
    r = np.swapaxes(R @ (platform.top_anchors_per_leg - platform.rotation_centre).T, -1, -2)
    l = p[:, None, :] + r - platform.base_anchors
    return r, l, np.sqrt(np.sum(l * l, axis=-1))


def _jinv(r: np.ndarray, l: np.ndarray, L: np.ndarray) -> np.ndarray:
    """J⁻¹ rows [u_iᵀ, (r_i × u_i)ᵀ] from ``leg_geometry`` output (cross product written out: faster than np.cross)."""
    u = l / L[..., None]
    J = np.empty(L.shape + (6,))
    J[..., :3] = u
    rx, ry, rz, ux, uy, uz = r[..., 0], r[..., 1], r[..., 2], u[..., 0], u[..., 1], u[..., 2]
    J[..., 3] = ry * uz - rz * uy
    J[..., 4] = rz * ux - rx * uz
    J[..., 5] = rx * uy - ry * ux
    return J


def legs_and_jacobian(platform: Platform, p: np.ndarray, R: np.ndarray):
    """For ``(n, 3)`` positions p_BC and ``(n, 3, 3)`` orientations R_BT: leg lengths ``(n, 6)`` and the
    inverse Jacobian J⁻¹ ``(n, 6, 6)`` (same rows as ``kinematics.inverse_jacobian``, computed from R
    directly so that no Euler angles are involved)."""
    r, l, L = leg_geometry(platform, p, R)
    return L, _jinv(r, l, L)


def _solve_batch(J: np.ndarray, e: np.ndarray):
    """Solve J d = e for each sample; returns (d, ok). Exactly singular samples get ok = False."""
    try:
        return np.linalg.solve(J, e[..., None])[..., 0], np.ones(len(J), bool)
    except np.linalg.LinAlgError:
        d, ok = np.zeros_like(e), np.ones(len(J), bool)
        for k in range(len(J)):
            try:
                d[k] = np.linalg.solve(J[k], e[k])
            except np.linalg.LinAlgError:
                ok[k] = False
        return d, ok


def newton_core(platform: Platform, p, R, L_target, tol=1e-12, max_iter=30, max_step_m=0.1, max_step_rad=0.5):
    """Flat Newton iteration (no validation; used by ``forward_kinematics`` and ``assembly_modes``).

    ``p (n, 3)``, ``R (n, 3, 3)`` initial iterates (modified copies are returned), ``L_target (n, 6)``.
    Returns ``p, R, residual (n,), iterations (n,), status (n,)``. A step is scaled down (direction kept)
    so that |δp| <= max_step_m and |ω| <= max_step_rad.
    """
    p, R = np.array(p, dtype=float), np.array(R, dtype=float)
    n = len(p)
    size = max(
        np.abs(platform.base_anchors).max(), np.abs(platform.top_anchors).max(), float(np.max(L_target, initial=0))
    )
    residual = np.full(n, np.inf)
    iterations = np.zeros(n, dtype=np.intp)
    status = np.full(n, MAX_ITER, dtype=np.intp)
    active = np.arange(n)
    for k in range(max_iter + 1):
        if active.size == 0:
            break
        pa, Ra = p[active], R[active]
        r, l, L = leg_geometry(platform, pa, Ra)
        err = L_target[active] - L
        res = np.abs(err).max(axis=-1)
        residual[active] = res
        done = res <= tol
        lost = ~np.isfinite(res) | (np.linalg.norm(pa, axis=-1) > DIVERGENCE_FACTOR * size)
        status[active[done]] = CONVERGED
        status[active[lost & ~done]] = DIVERGED
        keep = ~(done | lost)
        if k == max_iter:
            break
        if not keep.all():
            active, pa, Ra, r, l, L, err = (a[keep] for a in (active, pa, Ra, r, l, L, err))
        d, ok = _solve_batch(_jinv(r, l, L), err)
        if not ok.all():
            status[active[~ok]] = SINGULAR
            active, pa, Ra, d = active[ok], pa[ok], Ra[ok], d[ok]
        dp, w = d[:, :3], d[:, 3:]
        with np.errstate(divide="ignore"):
            s = np.minimum(
                1.0, np.minimum(max_step_m / np.linalg.norm(dp, axis=-1), max_step_rad / np.linalg.norm(w, axis=-1))
            )
        p[active] = pa + s[:, None] * dp
        R[active] = _exp_so3(s[:, None] * w) @ Ra
        iterations[active] += 1
    return p, R, residual, iterations, status


def _check_options(tol, max_iter, max_step_m, max_step_rad, max_condition):
    for name, v in (
        ("tol", tol),
        ("max_step_m", max_step_m),
        ("max_step_rad", max_step_rad),
        ("max_condition", max_condition),
    ):
        if not (np.isfinite(v) and v > 0):
            raise FkInputError(FkInputError.POSITIVE.format(name=name, value=v))
    if int(max_iter) != max_iter or max_iter < 1:
        raise FkInputError(FkInputError.MAX_ITER.format(value=max_iter))


def forward_kinematics(
    platform: Platform,
    lengths,
    initial=None,
    convention: str = "utn",
    *,
    tol: float = 1e-13,
    max_iter: int = 30,
    max_step_m: float = 0.1,
    max_step_rad: float = 0.5,
    max_condition: float = 1e8,
    check_singularity: bool = True,
    on_singular: str = "warn",
) -> FKResult:
    """Batched Newton–Raphson forward kinematics.

    lengths   ``(..., 6)`` target leg lengths, metres.
    initial   ``(6,)`` or ``(..., 6)`` initial pose(s) (m, rad, ``convention``): the previous pose when
              following a trajectory; default the platform's home pose.
    tol       convergence when max_i |L_i − L*_i| <= tol (metres). The default 1e-13 m is ~1000x the
              rounding floor of lengths near 1 m; the pose error is about tol / sigma_min (see
              ``JacobianAnalysis``), i.e. < 1e-9 m and rad unless the pose is near a singularity.
    max_iter  iteration limit; max_step_m / max_step_rad cap each step's translation / rotation.
    check_singularity  compute the Jacobian condition number at the initial guess and at the solution;
              where it exceeds ``max_condition``, ``on_singular`` = "warn" (default), "raise" or "ignore".
              Switch off only when the trajectory is known to stay clear of singularities (saves an SVD
              per sample).

    Returns an ``FKResult``; call ``.raise_if_failed()`` to turn non-convergence into a
    ``ForwardKinematicsError`` naming the first failed sample.
    """
    check_convention(convention)
    _check_options(tol, max_iter, max_step_m, max_step_rad, max_condition)
    _check_action(on_singular)
    L_target = validate_lengths(lengths)
    batch = L_target.shape[:-1]
    q0 = np.asarray(platform.home_pose() if initial is None else initial, dtype=float)
    if q0.shape[-1:] != (6,):
        raise FkInputError(FkInputError.INITIAL_SHAPE.format(shape=q0.shape))
    if not np.all(np.isfinite(q0)):
        raise FkInputError(FkInputError.INITIAL_NOT_FINITE.format(value=q0.tolist()))
    try:
        np.broadcast_shapes(q0.shape, batch + (6,))
    except ValueError:
        raise FkInputError(
            FkInputError.INITIAL_BROADCAST.format(shape=q0.shape, lengths_shape=L_target.shape)
        ) from None
    scale = anchor_scale(platform)
    if check_singularity:  # on the distinct initial poses, before broadcasting
        qi = q0.reshape(-1, 6)
        _, J0 = legs_and_jacobian(platform, qi[:, :3], rotation_matrix(qi[:, 3:], convention))
        c0 = frobenius_condition(J0, scale).reshape(q0.shape[:-1])
        _report_singular(
            c0,
            ~(c0 <= max_condition),
            max_condition,
            on_singular,
            "initial pose",
            "; Newton's first step there is unreliable: start from another pose",
        )
    q0 = np.broadcast_to(q0, batch + (6,)).reshape(-1, 6)
    R0 = rotation_matrix(q0[:, 3:], convention)
    Lf = L_target.reshape(-1, 6)
    p, R, res, its, status = newton_core(platform, q0[:, :3], R0, Lf, tol, max_iter, max_step_m, max_step_rad)
    converged = status == CONVERGED
    cond = np.full(len(p), np.nan)
    if check_singularity and converged.any():
        _, J = legs_and_jacobian(platform, p[converged], R[converged])
        cond[converged] = frobenius_condition(J, scale)
    near = converged & ~(cond <= max_condition)
    iterate = np.concatenate([p, angles_from_matrix(R, convention)], axis=-1)
    poses = np.where(converged[:, None], iterate, np.nan)
    result = FKResult(
        poses=poses.reshape(batch + (6,)),
        rotation=R.reshape(batch + (3, 3)),
        iterate=iterate.reshape(batch + (6,)),
        residual=res.reshape(batch),
        iterations=its.reshape(batch),
        converged=converged.reshape(batch),
        status=status.reshape(batch),
        condition=cond.reshape(batch),
        near_singular=near.reshape(batch),
        lengths=L_target,
        tol=float(tol),
        convention=convention,
    )
    if check_singularity:
        _report_singular(
            result.condition,
            result.near_singular,
            max_condition,
            on_singular,
            "forward-kinematics solution for lengths sample",
            "; the pose is poorly determined and may belong to another assembly mode",
        )
    return result


def multiple_root(platform: Platform, pose, sigma_min: float, tol: float, convention: str = "utn") -> bool:
    """Whether a pose (6,) that Newton reached to ``tol`` (m, the largest leg-length residual) is, at that
    accuracy, a multiple root: a pose on a singularity.

    Near a fold, along its null direction at distance d from the singular root, the leg lengths miss their
    targets by r = K·d²/2 and the smallest singular value of the scaled J⁻¹ is σ_min = K·d, K the curvature
    of the lengths along that direction (1/m), so σ_min² = 2·K·r: a double root stops Newton (which then
    converges only linearly) with σ_min² ≤ 2·√6·K·tol (r measured along one left singular vector, at most
    √6 times the largest residual). K is bounded by the slope of σ_min about the pose (one-sided differences
    over 0.1 mm, and 0.1 mm / anchor radius in the angles). A simple root keeps σ_min of order 1 at any
    tolerance; a pose is called a multiple root when σ_min² ≤ 8·K·tol."""
    pose = np.asarray(pose, dtype=float)
    step = 1e-4 * np.r_[np.ones(3), np.full(3, 1 / anchor_scale(platform))]
    poses = pose + np.concatenate([np.diag(step), -np.diag(step)])
    s = jacobian_analysis(platform, poses, convention).sigma_min
    slope = float(np.linalg.norm((s[:6] + s[6:]) / (2 * 1e-4)))  # |σ_min| each side: ≥ the slope across a fold
    return bool(sigma_min**2 <= 8 * slope * tol)
