"""Inverse dynamics along a trajectory: the six leg forces that move the plate (and optionally the legs)."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicSpline

from stewart_drake.api.result import Result
from stewart_drake.core.argcheck import as_flag, as_real, check_path, param
from stewart_drake.core.csvio import read_numeric_csv
from stewart_drake.core.dynamics import leg_forces, leg_forces_with_legs, seed_trajectory
from stewart_drake.core.geometry import Platform, check_platform
from stewart_drake.core.quantisation import check_finite_rates, check_quantisation, smooth_tolerance, smoothing_spline
from stewart_drake.core.rotations import angle_scale, check_convention, length_scale
from stewart_drake.core.sanity import (
    check_finite,
    check_gravity,
    check_trajectory,
    check_work,
    fmt_value,
    require_plate,
)
from stewart_drake.core.trajectory import Trajectory
from stewart_drake.core.unit_hint import other_unit_hint
from stewart_drake.errors import CsvError, OptionError, PhysicalLimitError, UsageError

# Memory per trajectory sample while computing forces ((6, 6) Jacobians, mass matrices and their
# temporaries) and the most samples one run takes (~10 s of vectorised inverse dynamics).
BYTES_PER_SAMPLE = 4000
MAX_SAMPLES = 10_000_000


@dataclass(repr=False)
class DynamicsResult(Result):
    """Leg forces along a trajectory (``inverse_dynamics``).

    Attributes:
        t: ``(n,)`` sample times, s.
        forces: ``(n, 6)`` leg forces, N (> 0 pushes the plate away from the base).
        platform: the platform's name.
        trajectory: the trajectory's name (or the CSV path).
        coriolis: the Coriolis and centripetal terms are included.
        legs: the legs' masses are included.
        gravity: m/s².
        warnings: stroke warnings (with ``allow_out_of_stroke``).
        read_units: a CSV's units as read (``{"length": ..., "angle": ...}``); None for other trajectories.
    """

    t: np.ndarray
    forces: np.ndarray
    platform: str
    trajectory: str
    coriolis: bool
    legs: bool
    gravity: float
    warnings: list
    read_units: dict | None = None

    @property
    def max_abs_force(self) -> np.ndarray:
        """``(6,)`` the largest |force| of each leg, N."""
        return np.abs(self.forces).max(axis=0)

    def _fields(self) -> dict:
        return {
            "platform": self.platform,
            "trajectory": self.trajectory,
            "coriolis": self.coriolis,
            "legs": self.legs,
            "gravity": self.gravity,
            "read_units": self.read_units,
            "unit": "N",
            "t": self.t,
            "forces": self.forces,
            "max_abs_force": self.max_abs_force,
            "warnings": self.warnings,
        }


def inverse_dynamics(
    platform: Platform,
    trajectory: str | Path | Trajectory = "seed",
    legs: bool = False,
    coriolis: bool = True,
    gravity: float = 9.81,
    *,
    t_end: float | None = None,
    dt: float = 0.1,
    convention: str = "utn",
    length_unit: str = "m",
    angle_unit: str = "rad",
    allow_out_of_stroke: bool = False,
    smooth: float | None = None,
    on_warning: Callable[[str], None] | None = None,
) -> DynamicsResult:
    """The leg forces that move the plate along a trajectory (rigid-body inverse dynamics).

    Args:
        platform: the platform (it must have plate mass properties).
        trajectory: ``"seed"``, a CSV file (7 columns t, pose: rates by a cubic spline; or 19 columns
            t, q, q̇, q̈), or a `Trajectory` (a motion program's own samples; otherwise, or with ``t_end``,
            sampled every ``dt`` seconds up to ``t_end``).
        legs: include the legs' masses (needs ``coriolis``).
        coriolis: include C(q, q̇) q̇ (False: the seed's model).
        gravity: m/s².
        t_end: last sample time, s (default 4 for the seed, else the trajectory's duration).
        dt: sample step, s (seed and `Trajectory`).
        convention: Euler convention of a CSV's angles.
        length_unit: unit of a CSV's positions (``"m"`` or ``"mm"``).
        angle_unit: unit of a CSV's angles (``"rad"``, ``"deg"`` or ``"pi"``).
        allow_out_of_stroke: compute forces where a leg leaves the stroke (a warning) instead of raising.
        smooth: a 7-column CSV is differentiated through a smoothing spline within this RMS tolerance (the
            file's units) of its samples; without it, a file rounded so coarsely that its second differences
            are noise is refused.
        on_warning: called with each warning as it is found.

    Returns:
        The sample times and the forces.

    Raises:
        StewartError: a platform without plate mass, bad samples or options; ``PhysicalLimitError`` when the
            trajectory leaves the stroke (unless allowed).
    """
    check_platform(platform)
    require_plate(platform, "dynamics")
    gravity = check_gravity(gravity)
    legs, coriolis = as_flag(legs, param("legs")), as_flag(coriolis, param("coriolis"))
    allow_out_of_stroke = as_flag(allow_out_of_stroke, param("allow_out_of_stroke"))
    check_convention(convention)
    smooth = None if smooth is None else as_real(smooth, param("smooth"))
    if not isinstance(trajectory, Trajectory):
        trajectory = check_path(trajectory, param("trajectory"))
    read_units = None
    if isinstance(trajectory, Trajectory) and trajectory.t is not None and t_end is None:  # a program's samples
        t, q, qd, qdd = trajectory.t, trajectory.q, trajectory.qd, trajectory.qdd
        convention, name, what = "utn", trajectory.name, f"trajectory {trajectory.name}"
    elif isinstance(trajectory, Trajectory):
        times = sample_times(trajectory.duration if t_end is None else t_end, dt)
        t, (q, qd, qdd), convention, name = times, trajectory_rates(trajectory, times), "utn", trajectory.name
        what = f"trajectory {name}"
    elif str(trajectory) == "seed":
        t = sample_times(4.0 if t_end is None else t_end, dt)
        (q, qd, qdd), convention, name, what = seed_trajectory(t), "utn", "seed", "the seed trajectory"
    else:
        t, q, qd, qdd = read_trajectory_csv(str(trajectory), length_unit, angle_unit, smooth)
        name, what = str(trajectory), f"trajectory {trajectory}"
        read_units = {"length": length_unit, "angle": angle_unit}
    try:
        warnings = check_trajectory(platform, t, q, convention, what, allow_out_of_stroke)
    except PhysicalLimitError as e:  # a CSV in the other unit than it was read in says so
        hint = "" if read_units is None else other_unit_hint(platform, q, length_unit, angle_unit, convention)
        raise PhysicalLimitError(str(e) + hint) from None
    for w in warnings:
        if on_warning:
            on_warning(w)
    if legs:
        if not coriolis:
            raise UsageError(UsageError.LEGS_CORIOLIS)
        F = leg_forces_with_legs(platform, q, qd, qdd, convention, gravity=gravity)
    else:
        F = leg_forces(platform, q, qd, qdd, convention, coriolis=coriolis, gravity=gravity)
    return DynamicsResult(t, F, platform.name, name, bool(coriolis), bool(legs), gravity, warnings, read_units)


def trajectory_rates(trajectory: Trajectory, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(q, q̇, q̈)`` of ``trajectory`` at times ``t`` (n,): exact where known, else a cubic spline through
    its poses at ``t``."""
    if trajectory.exact is not None:
        return trajectory.exact(t)
    spline = CubicSpline(t, trajectory.pose(t), axis=0)
    return spline(t), spline(t, 1), spline(t, 2)


def read_trajectory_csv(path: str, length_unit: str = "m", angle_unit: str = "rad", smooth=None):
    """``(t, q, qd, qdd)`` in SI units from a trajectory CSV (7 or 19 columns). Errors name the line. Poses
    alone are differentiated by a cubic spline, or by a smoothing spline within ``smooth`` (the file's
    units) RMS of the samples; a file whose second differences are rounding noise is refused without it. The
    file is read once as a stream (a FIFO works) within the memory budget."""
    a, _ = read_numeric_csv(
        path,
        "trajectory",
        (7, 19),
        "t, px, py, pz, a, b, g [, their 6 rates, their 6 accelerations]",
        option=param("trajectory"),
        bytes_per_row=BYTES_PER_SAMPLE + 600,
    )
    width = a.shape[1]
    if len(a) < (2 if width == 19 else 4):
        raise CsvError(CsvError.TOO_FEW.format(path=path, need=2 if width == 19 else 4, got=len(a)))
    t = a[:, 0]
    if np.any(np.diff(t) <= 0):
        k = int(np.argmax(np.diff(t) <= 0))
        raise CsvError(CsvError.TIMES.format(path=path, k=k + 1, t=t[k + 1], t_prev=t[k]))
    scale = np.r_[np.full(3, length_scale(length_unit)), np.full(3, angle_scale(angle_unit))]
    if width == 19:
        return t, a[:, 1:7] * scale, a[:, 7:13] * scale, a[:, 13:19] * scale
    check_finite_rates(path, t, a[:, 1:7] * scale)
    if smooth is not None:
        f = smoothing_spline(t, a[:, 1:7] * scale, smooth_tolerance(smooth) * scale)
        return t, f(t), f(t, 1), f(t, 2)
    check_quantisation(path, t, a[:, 1:7] * scale)
    spline = CubicSpline(t, a[:, 1:7] * scale, axis=0)
    return t, spline(t), spline(t, 1), spline(t, 2)


def sample_times(t_end: float, dt: float) -> np.ndarray:
    """``(n,)`` sample times 0, dt, ... t_end (s), after checking that both are finite and the sample count
    fits the memory and sample budget (before allocating)."""
    names = {"dt_name": param("dt"), "t_end_name": param("t_end")}
    t_end, dt = as_real(t_end, names["t_end_name"]), as_real(dt, names["dt_name"])
    check_finite(t_end, f"{names['t_end_name']} (s)")
    check_finite(dt, f"{names['dt_name']} (s)")
    if not (dt > 0 and t_end >= 0):
        raise OptionError(OptionError.DT.format(dt=fmt_value(dt), t_end=fmt_value(t_end), **names))
    n = math.floor(t_end / dt + 0.5) + 1
    check_work(
        f"{names['t_end_name']}/{names['dt_name']}",
        f"{fmt_value(t_end)}/{fmt_value(dt)} s",
        n,
        "samples",
        BYTES_PER_SAMPLE,
        MAX_SAMPLES,
        hint=f"; use a larger {names['dt_name']} or a shorter {names['t_end_name']}",
    )
    return np.arange(0.0, t_end + dt / 2, dt)
