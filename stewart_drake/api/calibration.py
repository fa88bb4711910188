"""Kinematic calibration: ``calibrate`` identifies a built platform's geometry from measured poses,
``plan_measurements`` chooses the poses to measure (D-optimal), ``simulate_measurements`` measures a machine
drawn around the nominal (for checking a calibration). The checks of the commands ``calibrate``,
``plan-measurements`` and ``simulate-measurements`` live here, once."""

from __future__ import annotations

import datetime
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from stewart_drake.api.platform import nominal_geometry
from stewart_drake.api.result import Result
from stewart_drake.calibration.identify import CalibrationResult as Identified
from stewart_drake.calibration.identify import (
    copies_warning,
    distinct_poses,
    distinct_tolerance,
    identify,
    min_poses,
    validation_failures,
)
from stewart_drake.calibration.measurements import Measurements, read_measurements
from stewart_drake.calibration.model import Layout
from stewart_drake.calibration.noise import parse_noise
from stewart_drake.calibration.plan import MAX_POSES, Box, PlanResult, stw_program
from stewart_drake.calibration.plan import plan_measurements as plan_poses
from stewart_drake.calibration.validate import validation_errors
from stewart_drake.core.argcheck import as_int, param
from stewart_drake.core.geometry import CalibrationRecord, Platform
from stewart_drake.core.platform_file import platform_yaml
from stewart_drake.core.rotations import angle_scale, length_scale
from stewart_drake.errors import CalibrationError, UsageError
from stewart_drake.spec import Machine

MAX_CANDIDATES = 20_000


# -- calibrate ---------------------------------------------------------------------------------------------------
@dataclass(repr=False)
class CalibrateResult(Result):
    """An identified platform (``calibrate``).

    Attributes:
        platform: the calibrated platform (write it with ``Platform.to_yaml``, or with its ``calibration:``
            block by ``to_yaml`` here).
        nominal: the nominal platform it was identified from.
        identified: the identification (parameters, σ, identifiability, fit and validation residuals).
    """

    platform: Platform
    nominal: Platform
    identified: Identified

    @property
    def converged(self) -> bool:
        """Whether the least-squares identification converged (else nothing should be trusted)."""
        return bool(self.identified.converged)

    @property
    def ok(self) -> bool:
        """Converged and usable: corrections of a plausible size, forward kinematics that converges on the
        calibrated platform, a validation no worse than the nominal (the reasons otherwise in
        ``identified.failures``; what to know besides in ``identified.warnings``)."""
        return bool(self.identified.ok)

    def record(self) -> CalibrationRecord:
        """The ``calibration:`` block of the calibrated platform file (source, residuals, σ, date now)."""
        r = self.identified
        unit = {"pose": ("leg_length", "m"), "points": ("target", "m"), "inclinometer": ("tilt", "rad")}[r.layout.kind]
        v = r.validation
        vkey = "position" if r.layout.kind == "pose" else unit[0]
        return CalibrationRecord(
            source=r.source,
            sha256=r.sha256,
            date=datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
            measurement_type=r.layout.kind,
            poses=len(r.lines),
            residual_rms_before=r.fit_before[unit[0]]["rms"],
            residual_rms_after=r.fit_after[unit[0]]["rms"],
            residual_unit=unit[1],
            validation_rms_m=v["calibrated"][vkey]["rms"] if v and unit[1] == "m" else None,
            parameters=list(r.layout.names),
            sigma=[float(s * k) for s, k in zip(r.sigma, r.layout.scales())],
        )

    def platform_yaml(self) -> str:
        """The calibrated platform file's text, with its ``calibration:`` block (what ``calibrate`` writes)."""
        r = self.identified
        header = (
            f"{self.platform.name}: calibrated by stewart-drake calibrate from {r.source} "
            f"({len(r.lines)} {r.layout.kind} poses), nominal {self.nominal.name}."
        )
        return platform_yaml(self.platform, self.record(), header)

    def _fields(self) -> dict:
        return self.identified.to_dict()


