"""Pose references: one ``Trajectory`` type for the closed-form references (the seed's, a rotating one),
sampled tables (a CSV of t, pose rows) and motion programs (their quintic segments and samples).

A trajectory's ``pose(t)`` maps times ``(...)`` (s) to poses ``(..., 6)`` (metres, radians, ``utn``
convention). The closed-form ones also give exact rates (``derivatives``); a motion program's also carries
its samples (``t``, ``q``, ``qd``, ``qdd``) and segments. Pose functions are module-level functions or
``functools.partial`` of them, so that a trajectory pickles (a Monte Carlo worker receives its scenario).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import numpy as np

from stewart_drake.core.argcheck import as_flag, as_real, check_path
from stewart_drake.core.csvio import read_numeric_csv
from stewart_drake.core.dynamics import harmonic_trajectory, seed_trajectory
from stewart_drake.core.geometry import Platform, check_platform
from stewart_drake.core.quantisation import check_finite_rates, check_quantisation, smooth_columns, smooth_tolerance
from stewart_drake.core.rotations import pose_to_si
from stewart_drake.errors import API_FIT_PLATFORM, TrajectoryError


@dataclass(frozen=True, eq=False)
class Trajectory:
    """A pose reference.

    ``fn``: times ``(...)`` s → poses ``(..., 6)``; ``duration``: the natural length in seconds (None:
    unbounded); ``exact``: times → ``(q, qd, qdd)``, each ``(..., 6)``, the exact pose and its rates (None:
    not known in closed form). A motion program's trajectory also holds its samples: ``t`` (n,) s; ``q``,
    ``qd``, ``qdd`` (n, 6); ``segment`` (n,) the index into ``segments`` of the piece each sample ends (−1:
    the start pose).
    """

    name: str
    fn: Callable
    duration: float | None = None
    exact: Callable | None = None
    t: np.ndarray | None = None
    q: np.ndarray | None = None
    qd: np.ndarray | None = None
    qdd: np.ndarray | None = None
    segment: np.ndarray | None = None
    segments: tuple = ()

    def pose(self, t) -> np.ndarray:
        """``(..., 6)`` poses at times ``(...)`` (s)."""
        return self.fn(np.asarray(t, dtype=float))

    def pose_at(self, t) -> np.ndarray:
        """``pose`` under the name a motion program's trajectory uses."""
        return self.pose(t)

    def derivatives(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(q, qd, qdd)`` at times ``(...)``, each ``(..., 6)``, exact; ValueError if not known."""
        if self.exact is None:
            raise TrajectoryError(TrajectoryError.NO_RATES.format(name=self.name))
        return self.exact(np.asarray(t, dtype=float))

    @property
    def moves(self) -> list:
        """The program's ``move`` segments, in order."""
        return [s for s in self.segments if s.kind == "move"]

    # -- constructors (the public API's: ``sd.Trajectory.seed(...)``, ...) ---------------------------
    @classmethod
    def seed(cls, platform: Platform | None = None, fit: bool = False) -> Trajectory:
        """The seed's reference: px = −0.1 m, py = 0.1 sin(2t) m, pz = 0.7 m, no rotation, 4 s.

        Args:
            platform: with ``fit``, the platform whose home and stroke the reference is moved to.
            fit: move and scale the reference (made for utn-dynamic) to ``platform`` (the CLI's ``--fit``).

        Returns:
            The reference (exact rates unless fitted).
        """
        return _fitted(SEED, platform, fit)

    @classmethod
    def rotating(cls, platform: Platform | None = None, fit: bool = False) -> Trajectory:
        """A rotating reference: pz = 0.7 m, turning 15°·sin(2t) about Z while tilting 5°·sin(3t) about X, 4 s.

        Args:
            platform: with ``fit``, the platform whose home and stroke the reference is moved to.
            fit: move and scale the reference (made for utn-dynamic) to ``platform`` (the CLI's ``--fit``).

        Returns:
            The reference (exact rates unless fitted).
        """
        return _fitted(ROTATING, platform, fit)

    @classmethod
    def from_csv(
        cls, path: str | Path, length_unit: str = "m", angle_unit: str = "rad", smooth: float | None = None
    ) -> Trajectory:
        """A table of ``t, px, py, pz, a, b, g`` rows (header optional; times increasing), interpolated linearly.

        Args:
            path: the CSV file.
            length_unit: unit of its positions (``"m"`` or ``"mm"``).
            angle_unit: unit of its angles (``"rad"``, ``"deg"`` or ``"pi"``).
            smooth: replace the samples by a smoothing spline's within this RMS tolerance (the file's units);
                without it, a file rounded so coarsely that its second differences are noise is refused.

        Returns:
            The reference, named after the file.

        Raises:
            StewartError: the file's first bad line, named; a noise-dominated file without ``smooth``.
        """
        return load_trajectory_csv(check_path(path, "path"), length_unit, angle_unit, smooth)

    @classmethod
    def from_program(
        cls, path: str | Path, platform: Platform, rate: float = 100.0, convention: str = "utn"
    ) -> Trajectory:
        """The trajectory of a motion program (``.stw``), sampled at ``rate``, with its samples and moves.

        Args:
            path: the program file.
            platform: the platform it runs on (its home pose and stroke).
            rate: samples per second.
            convention: Euler convention of the program's angles.

        Returns:
            The reference, named after the file.

        Raises:
            StewartError: the program's first error (``ScriptError``: file, line and column).
        """
        # deferred: the motion language's interpreter imports this module (its trajectories are Trajectory)
        from stewart_drake.script import run_program
        from stewart_drake.script.source import read_program

        path, platform, rate = check_path(path, "path"), check_platform(platform), as_real(rate, "rate")
        result = run_program(read_program(path), path, platform, rate=rate, convention=convention)
        return dataclasses.replace(result.trajectory, name=Path(path).stem)


def _seed_pose(t):
    return seed_trajectory(t)[0]


# The rotating reference: the plate at pz = 0.7 m turning about Z by 15°·sin(2t) while tilting 5°·sin(3t) about X.
_ROTATING = (
    [0.0, 0.0, 0.7, 0.0, 0.0, 0.0],
    [0.0, 0.0, 0.0, np.radians(5.0), 0.0, np.radians(15.0)],
    [0.0, 0.0, 0.0, 3.0, 0.0, 2.0],
)


def _rotating_exact(t):
    return harmonic_trajectory(t, *_ROTATING)


def _rotating_pose(t):
    return _rotating_exact(t)[0]


# SPEC §3: px = −0.1 m, py = 0.1·sin(2t) m, pz = 0.7 m, no rotation.
SEED = Trajectory("seed", _seed_pose, 4.0, seed_trajectory)
ROTATING = Trajectory("rotating", _rotating_pose, 4.0, _rotating_exact)
TRAJECTORIES = {"seed": SEED, "rotating": ROTATING}


def _fitted(trajectory: Trajectory, platform: Platform | None, fit: bool) -> Trajectory:
    if not as_flag(fit, "fit"):
        return trajectory
    if platform is not None:
        check_platform(platform)
    if platform is None:
        raise TrajectoryError(API_FIT_PLATFORM)
    return fit_trajectory(trajectory, platform)


def fit_trajectory(
    trajectory: Trajectory, platform: Platform, home_height: float = 0.7, stroke: float = 0.4
) -> Trajectory:
    """``trajectory`` (made for a platform whose home is pz = ``home_height`` with a stroke of ``stroke``
    metres, as ``SEED`` and ``ROTATING`` are for utn-dynamic) moved to ``platform``'s home and its
    positions scaled by the ratio of the strokes (angles unchanged): the same motion, relative to the
    platform's size."""
    s = (platform.stroke[1] - platform.stroke[0]) / stroke
    centre = np.array([0.0, 0.0, home_height])
    home = platform.home_pose()[:3]
    return Trajectory(trajectory.name, partial(_fitted_pose, trajectory, home, s, centre), trajectory.duration)


def _fitted_pose(trajectory: Trajectory, home, s: float, centre, t):
    q = trajectory.pose(t).copy()
    q[..., :3] = home + s * (q[..., :3] - centre)
    return q


# bytes a command holds per trajectory sample beyond the CSV row (the Drake run's logs and plots)
BYTES_PER_SAMPLE = 700.0


def read_trajectory_table(
    path, length_unit: str = "m", angle_unit: str = "rad", *, option: str = "--trajectory"
) -> tuple[str, np.ndarray, np.ndarray]:
    """``(name, times (n,) s, poses (n, 6) SI)`` of a ``(t, px, py, pz, a_x, a_y, a_z)`` CSV (header row
    optional; times strictly increasing, seconds), read once as a stream (``csvio``). Errors name the line."""
    data, lines = read_numeric_csv(
        path, "trajectory", (7,), "t, px, py, pz, a_x, a_y, a_z", option=option, bytes_per_row=BYTES_PER_SAMPLE
    )
    late = np.flatnonzero(np.diff(data[:, 0]) <= 0)
    if late.size:
        k = late[0] + 1
        raise TrajectoryError(
            TrajectoryError.TIME_ORDER.format(path=path, line=lines[k], t=data[k, 0], t_prev=data[k - 1, 0])
        )
    return Path(path).stem, data[:, 0], pose_to_si(data[:, 1:], length_unit, angle_unit)


def load_trajectory_csv(path, length_unit: str = "m", angle_unit: str = "rad", smooth=None) -> Trajectory:
    """A trajectory CSV (``read_trajectory_table``: read once as a stream, errors name the line) as a
    piecewise-linear Trajectory (``table_trajectory``). A file rounded so coarsely that its second differences
    are noise is refused (``quantisation``) unless ``smooth`` (a tolerance in the file's units) replaces the
    samples by a smoothing spline's."""
    name, t, poses = read_trajectory_table(path, length_unit, angle_unit)
    check_finite_rates(path, t, poses)
    if smooth is None:
        check_quantisation(path, t, poses)
    else:
        scale = pose_to_si(np.ones(6), length_unit, angle_unit)
        poses = smooth_columns(t, poses, smooth_tolerance(smooth) * scale)
    return table_trajectory(name, t, poses)


def table_trajectory(name: str, ts, poses) -> Trajectory:
    """Samples ``ts`` (n,) s, ``poses`` (n, 6) SI as a piecewise-linear Trajectory, held constant after the
    last sample and continued before the first along the first segment: the differences that start a run
    at t = 0 (``control.initial_leg_forces``, the plant's initial velocity) then see the reference's initial
    velocity, not a kink from a pose held before t = 0 (a clamp there read as an acceleration of v/h and
    threw the plate)."""
    ts, poses = np.asarray(ts, dtype=float), np.asarray(poses, dtype=float)
    slope = (poses[1] - poses[0]) / (ts[1] - ts[0]) if len(ts) > 1 else np.zeros(6)
    return Trajectory(name, partial(_table_pose, ts, poses, slope), float(ts[-1]))


def _table_pose(ts, poses, slope, t):
    t = np.asarray(t, dtype=float)
    q = np.stack([np.interp(t, ts, poses[:, j]) for j in range(6)], axis=-1)
    before = (t < ts[0])[..., None]
    return np.where(before, poses[0] + (t - ts[0])[..., None] * slope, q)


def constant_trajectory(name: str, pose, duration: float | None = None) -> Trajectory:
    """The plate held at ``pose`` (6,) for all times."""
    return Trajectory(name, partial(_constant_pose, np.asarray(pose, dtype=float).reshape(6)), duration)


def _constant_pose(pose, t):
    return np.broadcast_to(pose, np.shape(t) + (6,)).copy()


def design_poses(trajectory: Trajectory, duration: float | None = None, n: int = 64) -> np.ndarray:
    """``(n, 6)`` poses of ``trajectory`` evenly spread over [0, ``duration``] (default the trajectory's
    duration, else 4 s): what the default gain design (``control.design_gains``) takes as the poses the
    loop will visit (the struts' stiffness and the leg-space masses vary along the way)."""
    d = duration if duration is not None else (trajectory.duration or 4.0)
    if not (math.isfinite(d) and d >= 0):
        raise TrajectoryError(TrajectoryError.DESIGN_DURATION.format(value=d))
    return trajectory.pose(np.linspace(0.0, d, n))


def get_trajectory(name_or_path, **units) -> Trajectory:
    """``seed``, ``rotating`` or a CSV file path (``units``: ``length_unit``, ``angle_unit`` of the CSV)."""
    if isinstance(name_or_path, Trajectory):
        return name_or_path
    s = str(name_or_path)
    if s in TRAJECTORIES:
        return TRAJECTORIES[s]
    if s.endswith(".csv") or Path(s).exists():
        return load_trajectory_csv(s, **units)
    raise TrajectoryError(TrajectoryError.UNKNOWN.format(value=s, valid=", ".join(TRAJECTORIES)))
