"""How well a platform's motion cues a vehicle's, as a person perceives them.

Both drives go through the vestibular models (``vestibular.perceive``) and are compared per head channel
(``fx fy fz`` specific force, ``wx wy wz`` angular velocity):

- ``rmse`` (m/s², rad/s) and ``pearson`` (the correlation coefficient; 0 where a series is constant);
- ``delay_s``: the lag of the cross-correlation's peak within ±``max_lag`` (positive: the platform lags);
- ``false_cue_share``: the share of samples where the platform's perceived cue (less rest: ``g`` on fz) is above
  the perception threshold with the sign opposite to the vehicle's.

and for the run: the vector RMSE and mean correlation of specific force and angular velocity, the largest roll
and pitch rate and the share of samples where one is above the canals' threshold while the vehicle's is not
(a rotation the vehicle does not make, e.g. tilt coordination turning too fast), and from the exact leg lengths
the stroke used (% of the stroke, per leg, the largest), the smallest distance to a stroke end, the largest leg
speed and acceleration.
"""

from __future__ import annotations

import numpy as np
from scipy import signal

from stewart_drake.control.cueing.drive import GRAVITY, Drive
from stewart_drake.control.cueing.vestibular import FORCE_THRESHOLD, RATE_THRESHOLD, perceive
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.errors import CueingError

CHANNELS = ("fx", "fy", "fz", "wx", "wy", "wz")
MAX_LAG = 2.0  # s
CONSTANT = 1e-9  # m/s², rad/s: a series whose range is below this is constant (a still channel)


def score(vehicle: Drive, platform: Drive, poses, platform_geometry: Platform, max_lag: float = MAX_LAG) -> dict:
    """The scores of cueing ``vehicle`` by the platform's felt motion ``platform`` (``platform_motion.platform_drive``
    of ``poses`` ``(N, 6)``) on ``platform_geometry``; a JSON-ready dict in SI (see the module)."""
    if len(vehicle) != len(platform) or not np.allclose(vehicle.t, platform.t, rtol=0, atol=1e-9 * vehicle.dt):
        raise CueingError(
            CueingError.SAME_TIMES.format(n=len(vehicle), dt=vehicle.dt, m=len(platform), dt2=platform.dt)
        )
    pv, pp = perceive(vehicle), perceive(platform)
    rest = np.array([0.0, 0.0, GRAVITY])
    v = np.hstack([pv.specific_force - rest, pv.angular_velocity])
    p = np.hstack([pp.specific_force - rest, pp.angular_velocity])
    threshold = np.concatenate([FORCE_THRESHOLD, RATE_THRESHOLD])
    lag = max(1, int(round(max_lag / vehicle.dt)))
    channels = {}
    for i, name in enumerate(CHANNELS):
        channels[name] = {
            "rmse": float(np.sqrt(np.mean((p[:, i] - v[:, i]) ** 2))),
            "pearson": pearson(v[:, i], p[:, i]),
            "delay_s": delay(v[:, i], p[:, i], lag) * vehicle.dt,
            "false_cue_share": float(np.mean((np.abs(p[:, i]) > threshold[i]) & (p[:, i] * v[:, i] < 0))),
        }
    roll_pitch = np.abs(platform.angular_velocity[:, :2])
    spurious = (roll_pitch > RATE_THRESHOLD[:2]) & (np.abs(vehicle.angular_velocity[:, :2]) <= RATE_THRESHOLD[:2])
    L = leg_lengths(platform_geometry, poses)
    lo, hi = platform_geometry.stroke
    dt = vehicle.dt
    speed = np.gradient(L, dt, axis=0)
    accel = (L[2:] - 2 * L[1:-1] + L[:-2]) / dt**2
    return {
        "channels": channels,
        "specific_force_rmse": float(np.sqrt(np.mean((p[:, :3] - v[:, :3]) ** 2) * 3)),
        "angular_velocity_rmse": float(np.sqrt(np.mean((p[:, 3:] - v[:, 3:]) ** 2) * 3)),
        "specific_force_pearson": float(np.mean([channels[c]["pearson"] for c in CHANNELS[:3]])),
        "angular_velocity_pearson": float(np.mean([channels[c]["pearson"] for c in CHANNELS[3:]])),
        "false_cue_share": float(np.mean([channels[c]["false_cue_share"] for c in CHANNELS])),
        "tilt_rate_max": float(roll_pitch.max()),
        "spurious_rotation_share": float(np.mean(np.any(spurious, axis=1))),
        "stroke_use_pct": float(100 * np.max(L.max(axis=0) - L.min(axis=0)) / (hi - lo)),
        "stroke_margin_min": float(min(np.min(L - lo), np.min(hi - L))),
        "leg_speed_max": float(np.max(np.abs(speed))),
        "leg_accel_max": float(np.max(np.abs(accel))) if len(L) > 2 else 0.0,
    }


def pearson(a: np.ndarray, b: np.ndarray) -> float:
    """The correlation coefficient of two ``(N,)`` series; 0 where either is constant (``CONSTANT``)."""
    if _constant(a) or _constant(b):
        return 0.0
    a, b = a - a.mean(), b - b.mean()
    return float(np.sum(a * b) / np.sqrt(np.sum(a * a) * np.sum(b * b)))


def _constant(x: np.ndarray) -> bool:
    """Whether ``x`` varies by less than ``CONSTANT``: a filter's rounding, not a motion."""
    return bool(np.ptp(x) < CONSTANT)


def delay(reference: np.ndarray, delayed: np.ndarray, max_lag: int) -> int:
    """The lag (samples) within ±``max_lag`` at which ``delayed`` best matches ``reference`` (the peak of their
    cross-correlation, means removed); positive when ``delayed`` comes later; 0 for a constant series."""
    if _constant(reference) or _constant(delayed):
        return 0
    a, b = reference - reference.mean(), delayed - delayed.mean()
    xc = signal.correlate(b, a, mode="full", method="fft")
    lags = signal.correlation_lags(len(b), len(a), mode="full")
    keep = np.abs(lags) <= max_lag
    return int(lags[keep][np.argmax(xc[keep])])
