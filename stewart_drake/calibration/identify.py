"""Identification: robust nonlinear least squares of the calibration model on measured poses.

``identify`` fits θ (and the poses' own unknowns) with scipy's ``least_squares`` (trust-region reflective):
a first pass with the plain quadratic loss from the nominal, then a Huber pass (quadratic within
``HUBER_SIGMAS`` σ, linear beyond) so that an outlying pose pulls the fit no more than a few σ. The
parameters the data cannot identify (``identifiability``) stay at their nominal values. The covariance
of θ is (Σ A_kᵀ A_k)⁻¹ over the free parameters (``model.reduced_blocks``: the poses' unknowns
eliminated; residuals whitened by the stated noise), so σ is what the stated noise gives, not fitted.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares

from stewart_drake.calibration.identifiability import Identifiability, analyse, free_parameters, stacked
from stewart_drake.calibration.measurements import Measurements
from stewart_drake.calibration.model import (
    Layout,
    Noise,
    Problem,
    initial_targets,
    make_problem,
    pose_blocks,
    pose_residuals,
    reduced_blocks,
)
from stewart_drake.calibration.validate import validation_errors
from stewart_drake.core.geometry import Platform
from stewart_drake.errors import ForwardKinematicsError, GeometryError

HUBER_SIGMAS = 3.0
MAX_NFEV = 60  # evaluations per pass; Gauss–Newton converges in ~10 from ~1 mm errors (inclinometer data: ~30)
OUTLIER_P = 1e-3  # a pose whose residual a χ² test rejects at this level (Bonferroni over the poses) is named
MAX_CHI2_RATIO = 100.0  # residuals this many times the stated noise (RMS): the model does not fit the data


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
    stopped short or the fit leaves residuals far above the stated noise. ``gains``: identify each sensor's
    gain too (48 parameters on a 6-6)."""
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
    second = least_squares(
        fun,
        first.x,
        jac=jac,
        method="trf",
        loss="huber",
        f_scale=HUBER_SIGMAS,
        x_scale="jac",
        max_nfev=MAX_NFEV,
        xtol=1e-12,
        ftol=1e-12,
    )
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
    inlier_ratio = float(np.sqrt(np.sum(per_pose[inlier]) / max(inlier.sum() * k - free.sum(), 1)))
    if converged and (inlier_ratio > MAX_CHI2_RATIO or len(bad) > problem.n // 4):
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
        noise=noise,
        convention=convention,
        theta0=theta0,
        theta=theta,
        sigma=sigma,
        identifiability=ident,
        converged=converged,
        message=message,
        nfev=int(first.nfev + second.nfev),
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
    return result
