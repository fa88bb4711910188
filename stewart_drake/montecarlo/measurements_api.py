"""``simulate_measurements`` (public as ``sd.simulate_measurements``): synthetic calibration measurements of a
machine drawn around the nominal. It sits in the montecarlo layer because the machine's errors are written in the
Monte Carlo ``--vary`` grammar (``montecarlo.spec``); the checks of ``simulate-measurements`` live here, once."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from stewart_drake.api.platform import nominal_geometry
from stewart_drake.api.result import Result
from stewart_drake.calibration.measurements import Measurements, measurements_csv
from stewart_drake.calibration.noise import parse_noise
from stewart_drake.calibration.simulate import simulate_measurements as measure
from stewart_drake.core.argcheck import as_int, as_poses, param
from stewart_drake.core.csvio import read_numeric_csv
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.rotations import pose_to_si
from stewart_drake.core.sanity import check_poses
from stewart_drake.errors import API_FILE_EXISTS, CalibrationError, OutputError
from stewart_drake.montecarlo.spec import parse_spec
from stewart_drake.spec import Machine

MAX_MEASURED_POSES = 10_000
GEOMETRIC_KEYS = ("anchor", "leg_offset")
DEFAULT_ERRORS = ("anchor=±1mm", "leg_offset=±0.5mm")
NOTE_LEG_OFFSET = (
    "leg_offset is what each sensor reads beyond the joint-to-joint length (as in montecarlo); "
    "the true legs.length_offset is the nominal's minus it"
)


# -- simulate-measurements ---------------------------------------------------------------------------------------
@dataclass(repr=False)
class MeasurementsResult(Result):
    """Synthetic calibration measurements of a machine drawn around the nominal (``simulate_measurements``).

    Attributes:
        measurements: the measurements (SI), written by ``to_csv`` as ``calibrate`` reads them.
        truth: the true machine that was measured (for checking a calibration only).
        info: the truth's parameters, the errors, noise and seed (the command's ``--json``).
    """

    measurements: Measurements
    truth: Platform
    info: dict

    def to_csv(self, path: str | Path, overwrite: bool = False) -> Path:
        """Write the measurements as a CSV (m, rad) that ``calibrate`` reads; a new file unless ``overwrite``."""
        p = Path(path)
        if p.exists() and not overwrite:
            raise OutputError(API_FILE_EXISTS.format(path=path))
        p.write_text(measurements_csv(self.measurements), encoding="utf-8")
        return p

    def _fields(self) -> dict:
        return self.info


def simulate_measurements(
    platform: str | Path | Platform | Machine,
    poses: str | Path | ArrayLike,
    *,
    errors: str | Sequence[str] = DEFAULT_ERRORS,
    noise: str | Sequence[str] = (),
    type: str = "pose",
    targets: int = 3,
    seed: int = 0,
    length_unit: str = "m",
    angle_unit: str = "rad",
    convention: str = "utn",
) -> MeasurementsResult:
    """Measure a machine drawn around the nominal (joint and sensor-offset errors in the Monte Carlo ``--vary``
    grammar) at the given poses with the given noise: data for checking a calibration, the truth kept apart.

    Args:
        platform: the nominal platform (a preset name, a platform file or a ``Platform``; a machine file or a
            ``Machine``: its platform, without the payload).
        poses: a CSV file ``px,py,pz,a,b,g`` (in ``length_unit``/``angle_unit``, e.g. a plan's poses) or an
            ``(n, 6)`` array (m, rad).
        errors: the machine's errors, keys ``anchor`` and ``leg_offset`` (default ±1 mm, ±0.5 mm).
        noise: measurement σ as ``key=value`` words (as for ``calibrate``).
        type: what is measured: ``"pose"``, ``"points"`` or ``"inclinometer"``.
        targets: ``type="points"``: targets on the plate (1 to 8).
        seed: seed of the machine and of the noise.
        length_unit: lengths in the poses file.
        angle_unit: angles in the poses file.
        convention: Euler convention of the poses.

    Returns:
        The measurements, the true machine and its parameters.

    Raises:
        StewartError: an error key that is not geometric, a pose outside the stroke (of the nominal, or of the
            machine drawn: errors too large for it to reach the poses), a bad file. A σ of 0 gives noise-free data.
    """
    platform = nominal_geometry(platform)
    spec = parse_spec(errors, where=param("errors"))
    bad = [k for k in spec.laws if k not in GEOMETRIC_KEYS]
    if bad:
        raise CalibrationError(CalibrationError.ERRORS_KEY.format(name=param("errors"), key=bad[0]))
    sigma = parse_noise(noise)
    targets, seed = as_int(targets, param("targets")), as_int(seed, param("seed"), 0, 2**63 - 1)
    if not 1 <= targets <= 8:
        raise CalibrationError(CalibrationError.TARGET_COUNT.format(name=param("targets"), value=targets))
    if isinstance(poses, (str, Path)):
        path = str(poses)
        too_many = CalibrationError(CalibrationError.POSE_COUNT.format(path=path, limit=MAX_MEASURED_POSES))
        raw, lines = read_numeric_csv(
            path, "poses", (6,), "px,py,pz,a,b,g", option="--poses", max_rows=MAX_MEASURED_POSES, too_many=too_many
        )
        if len(raw) > MAX_MEASURED_POSES:
            raise CalibrationError(CalibrationError.POSE_COUNT.format(path=path, limit=MAX_MEASURED_POSES))
        q = pose_to_si(raw, length_unit, angle_unit)
    else:
        path, q = "poses", as_poses(poses, param("poses"))
        lines = list(range(1, len(q) + 1))
        if len(q) > MAX_MEASURED_POSES:
            raise CalibrationError(CalibrationError.POSE_COUNT.format(path=path, limit=MAX_MEASURED_POSES))
    check_poses(platform, q, convention, what=f"{path}: pose", lines=lines)
    L = leg_lengths(platform, q, convention)
    out = np.argwhere((L < platform.L_min) | (L > platform.L_max))
    if out.size:
        r, leg = out[0]
        raise CalibrationError(
            CalibrationError.POSE_STROKE.format(
                path=path, line=lines[r], leg=leg + 1, length=L[r, leg], lmin=platform.L_min, lmax=platform.L_max
            )
        )
    data, truth = measure(platform, spec.laws, q, type, sigma, seed, convention, targets)
    L = leg_lengths(truth.platform, q, convention)
    out = (L < platform.L_min) | (L > platform.L_max)
    if out.any():
        r, leg = np.argwhere(out)[0]
        raise CalibrationError(
            CalibrationError.TRUTH_STROKE.format(
                errors=" ".join(errors) if not isinstance(errors, str) else errors,
                seed=seed,
                path=path,
                line=lines[r],
                leg=leg + 1,
                length=L[r, leg],
                lmin=platform.L_min,
                lmax=platform.L_max,
                count=int(out.any(axis=1).sum()),
                n=len(q),
                name=platform.name,
            )
        )
    info = {
        "platform": platform.name,
        "errors": spec.to_dict(),
        "noise": sigma.to_dict(),
        "seed": seed,
        "measurement_type": type,
        "convention": convention,
        "note": NOTE_LEG_OFFSET,
        **truth.to_dict(),
    }
    return MeasurementsResult(data, truth.platform, info)
