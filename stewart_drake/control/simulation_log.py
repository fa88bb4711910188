"""The logs of one controller-in-the-loop run and the verdict on them: numpy only, so that a log can be
read, saved and judged (tracking lost, a leg saturated too long) without Drake; ``drake.simulation`` fills
a ``SimulationLog`` from its Diagram's loggers."""

from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from stewart_drake.control.laws import STATUS
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.trajectory import Trajectory


@dataclass
class SimulationLog:
    """The logs of one run, numpy arrays in SI units.

    ``t`` (n,) plant-step times; ``pose`` (n, 6) measured plate pose (utn); ``lengths`` (n, 6) true leg
    lengths; ``command`` (n, 6) held controller output (N); ``setpoint`` (n, 6) held set-points (m);
    ``force`` (n, 6) actuator forces (N); ``status`` (n, len(STATUS)); ``t_ref`` (m,), ``reference``
    (m, 6) the pose reference at the controller's ticks.
    """

    kind: str
    platform: str
    trajectory: str
    sample_period: float
    t: np.ndarray
    pose: np.ndarray
    lengths: np.ndarray
    command: np.ndarray
    setpoint: np.ndarray
    force: np.ndarray
    status: np.ndarray
    t_ref: np.ndarray
    reference: np.ndarray

    ARRAYS = ("t", "pose", "lengths", "command", "setpoint", "force", "status", "t_ref", "reference")

    def tick_times(self) -> np.ndarray:
        """The controller's tick times read from the logged status (one per tick, in order)."""
        ticks = self.status[:, STATUS.index("ticks")].astype(int)
        times = self.status[:, STATUS.index("last_tick_time")]
        first = np.r_[True, np.diff(ticks) != 0] & (ticks > 0)
        return times[first]

    def saturations(self) -> np.ndarray:
        """``(6,)`` saturated ticks per leg over the run."""
        return self.status[-1, 4:10].copy()

    def length_error(self, trajectory: Trajectory, platform: Platform) -> np.ndarray:
        """``(n, 6)`` true leg length − the exact IK of the reference at the same time (m)."""
        return self.lengths - leg_lengths(platform, trajectory.pose(self.t))

    def pose_error(self, trajectory: Trajectory) -> np.ndarray:
        """``(n, 6)`` measured pose − reference pose at the same time (m, rad)."""
        return self.pose - trajectory.pose(self.t)

    def save(self, directory) -> list[Path]:
        """Write ``log.npz`` (every array) and ``log.csv`` (one row per plant step); return the paths."""
        d = Path(directory)
        d.mkdir(parents=True, exist_ok=True)
        npz = d / "log.npz"
        np.savez(
            npz,
            **{k: getattr(self, k) for k in self.ARRAYS},
            kind=self.kind,
            platform=self.platform,
            trajectory=self.trajectory,
            sample_period=self.sample_period,
        )
        header = (
            ["t"]
            + [f"pose_{c}" for c in ("px", "py", "pz", "ax", "ay", "az")]
            + [f"L{i}" for i in range(1, 7)]
            + [f"setpoint{i}" for i in range(1, 7)]
            + [f"command{i}" for i in range(1, 7)]
            + [f"force{i}" for i in range(1, 7)]
            + list(STATUS)
        )
        rows = np.concatenate(
            [self.t[:, None], self.pose, self.lengths, self.setpoint, self.command, self.force, self.status], axis=1
        )
        path = d / "log.csv"
        with path.open("w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(header)
            w.writerows([[repr(float(v)) for v in r] for r in rows])
        return [npz, path]


# Tracking is lost when a leg's length error or the plate's position error exceeds this fraction of the
# stroke range (20 mm on utn-dynamic's 0.4 m stroke; the seed run's error is ~1 mm).
TRACKING_LOST_FRACTION = 0.05
# A leg whose command stays saturated (at the command range) longer than this, in one stretch, has
# lost authority over its leg.
MAX_SATURATION_S = 0.05


def longest_saturation(log: SimulationLog) -> np.ndarray:
    """``(6,)`` the longest stretch (s) over which each leg's command was saturated on every tick."""
    ticks = log.status[:, STATUS.index("ticks")].astype(int)
    first = np.r_[True, np.diff(ticks) != 0] & (ticks > 0)
    counts = log.status[first][:, 4:10]
    sat = np.diff(np.vstack([np.zeros((1, 6)), counts]), axis=0) > 0  # (ticks, 6) saturated on that tick
    out = np.zeros(6)
    for j in range(6):
        s = np.r_[0, sat[:, j].astype(np.int8), 0]
        d = np.diff(s)
        starts, ends = np.flatnonzero(d == 1), np.flatnonzero(d == -1)
        out[j] = (ends - starts).max() * log.sample_period if len(starts) else 0.0
    return out


def tracking_verdict(platform: Platform, length_error, pose_error, log: SimulationLog) -> dict:
    """Whether a run tracked its reference: ``{"tracking_bound_mm", "saturation_bound_s",
    "longest_saturation_s" (6,), "tracking_lost": bool, "saturated_legs": [1-based legs], "failures":
    [messages]}``; a failure is a leg error or plate position error beyond ``TRACKING_LOST_FRACTION`` × the
    stroke range (lost tracking, with its first time), or a leg saturated for longer than ``MAX_SATURATION_S``
    in one stretch."""
    bound = TRACKING_LOST_FRACTION * float(platform.L_max - platform.L_min)
    failures, lost = [], False
    e = np.abs(np.asarray(length_error))
    pe = np.linalg.norm(np.asarray(pose_error)[:, :3], axis=1)
    for name, err, legwise in (("leg length", e, True), ("plate position", pe, False)):
        bad = (err > bound).reshape(len(err), -1).any(axis=1)
        if np.any(bad):
            lost = True
            i = int(np.argmax(bad))
            which = f" of leg {int(np.argmax(err[i])) + 1}" if legwise else ""
            failures.append(
                f"tracking lost: the {name} error{which} exceeds {bound * 1e3:.1f} mm ({TRACKING_LOST_FRACTION:g} × the stroke range) "
                f"first at t = {log.t[i]:.4f} s, and reaches {err.max() * 1e3:.1f} mm"
            )
    longest = longest_saturation(log)
    saturated = np.flatnonzero(longest > MAX_SATURATION_S)
    for j in saturated:
        failures.append(
            f"leg {j + 1} saturated for {longest[j]:.3f} s in one stretch (longer than {MAX_SATURATION_S:g} s): "
            "its actuator cannot follow the reference"
        )
    return {
        "tracking_bound_mm": bound * 1e3,
        "saturation_bound_s": MAX_SATURATION_S,
        "longest_saturation_s": longest.tolist(),
        "tracking_lost": lost,
        "saturated_legs": [int(j) + 1 for j in saturated],
        "failures": failures,
    }
