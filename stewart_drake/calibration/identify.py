"""Identification: robust nonlinear least squares of the calibration model on measured poses.

``identify`` fits θ (and the poses' own unknowns) with scipy's ``least_squares`` (trust-region reflective):
a first pass with the plain quadratic loss from the nominal, then Huber passes (quadratic within f σ, linear
beyond; f from the plain fit's largest residual down to ``HUBER_SIGMAS``, ``huber_scales``) so that an outlying
pose pulls the fit no more than a few σ. The parameters the data cannot identify (``identifiability``) stay at
their nominal values. The covariance of θ is (Σ A_kᵀ A_k)⁻¹ over the free parameters (``model.reduced_blocks``:
the poses' unknowns eliminated; residuals whitened by the stated noise), so σ is what the stated noise gives,
not fitted. Rows that repeat an earlier row exactly count once (``Measurements.without_copies``).

A converged fit is then judged: ``failures`` (the model moved beyond what a built machine can,
``plausible_correction``; forward kinematics that does not converge on the calibrated platform; a validation
worse than the nominal, ``validation_failures``) make it unusable; ``warnings`` say what to know to read it
(copies, σ at the floor, residuals below the stated noise, a condition number above ``CONDITION_RULE`` with the
weakest combination named).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares

from stewart_drake.calibration.identifiability import (
    CONDITION_RULE,
    Identifiability,
    analyse,
    free_parameters,
    stacked,
)
from stewart_drake.calibration.measurements import Measurements
from stewart_drake.calibration.model import (
    NOISE_FLOOR,
    Layout,
    Noise,
    Problem,
    initial_targets,
    make_problem,
    pose_blocks,
    pose_residuals,
    reduced_blocks,
)
from stewart_drake.calibration.plan import Box, candidate_poses
from stewart_drake.calibration.validate import validation_errors
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import anchor_radius, leg_lengths
from stewart_drake.errors import ForwardKinematicsError, GeometryError

HUBER_SIGMAS = 3.0
HUBER_STEP = 10.0  # each Huber pass's f_scale is this factor below the last's (``huber_scales``)
MAX_NFEV = 60  # evaluations per pass; Gauss–Newton converges in ~10 from ~1 mm errors (inclinometer data: ~30)
OUTLIER_P = 1e-3  # a pose whose residual a χ² test rejects at this level (Bonferroni over the poses) is named
MAX_CHI2_RATIO = 100.0  # residuals this many times the stated noise (RMS): the model does not fit the data
LOW_CHI2_P = 1e-3  # residuals whose χ² falls below its lower quantile at this level are smaller than the noise allows
DISTINCT_SIGMAS = 10.0  # two readings of one pose differ by N(0, 2σ²) per leg: beyond 7 standard deviations at 10 σ
PLAUSIBLE_FRACTION = 0.05  # a model change beyond this fraction of the platform's size is no manufacturing error
WORKSPACE_POSES = 200  # candidate poses drawn to measure how far the calibrated model moved (``model_departure``)
VALIDATION_SE = 2.0  # the calibrated model is worse than nominal when its RMS exceeds the nominal's by this many
# standard errors of an RMS of m values (relative 1/√(2m) for Gaussian errors)


def huber_scales(r) -> list[float]:
    """The Huber passes' ``f_scale`` (in σ): from the largest whitened residual ``r`` of the plain fit down to
    ``HUBER_SIGMAS`` by factors of ``HUBER_STEP``, each pass started where the last stopped. A gross outlier
    (thousands of σ) then loses its pull in steps, each a short solve; one pass at 3 σ from the plain fit
    crawls (the outlier's rows are in Huber's linear part, where its Gauss–Newton model is flat)."""
    top = float(np.max(np.abs(r), initial=0.0))
    k = int(np.ceil(np.log(max(top, HUBER_SIGMAS) / HUBER_SIGMAS) / np.log(HUBER_STEP)))
    return [HUBER_SIGMAS * HUBER_STEP ** (k - i) for i in range(k + 1)]


def distinct_poses(data: Measurements, noise: Noise) -> int:
    """The distinct poses in ``data``: rows whose readings all agree within ``DISTINCT_SIGMAS`` σ of the leg
    sensor (``noise.floored()``) are one pose measured again (``Measurements.distinct_poses``)."""
    return data.distinct_poses(distinct_tolerance(noise))


def distinct_tolerance(noise: Noise) -> float:
    """The reading difference (m) below which two rows are one pose: ``DISTINCT_SIGMAS`` × the sensor's σ."""
    return DISTINCT_SIGMAS * noise.floored().length