def _split(data: Measurements, layout: Layout, holdout, validate, seed: int, length_unit: str, angle_unit: str):
    """``(fit, validation or None)``: a validation file, a seeded random holdout fraction, or neither."""
    if validate is not None:
        val = read_measurements(str(validate), layout.nominal, data.kind, length_unit, angle_unit)
        if val.n_targets != data.n_targets:
            raise CalibrationError(
                CalibrationError.VALIDATE_TARGETS.format(
                    path=validate, got=val.n_targets, fit=data.source, want=data.n_targets
                )
            )
        return data, val
    if holdout is None:
        return data, None
    if not 0 < holdout <= 0.5:
        raise CalibrationError(CalibrationError.HOLDOUT.format(value=holdout))
    n, need = len(data), min_poses(layout)
    held = max(1, int(round(holdout * n)))
    if n - held < need:
        raise CalibrationError(
            CalibrationError.HOLDOUT_TOO_FEW.format(value=holdout, held=held, n=n, left=n - held, need=need)
        )
    order = np.random.default_rng(seed).permutation(n)
    return data.subset(np.sort(order[held:])), data.subset(np.sort(order[:held]))


def calibrate(
    platform: str | Path | Platform | Machine,
    measurements: str | Path,
    *,
    type: str | None = None,
    length_unit: str = "m",
    angle_unit: str = "rad",
    holdout: float | None = None,
    validate: str | Path | None = None,
    seed: int = 0,
    gains: bool = False,
    noise: str | Sequence[str] = (),
    convention: str = "utn",
) -> CalibrateResult:
    """Identify a built platform's joint centres and leg-sensor offsets (and gains) from measured poses:
    robust least squares, the unidentifiable combinations named and held at nominal, σ per parameter from the
    stated noise, validation on held-out poses.

    Args:
        platform: the nominal platform (a preset name, a platform file or a ``Platform``; a machine file or a
            ``Machine``: its platform, without the payload).
        measurements: the measurement CSV (header ``l1..l6`` and the measured columns; see docs/calibration.md).
        type: ``"pose"``, ``"points"`` or ``"inclinometer"`` (default: from the header).
        length_unit: lengths in the CSV files.
        angle_unit: angles in the CSV files.
        holdout: hold out this fraction (0, 0.5] of the poses for validation (seeded by ``seed``).
        validate: a validation measurement file instead (same kind and units); not with ``holdout``.
        seed: seed of the ``holdout`` split.
        gains: identify each leg sensor's gain too.
        noise: measurement σ as ``key=value`` words (``length=1um position=10um angle=20urad``, the defaults).
        convention: Euler convention of the measured poses.

    Returns:
        The calibrated platform and the identification; check ``ok`` before using it. Rows that repeat an
        earlier row exactly count once (a warning); σ = 0 is weighed as ``NOISE_FLOOR`` (1e-9 m or rad).

    Raises:
        StewartError: an unreadable measurement file, too few distinct poses, a bad noise word or split.
    """
    if holdout is not None and validate is not None:
        raise UsageError(UsageError.NOT_BOTH.format(first="holdout (--holdout)", second="validate (--validate)"))
    nominal = nominal_geometry(platform)
    sigma = parse_noise(noise)
    rows = read_measurements(str(measurements), nominal, type, length_unit, angle_unit)
    data, copies = rows.without_copies()
    layout = Layout(nominal, data.kind, data.n_targets, gains)
    fit, val = _split(data, layout, holdout, validate, seed, length_unit, angle_unit)
    need, n = min_poses(layout), distinct_poses(fit, sigma)
    if n < need:
        words = {
            "path": measurements,
            "n": n,
            "equations": n * layout.rows(),
            "unknowns": layout.size + n * layout.nuisance,
            "parameters": layout.size,
            "nuisance": f" + {layout.nuisance} per pose" if layout.nuisance else "",
            "need": need,
        }
        if n == len(fit) and not copies:
            raise CalibrationError(CalibrationError.TOO_FEW.format(**words))
        tol = distinct_tolerance(sigma)
        raise CalibrationError(
            CalibrationError.TOO_FEW_DISTINCT.format(
                rows=len(fit) + len(copies), copies=len(copies), tol=f"{tol * 1e6:.3g} µm", **words
            )
        )
    result = identify(nominal, fit, sigma, convention, gains)
    if copies:
        result.warnings.insert(0, copies_warning(copies))
    if val is not None:
        targets0 = layout.split(result.theta0)[3]
        result.validation = {
            "poses": len(val),
            "lines": val.lines.tolist() if validate is None else None,
            "source": val.source,
            "nominal": validation_errors(nominal, targets0, val, convention),
            "calibrated": validation_errors(result.calibrated, result.targets, val, convention),
        }
        if result.converged:
            result.failures += validation_failures(result.validation)
    return CalibrateResult(result.calibrated, nominal, result)


