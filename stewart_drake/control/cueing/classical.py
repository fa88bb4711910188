"""Classical washout (Reid & Nahon's structure): a vehicle's specific force and angular velocity → platform poses.

Three channels, per axis, as continuous filters discretised by the bilinear transform at the drive's step (each
starting at rest at the drive's first sample, ``vestibular.filter_series``):

- **translational**: the scaled specific force less gravity, ``k (f − g e_z)``, through a high-pass and a double
  integration in one filter, ``x/a = s / ((s² + 2ζω s + ω²)(s + ω_b))`` (third order: a sustained acceleration
  washes out to zero excursion; ``hp_break = 0`` makes it the second-order ``1/(s² + 2ζω s + ω²)``);
- **tilt coordination**: the scaled x, y specific force low-passed, ``ω_t² / (s² + 2ζ_t ω_t s + ω_t²)``, and
  turned into the pitch and roll whose gravity component gives it (exactly, for the ``utn`` convention:
  ``f_x = −g sin β``, ``f_y = g sin α cos β``), limited to ``tilt_max`` and rate-limited to ``tilt_rate`` (below
  the canals' threshold, so the tilt itself is not perceived as a rotation);
- **rotational**: the scaled angular velocity through a second-order high-pass and an integration,
  ``θ/ω = s / (s² + 2ζ_r ω_r s + ω_r²)`` (taken as the Euler-angle rates: small excursions).

The pose is home plus the translational excursion and home's angles plus tilt and rotation.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from stewart_drake.control.cueing.drive import GRAVITY, Drive
from stewart_drake.control.cueing.vestibular import filter_series
from stewart_drake.errors import CueingError


@dataclass(frozen=True)
class ClassicalParams:
    """The classical washout's parameters (SI: rad/s, rad, 1).

    The defaults are in the range of Reid & Nahon's tunings (UTIAS Report 296, 1985): unit-damped third-order
    translational high-pass near 1–2 rad/s with a 0.5 rad/s break, tilt low-pass near 2 rad/s, rate-limited to
    3°/s, rotational high-pass near 1 rad/s, cues scaled by a half."""

    scale_xy: float = 0.5  # specific-force gain, x and y
    scale_z: float = 0.5  # specific-force gain, z (heave)
    scale_rot: float = 0.5  # angular-velocity gain, roll pitch yaw
    hp_xy: float = 1.5  # rad/s, translational high-pass natural frequency, x and y
    hp_z: float = 2.0  # rad/s, heave
    hp_zeta: float = 1.0
    hp_break: float = 0.5  # rad/s, the third-order break (0: second order)
    tilt_lp: float = 2.0  # rad/s, tilt-coordination low-pass natural frequency
    tilt_zeta: float = 1.0
    tilt_rate: float = math.radians(3.0)  # rad/s, below the canals' 3.0-3.6 °/s roll/pitch thresholds
    tilt_max: float = math.radians(15.0)  # rad
    hp_rot: float = 1.0  # rad/s, rotational high-pass natural frequency
    hp_rot_zeta: float = 1.0

    def __post_init__(self):
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            zero_ok = f.name == "hp_break"
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                rule = "a finite number"
            elif value < 0 or (value == 0 and not zero_ok):
                rule = "a number >= 0" if zero_ok else "a positive number"
            else:
                continue
            error = CueingError(CueingError.PARAM.format(name=f.name, rule=rule, value=value))
            error.field, error.value, error.rule = f.name, value, rule  # a parameters file names the line
            raise error


# A hobby tool's hand set (FlyPT Mover-like: its users set per-axis gains and first-order-like washout by feel;
# FlyPT publishes no default numbers, these are typical of shared profiles): larger gains, a second-order
# translational high-pass with a sustained-acceleration offset, a quick tilt low-pass at a 6 °/s rate limit.
HAND_SET = ClassicalParams(
    scale_xy=0.8,
    scale_z=0.8,
    scale_rot=0.8,
    hp_xy=2.5,
    hp_z=3.0,
    hp_zeta=0.7,
    hp_break=0.0,
    tilt_lp=5.0,
    tilt_zeta=0.7,
    tilt_rate=math.radians(6.0),
    tilt_max=math.radians(20.0),
    hp_rot=2.0,
    hp_rot_zeta=0.7,
)


def classical(drive: Drive, params: ClassicalParams = ClassicalParams(), home=None) -> np.ndarray:
    """``(N, 6)`` platform poses (m, rad, ``utn``) cueing ``drive`` with ``params`` about ``home`` ``(6,)`` (None:
    zeros, the excursions alone)."""
    home = np.zeros(6) if home is None else np.asarray(home, dtype=float)
    p, dt = params, drive.dt
    f, w = drive.specific_force, drive.angular_velocity
    accel = f * [p.scale_xy, p.scale_xy, p.scale_z] - [0.0, 0.0, p.scale_z * GRAVITY]
    pose = np.tile(home, (len(drive), 1))
    for i, omega in enumerate((p.hp_xy, p.hp_xy, p.hp_z)):
        pose[:, i] += filter_series(translational_tf(omega, p.hp_zeta, p.hp_break), accel[:, i], dt)
    lp = (np.array([p.tilt_lp**2]), np.array([1.0, 2 * p.tilt_zeta * p.tilt_lp, p.tilt_lp**2]))
    fx, fy = (filter_series(lp, p.scale_xy * f[:, i], dt) for i in (0, 1))
    pitch = np.arcsin(np.clip(-fx / GRAVITY, -1.0, 1.0))
    roll = np.arcsin(np.clip(fy / (GRAVITY * np.cos(pitch)), -1.0, 1.0))
    step = p.tilt_rate * dt
    for i, target in ((3, roll), (4, pitch)):
        pose[:, i] += rate_limited(np.clip(target, -p.tilt_max, p.tilt_max), step)
    hp = (np.array([1.0, 0.0]), np.array([1.0, 2 * p.hp_rot_zeta * p.hp_rot, p.hp_rot**2]))
    for i in range(3):
        pose[:, 3 + i] += filter_series(hp, p.scale_rot * w[:, i], dt)
    return pose


def translational_tf(omega: float, zeta: float, brk: float) -> tuple[np.ndarray, np.ndarray]:
    """``(num, den)`` of position over acceleration: high-pass then double integration."""
    second = np.array([1.0, 2 * zeta * omega, omega**2])
    if brk == 0:
        return np.array([1.0]), second
    return np.array([1.0, 0.0]), np.polymul(second, [1.0, brk])


def rate_limited(x: np.ndarray, step: float) -> np.ndarray:
    """``(N,)``: ``x`` followed from its first value with at most ``step`` change per sample."""
    values = x.tolist()  # a sequential clamp: a loop over Python floats, not numpy scalars
    out, prev = [values[0]], values[0]
    for v in values[1:]:
        prev += min(max(v - prev, -step), step)
        out.append(prev)
    return np.array(out)