def min_poses(layout: Layout) -> int:
    """The fewest poses whose equations outnumber the unknowns (θ and each pose's own)."""
    per = layout.rows() - layout.nuisance
    return int(np.ceil((layout.size + 1) / per))


@dataclass
class CalibrationResult:
    """The identified platform and everything known about it (``to_dict`` is the command's ``--json``)."""

    nominal: Platform
    calibrated: Platform
    layout: Layout
    noise: Noise
    convention: str
    theta0: np.ndarray
    theta: np.ndarray
    sigma: np.ndarray
    identifiability: Identifiability
    converged: bool
    message: str
    nfev: int
    rms_sigma_before: float
    rms_sigma_after: float
    pose_rms_before: np.ndarray
    pose_rms_after: np.ndarray
    lines: np.ndarray
    outliers: list = field(default_factory=list)
    warnings: list = field(default_factory=list)
    failures: list = field(default_factory=list)
    fit_before: dict = field(default_factory=dict)
    fit_after: dict = field(default_factory=dict)
    validation: dict | None = None
    source: str = ""
    sha256: str = ""

    @property
    def targets(self) -> np.ndarray:
        """``(K, 3)`` identified target positions in the plate frame (m)."""
        return self.layout.split(self.theta)[3]

    @property
    def corrections(self) -> np.ndarray:
        return self.theta - self.theta0

    @property
    def ok(self) -> bool:
        """Converged and none of ``failures``: a calibrated platform to use."""
        return self.converged and not self.failures

    def to_dict(self) -> dict:
        names = self.layout.names
        fixed = set(self.identifiability.fixed)
        return {
            "platform": self.nominal.name,
            "measurement_type": self.layout.kind,
            "source": self.source,
            "sha256": self.sha256,
            "poses": len(self.lines),
            "convention": self.convention,
            "noise": self.noise.to_dict(),
            "converged": self.converged,
            "message": self.message,
            "ok": self.ok,
            "failures": self.failures,
            "warnings": self.warnings,
            "evaluations": self.nfev,
            "residual_rms_sigma": {"before": self.rms_sigma_before, "after": self.rms_sigma_after},
            "fit_before": self.fit_before,
            "fit_after": self.fit_after,
            "identifiability": self.identifiability.to_dict(),
            "parameters": [
                {
                    "name": n,
                    "unit": "m" if k == 1.0 else "1",
                    "nominal": float(a * k + (k != 1.0)),
                    "identified": float(b * k + (k != 1.0)),
                    "correction": float((b - a) * k),
                    "sigma": float(s * k),
                    "fixed": i in fixed,
                }
                for i, (n, a, b, s, k) in enumerate(
                    zip(names, self.theta0, self.theta, self.sigma, self.layout.scales())
                )
            ],
            "outliers": self.outliers,
            "pose_rms_sigma": [{"line": int(ln), "rms": float(r)} for ln, r in zip(self.lines, self.pose_rms_after)],
            "validation": self.validation,
        }


def plausible_correction(platform: Platform) -> float:
    """The largest change (m) calibration can make to what a built ``platform`` reads: ``PLAUSIBLE_FRACTION`` of its
    size, the smaller of its anchor radius and its stroke range. Manufacturing and assembly put joints and sensor
    zeros millimetres off the drawing; a model that reads centimetres away from it is another machine, or a fit
    that wandered along directions the poses do not fix."""
    return PLAUSIBLE_FRACTION * min(anchor_radius(platform), platform.L_max - platform.L_min)


def model_departure(nominal: Platform, calibrated: Platform, convention: str = "utn") -> float:
    """The largest difference (m) between the readings ``calibrated`` and ``nominal`` predict, over
    ``WORKSPACE_POSES`` candidate poses drawn (seeded) in the nominal's default planning box: how far the model
    moved, whichever parameter combination moved it."""
    q = candidate_poses(nominal, Box.default(nominal), WORKSPACE_POSES, seed=0, convention=convention)
    d = calibrated.readings(leg_lengths(calibrated, q, convention)) - nominal.readings(
        leg_lengths(nominal, q, convention)
    )
    return float(np.abs(d).max(initial=0.0))