# -- plan-measurements -------------------------------------------------------------------------------------------
@dataclass(repr=False)
class PlanMeasurementsResult(Result):
    """Planned calibration poses against random ones of the same count (``plan_measurements``).

    Attributes:
        poses: ``(n, 6)`` the planned poses, m and rad.
        random: ``(n, 6)`` the random baseline's poses.
        plan: the plan (both sets' identifiability, the box, the candidates' count).
    """

    poses: np.ndarray
    random: np.ndarray
    plan: PlanResult

    def program(self) -> str:
        """A motion program (``.stw``) that visits the planned poses."""
        return stw_program(self.poses, self.plan.platform)

    def _fields(self) -> dict:
        return self.plan.to_dict()


def plan_measurements(
    platform: str | Path | Platform | Machine,
    poses: int,
    *,
    type: str = "pose",
    workspace: ArrayLike | None = None,
    noise: str | Sequence[str] = (),
    targets: int = 3,
    gains: bool = False,
    candidates: int = 1000,
    seed: int = 0,
    length_unit: str = "m",
    angle_unit: str = "rad",
    convention: str = "utn",
) -> PlanMeasurementsResult:
    """Choose ``poses`` calibration poses that maximise the identification's D-index among random candidates in
    a box about home, and draw as many random ones from the same candidates for comparison.

    Args:
        platform: a preset name, a platform file or a ``Platform`` (a machine file or a ``Machine``: its
            platform, without the payload).
        poses: the number of poses to plan.
        type: the measurement to plan for: ``"pose"``, ``"points"`` or ``"inclinometer"``.
        workspace: ``(4,)`` the box about home: ±x ±y ±z (``length_unit``) and ±rotation per angle
            (``angle_unit``); default ±30 % of the stroke range in x, y, ±20 % in z, ±20°.
        noise: σ as for ``calibrate`` (weights the rows).
        targets: ``type="points"``: targets on the plate (1 to 8).
        gains: plan for identifying the sensor gains too.
        candidates: candidate poses drawn (at least twice ``poses``).
        seed: seed of the candidates and of the random baseline.
        length_unit: lengths of ``workspace``.
        angle_unit: angle of ``workspace``.
        convention: Euler convention of the poses.

    Returns:
        The planned and random poses and both sets' identifiability.

    Raises:
        StewartError: counts out of range, too few poses for the unknowns, a box that is not positive.
    """
    platform = nominal_geometry(platform)
    poses, candidates, targets = (
        as_int(v, param(n)) for v, n in ((poses, "poses"), (candidates, "candidates"), (targets, "targets"))
    )
    if not 1 <= poses <= MAX_POSES:
        raise CalibrationError(CalibrationError.POSES.format(name=param("poses"), value=poses, lo=1, hi=MAX_POSES))
    if not 1 <= candidates <= MAX_CANDIDATES or candidates < 2 * poses:
        raise CalibrationError(
            CalibrationError.CANDIDATE_COUNT.format(
                name=param("candidates"),
                poses=param("poses"),
                value=candidates,
                lo=max(2 * poses, 1),
                hi=MAX_CANDIDATES,
            )
        )
    if not 1 <= targets <= 8:
        raise CalibrationError(CalibrationError.TARGET_COUNT.format(name=param("targets"), value=targets))
    layout = Layout(platform, type, targets if type == "points" else 0, gains)
    if poses < min_poses(layout):
        raise CalibrationError(
            CalibrationError.PLAN_TOO_FEW.format(
                value=poses,
                kind=type,
                need=min_poses(layout),
                name=platform.name,
                unknowns=f"{layout.size} + {layout.nuisance} per pose" if layout.nuisance else layout.size,
                per=layout.rows(),
            )
        )
    box = None
    if workspace is not None:
        w = list(workspace)
        if len(w) != 4 or not all(v > 0 for v in w):
            raise CalibrationError(
                CalibrationError.WORKSPACE.format(value=" ".join(str(v) for v in w), unit=length_unit, angle=angle_unit)
            )
        k, a = length_scale(length_unit), angle_scale(angle_unit)
        box = Box(w[0] * k, w[1] * k, w[2] * k, w[3] * a)
    plan = plan_poses(platform, poses, type, box, parse_noise(noise), seed, convention, candidates, targets, gains)
    return PlanMeasurementsResult(plan.poses, plan.random, plan)


def poses_csv(poses) -> str:
    """``px,py,pz,a,b,g`` rows in m and rad (what ``simulate-measurements --poses`` and ``ik --poses`` read)."""
    return "px,py,pz,a,b,g\n" + "".join(",".join(repr(float(v)) for v in q) + "\n" for q in np.asarray(poses))
