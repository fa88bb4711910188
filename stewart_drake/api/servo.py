"""The RC-servo hexapod (seed 002) as a function: ``servo`` gives the arm angles and PWM pulse widths that hold
a pose, with the reach and travel checks."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from stewart_drake.api.result import Result
from stewart_drake.core.argcheck import as_flag, as_real_array, check_path, check_shape, param
from stewart_drake.core.sanity import check_finite, check_servo_neutrals, check_servo_pose
from stewart_drake.core.sdf_models import write_sdf as write_sdf_file
from stewart_drake.errors import API_POSE_SHAPE, OPTION_SERVO_POSE, ArgumentError, ServoPoseError, UsageError
from stewart_drake.mechanisms.servo import ServoHexapod, load_servo_hexapod, solve

__all__ = ["servo", "ServoResult"]

US = 1e-6  # seconds per microsecond: the servos' pulses are written in µs at the command line


@dataclass(repr=False)
class ServoResult(Result):
    """Arm angles and pulse widths of the RC-servo hexapod for one pose (``servo``).

    Attributes:
        platform: the servo hexapod's name.
        pose: ``(6,)`` the pose solved, ``[x, y, z, phi, theta, psi]`` (m, rad), R = Rz(psi)·Ry(theta)·Rx(phi).
        home_height: h0, the platform origin's height at home, m.
        home_angles: ``(6,)`` the arm angles at home alpha0_i, rad.
        angles: ``(6,)`` the arm angles alpha_i, rad (the nearest angle where a servo cannot reach).
        pulse: ``(6,)`` the commanded pulse widths, s (``pulse_raw`` clamped to the travel).
        pulse_raw: ``(6,)`` the pulse widths without the travel limit, s.
        violations: ``{"servo", "kind": "unreachable", "ratio"}`` or ``{"servo", "kind": "travel", "angle",
            "limit", "excess"}`` (rad) per servo that cannot hold the pose.
        sdf_file: the SDF written (``write_sdf``), else None.
    """

    platform: str
    pose: np.ndarray
    home_height: float
    home_angles: np.ndarray
    angles: np.ndarray
    pulse: np.ndarray
    pulse_raw: np.ndarray
    violations: list
    sdf_file: Path | None = None

    @property
    def ok(self) -> bool:
        """Every servo reaches the pose and stays within its travel."""
        return not self.violations

    def _fields(self) -> dict:
        out = {
            "preset": self.platform,
            "pose": self.pose,
            "convention": "zyx",
            "home_height": self.home_height,
            "alpha0": self.home_angles,
            "angles": self.angles,
            "pulse": self.pulse,
            "pulse_raw": self.pulse_raw,
            "ok": self.ok,
            "violations": self.violations,
        }
        if self.sdf_file is not None:
            out["sdf_file"] = str(self.sdf_file)
        return out


def servo(
    pose: ArrayLike | None = None,
    *,
    platform: str | Path = "hobby-servo",
    from_home: bool = False,
    trim: ArrayLike | None = None,
    write_sdf: str | Path | None = None,
) -> ServoResult:
    """Arm angles and pulse widths that hold ``pose`` on an RC-servo hexapod (seed 002), checked for reach and
    travel.

    Args:
        pose: ``(6,)`` ``[x, y, z, phi, theta, psi]`` in metres and radians (R = Rz(psi)·Ry(theta)·Rx(phi));
            None: home.
        platform: a servo hexapod preset (``"hobby-servo"``) or a servo hexapod YAML file.
        from_home: ``z`` is the offset from the home height h0.
        trim: ``(6,)`` per-servo neutral pulses W0_i, s (default: the platform's, 1500 µs).
        write_sdf: also write the hexapod's SDF into this folder.

    Returns:
        The angles, pulses and the servos that cannot hold the pose (``ok`` False then).

    Raises:
        StewartError: an unknown platform, a pose or trim that is not finite, a trim that leaves no room for
            the travel, an SDF folder that cannot be written.
    """
    if trim is not None:
        trim = check_finite(check_shape(trim, "trim", (6,)), "trim (s)")
    trim_us = None if trim is None else trim / US
    return solve_servo(platform, pose, from_home=from_home, trim_us=trim_us, write_sdf=write_sdf)


def solve_servo(platform, pose, *, from_home=False, trim_us=None, write_sdf=None, what="pose") -> ServoResult:
    """``servo`` with the trim in µs (as ``stewart-drake servo --trim`` takes it, so that its errors show the
    value typed) and ``what``, the name errors give the pose."""
    named = isinstance(platform, (str, os.PathLike)) and "\0" not in os.fspath(platform)
    if not named and not isinstance(platform, ServoHexapod):
        raise ArgumentError(ArgumentError.NOT_PLATFORM.format(name="platform", value=repr(platform)[:80]))
    hexapod = load_servo_hexapod(platform)
    from_home = as_flag(from_home, param("from_home"))
    check_servo_neutrals(hexapod, f"{platform}: servo.neutral_us")
    if trim_us is not None:
        trim_us = check_finite(check_shape(trim_us, param("trim"), (6,)), f"{param('trim')} (µs)")
        check_servo_neutrals(hexapod.replace(neutral_us=trim_us), param("trim"))
        hexapod = hexapod.replace(neutral_us=trim_us)
    sdf_file = (
        None
        if write_sdf is None
        else write_sdf_file(hexapod, check_path(write_sdf, param("write_sdf")), option=param("write_sdf"))
    )
    if pose is None:
        q = np.zeros(6) if from_home else hexapod.home_pose()
    else:
        q = np.array(as_real_array(pose, what), dtype=float)
        if q.shape != (6,):
            raise UsageError(API_POSE_SHAPE.format(what=what, shape=q.shape))
        if not np.all(np.isfinite(q)):
            raise ServoPoseError(OPTION_SERVO_POSE.format(value=q.tolist()).replace("--pose", what, 1))
    if from_home:
        q[2] += hexapod.home_height
    check_servo_pose(hexapod, q, what)  # far away: a unit mistake (exit 2), not "unreachable"
    sol = solve(hexapod, q)
    violations = []
    for v in sol.violations():
        d = {k: x for k, x in v.items() if k != "pose"}
        for k in ("angle", "limit", "excess"):
            if f"{k}_deg" in d:
                d[k] = float(np.radians(d.pop(f"{k}_deg")))
        violations.append(d)
    return ServoResult(
        hexapod.name,
        q,
        hexapod.home_height,
        np.asarray(hexapod.home_angles),
        np.asarray(sol.angles),
        np.asarray(sol.pulse) * US,
        np.asarray(sol.pulse_raw) * US,
        violations,
        sdf_file,
    )