def _failures(result: CalibrationResult) -> list[str]:
    """What makes a converged fit unusable: a calibrated model whose readings depart from the nominal's by more than
    ``plausible_correction`` over the workspace, a calibrated platform whose forward kinematics does not converge
    at the fitted readings."""
    out = []
    lay, ident = result.layout, result.identifiability
    limit = plausible_correction(result.nominal)
    moved = model_departure(result.nominal, result.calibrated, result.convention)
    if moved > limit:
        corr = np.abs(result.corrections * ident.free)
        i = int(np.argmax(corr))
        out.append(
            f"the calibrated model reads up to {moved * 1e3:.3g} mm away from the nominal over the workspace, beyond "
            f"{limit * 1e3:.3g} mm ({PLAUSIBLE_FRACTION:.0%} of the platform's size; largest correction "
            f"{corr[i] * 1e3:.3g} mm, {lay.names[i]}): this is not a built {result.nominal.name} (wrong --platform, "
            f"or poses that do not fix the parameters: condition number {ident.condition:.3g})"
        )
    unsolved = result.fit_after.get("unsolved")
    if unsolved:
        out.append(
            f"the calibrated platform's forward kinematics does not converge at {unsolved['count']} of "
            f"{len(result.lines)} fitted poses (lines {_lines(unsolved['lines'])})"
        )
    return out


def validation_failures(validation: dict) -> list[str]:
    """What makes a validation fail (``validation``: ``{"nominal": ..., "calibrated": ...}`` of
    ``validation_errors``): a quantity whose calibrated RMS exceeds the nominal's by more than ``VALIDATION_SE``
    standard errors, or held-out readings where the calibrated platform's forward kinematics does not converge."""
    out = []
    nom, cal = validation["nominal"], validation["calibrated"]
    for key, c in cal.items():
        if key == "unsolved" or key not in nom:
            continue
        a, b = nom[key]["rms"], c["rms"]
        if b > a * (1 + VALIDATION_SE / np.sqrt(2 * c["count"])):
            scale, unit = (1e6, "µm") if c["unit"] == "m" else (1e3, "mrad")
            out.append(
                f"validation: the calibrated model is worse than the nominal on the {validation['poses']} held-out "
                f"poses ({key} RMS {a * scale:.3g} → {b * scale:.3g} {unit})"
            )
    if "unsolved" in cal:
        out.append(
            f"validation: the calibrated platform's forward kinematics does not converge at {cal['unsolved']['count']} "
            f"of {validation['poses']} held-out poses"
        )
    return out


def _lines(lines) -> str:
    shown = ", ".join(str(v) for v in lines[:8])
    return shown + (f", … ({len(lines) - 8} more)" if len(lines) > 8 else "")


def copies_warning(copies) -> str:
    """The warning for rows dropped as copies (``[(line, line it repeats), ...]``, ``without_copies``)."""
    more = ", …" if len(copies) > 1 else ""
    return (
        f"{len(copies)} rows repeat an earlier row exactly and were counted once (line {copies[0][0]} repeats "
        f"line {copies[0][1]}{more}): a copy is not another measurement"
    )


def _warnings(result: CalibrationResult, copies, chi2_inliers: float, dof: int, chi2) -> list[str]:
    """What a user must know to read a usable fit: copied rows, σ = 0 weighed as the floor, residuals below
    the stated noise, a condition number above the rule with the weakly identified parameters named."""
    out = [copies_warning(copies)] if copies else []
    low = result.noise.below_floor()
    if low:
        out.append(
            f"σ {', '.join(low)} stated below {NOISE_FLOOR:g} (m or rad): weighed as {NOISE_FLOOR:g} (a weight divides "
            "by σ); the σ of the parameters are what that noise would give"
        )
    elif dof > 0 and chi2_inliers < chi2.ppf(LOW_CHI2_P, dof):
        out.append(
            f"residuals {np.sqrt(chi2_inliers / dof):.3g} σ RMS after the fit, smaller than the stated noise can give "
            f"(χ² {chi2_inliers:.3g} < {chi2.ppf(LOW_CHI2_P, dof):.3g}, the {LOW_CHI2_P:g} quantile of {dof} degrees "
            "of freedom): the noise is overstated or the rows are not independent measurements; σ is not to be trusted"
        )
    ident = result.identifiability
    if ident.condition > CONDITION_RULE and ident.weak and ident.weak[0][1] > 0:
        name, s = ident.weak[0]
        free = ident.free
        worst = int(np.flatnonzero(free)[np.argmax(result.sigma[free])])
        fit = next((v for v in result.fit_after.values() if "unit" in v), None)
        model = (
            f" while the model as a whole fits the poses to {fit['rms'] * 1e6:.3g} µ{'m' if fit['unit'] == 'm' else 'rad'} RMS"
            if fit
            else ""
        )
        n_weak = int(np.sum(ident.singular_values * CONDITION_RULE < ident.singular_values[0]))
        out.append(
            f"condition number {ident.condition:.3g} is above ~{CONDITION_RULE:g}: {n_weak} combinations of the "
            f"parameters are weakly identified, the weakest [{name}] to σ {result.noise.floored().length / s * 1e6:.3g} µm; "
            f"single parameters can be off by their σ (up to {result.sigma[worst] * 1e6:.3g} µm, "
            f"{result.layout.names[worst]}){model}: judge the model by its validation, not the parameter table"
        )
    return out


def _variables(problem: Problem, free: np.ndarray):
    """``(pack, unpack)`` between (θ, ξ) and the solver's vector [θ_free, ξ]."""
    lay = problem.layout
    n6 = problem.n * lay.nuisance

    def unpack(z, theta_fixed):
        theta = theta_fixed.copy()
        theta[free] = z[: free.sum()]
        xi = z[free.sum() :].reshape(problem.n, 6) if n6 else None
        return theta, xi

    def pack(theta, xi):
        return np.concatenate([theta[free], np.zeros(n6) if xi is None else np.ravel(xi)])

    return pack, unpack


def _jacobian(problem: Problem, theta, xi, free) -> np.ndarray:
    """Dense ``(n·rows, free + 6n)`` Jacobian of the stacked residuals in the solver's variables."""
    Jg, Jn = pose_blocks(problem, theta, xi)
    n, rows, _ = Jg.shape
    parts = [Jg[:, :, free].reshape(n * rows, -1)]
    if problem.layout.nuisance:
        blk = np.zeros((n, rows, n, 6))
        blk[np.arange(n), :, np.arange(n), :] = Jn
        parts.append(blk.reshape(n * rows, n * 6))
    return np.concatenate(parts, axis=1)


def identify(
    nominal: Platform, data: Measurements, noise: Noise = Noise(), convention: str = "utn", gains: bool = False
) -> CalibrationResult:
    """Identify the geometry of the machine that produced ``data`` (see the module docstring). Returns a
    ``CalibrationResult`` whose ``converged`` is False (with the reason in ``message``) when the solver
    stopped short or the fit leaves residuals far above the stated noise, and whose ``failures`` (when converged)
    and ``warnings`` judge it; ``ok`` is converged without failures. ``gains``: identify each sensor's gain too
    (48 parameters on a 6-6). A σ of ``noise`` below ``NOISE_FLOOR`` is weighed as the floor."""
    stated, noise = noise, noise.floored()
    data, copies = data.without_copies()
    layout = Layout(nominal, data.kind, data.n_targets, gains)
    problem = make_problem(layout, data, noise, convention)
    targets0 = initial_targets(problem) if data.kind == "points" else None
    theta0 = layout.theta(nominal, targets0)
    Jg, Jn = pose_blocks(problem, theta0)
    fixed0, free = free_parameters(stacked(reduced_blocks(Jg, Jn), noise.length))  # the convention, at the nominal
    pack, unpack = _variables(problem, free)

    def fun(z):
        theta, xi = unpack(z, theta0)
        return pose_residuals(problem, theta, xi).ravel()

    def jac(z):
        theta, xi = unpack(z, theta0)
        return _jacobian(problem, theta, xi, free)

    z0 = pack(theta0, None)
    r0 = fun(z0)
    first = least_squares(fun, z0, jac=jac, method="trf", x_scale="jac", max_nfev=MAX_NFEV, xtol=1e-12, ftol=1e-12)
    second, nfev = first, first.nfev
    for f_scale in huber_scales(first.fun):
        second = least_squares(
            fun,
            second.x,
            jac=jac,
            method="trf",
            loss="huber",
            f_scale=f_scale,
            x_scale="jac",
            max_nfev=MAX_NFEV,
            xtol=1e-12,
            ftol=1e-12,
        )
        nfev += second.nfev
    theta, xi = unpack(second.x, theta0)
    r = second.fun.reshape(problem.n, -1)
    # covariance of θ at the solution, poses' unknowns eliminated
    Jg, Jn = pose_blocks(problem, theta, xi)
    A = reduced_blocks(Jg, Jn)
    ident = analyse(layout, stacked(A, noise.length), theta, fixed=fixed0)
    free = ident.free
    Af = A[:, :, free].reshape(-1, free.sum())
    cov = np.linalg.pinv(Af.T @ Af)
    sigma = np.zeros(layout.size)
    sigma[free] = np.sqrt(np.clip(np.diag(cov), 0, None))
    rms_after = float(np.sqrt(np.mean(r**2)))
    converged = bool(first.status > 0 and second.status > 0)
    message = "converged" if converged else f"solver stopped: {second.message}"
    # outliers: a pose's whitened residual beyond the χ² test (quadratic part only: Huber keeps it bounded)
    k = r.shape[1]
    # imported here: scipy.stats takes ~0.5 s CPU to import, which the report's main process (it imports every
    # analysis to list them) would pay without ever identifying
    from scipy.stats import chi2

    limit = chi2.isf(OUTLIER_P / problem.n, k)
    per_pose = np.sum(r**2, axis=1)
    bad = np.flatnonzero(per_pose > limit)
    outliers = [
        {
            "line": int(data.lines[i]),
            "chi2": float(per_pose[i]),
            "limit": float(limit),
            "rms_sigma": float(np.sqrt(per_pose[i] / k)),
        }
        for i in bad
    ]
    inlier = np.ones(problem.n, bool)
    inlier[bad] = False
    if not inlier.any():  # every pose outlying: the ratio over all of them, not over none
        inlier[:] = True
    dof = inlier.sum() * k - free.sum() - inlier.sum() * layout.nuisance
    inlier_ratio = float(np.sqrt(np.sum(per_pose[inlier]) / max(dof, 1)))
    if inlier_ratio > MAX_CHI2_RATIO or len(bad) > problem.n // 4:  # the reason, whether or not the solver stopped
        converged = False
        message = (
            f"residuals {inlier_ratio:.3g} times the stated noise after the fit ({len(bad)} of {problem.n} poses "
            "outlying): the model does not explain the data (wrong --type, units, convention or noise?)"
        )
    try:
        calibrated = layout.platform(theta, name=f"{nominal.name}-calibrated")
        fit_after = validation_errors(calibrated, layout.split(theta)[3], data, convention)
    except (GeometryError, ForwardKinematicsError) as e:  # the fit wandered off to no platform at all
        calibrated, fit_after = nominal, {}
        if converged:
            message = f"the fitted geometry is not a usable platform ({e})"
        converged = False
    result = CalibrationResult(
        nominal=nominal,
        calibrated=calibrated,
        layout=layout,
        noise=stated,
        convention=convention,
        theta0=theta0,
        theta=theta,
        sigma=sigma,
        identifiability=ident,
        converged=converged,
        message=message,
        nfev=int(nfev),
        rms_sigma_before=float(np.sqrt(np.mean(r0**2))),
        rms_sigma_after=rms_after,
        pose_rms_before=np.sqrt(np.mean(r0.reshape(problem.n, -1) ** 2, axis=1)),
        pose_rms_after=np.sqrt(per_pose / k),
        lines=data.lines,
        outliers=outliers,
        source=data.source,
        sha256=data.sha256,
    )
    result.fit_before = validation_errors(nominal, targets0, data, convention)
    result.fit_after = fit_after
    result.warnings = _warnings(result, copies, np.sum(per_pose[inlier]), dof, chi2)
    if converged:
        result.failures = _failures(result)
    return result
