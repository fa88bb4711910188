"""Leg PID gains: the SI gains and the controller configuration, their design from a platform's
leg-space inertia, strut stiffness and loop delay, and their Q15 encoding for the firmware.

Design for any platform (``ControllerConfig.for_platform``; what ``make_law`` and the simulation use when no
configuration is given):

- the command range is the platform's actuator force (``legs.max_force``);
- the gains come from the leg-space inertia M_L = J⁻ᵀ M J⁻¹ at home (plate **and** legs,
  ``leg_space_inertia``) and the loop's delay (``design_gains``): one diagonal PID must serve the
  lightest mode m_min and the heaviest m_max of M_L. The lightest sets the derivative gain
  (kd = m_min·ω_c, crossover ω_c = ``PHASE_BUDGET``/t_d from the delay t_d = output delay + T (zero-order
  hold and backward difference) + actuator lag), the heaviest the stiffness (kp = kd²/(4 ζ_h² m_max): its
  damping ratio is ζ_h) and the integral (ki = kp·ω_h/4, ω_h = √(kp/m_max)).
"""

from __future__ import annotations

import hashlib
import math
import pickle
from dataclasses import dataclass, field

import numpy as np

from stewart_drake.control.timing import PHASE_BUDGET, DspTiming, loop_delay
from stewart_drake.core.dynamics import leg_forces_with_legs
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import length_jacobian
from stewart_drake.errors import GainError, SingularPoseError
from stewart_drake.fixedpoint import QFormat

# The measurement difference is scaled up by 2^DIFF_SHIFT before its 16-bit filter, so that a
# difference of a few counts keeps its resolution (±512 counts per tick still fit a word).
DIFF_SHIFT = 6


@dataclass(frozen=True)
class PidGains:
    """Leg-position PID with velocity feed-forward, in SI:
    force = kp·e + ki·∫e dt − kd·dL/dt + kv·dS/dt  (e = set-point S − measured length L).

    kp N/m, ki N/(m·s), kd N·s/m, kv N·s/m. The defaults are a sweep's on ``utn-dynamic``; for any
    other platform use ``design_gains`` (``ControllerConfig.for_platform``). The derivative acts on the measurement (no kick from the
    IK's 1 mm set-point steps); the set-point rate enters as a feed-forward through its own
    first-order filter (``feedforward_filter``: the weight of the new difference, in (0, 1]), which
    smooths the steps without adding lag inside the loop; with kv = kd the pair acts as a derivative
    of the error at low frequency. ``derivative_filter``: the same for dL/dt (1: none).
    """

    kp: float = 3000.0
    ki: float = 15000.0
    kd: float = 80.0
    kv: float = 80.0
    derivative_filter: float = 1.0
    feedforward_filter: float = 0.1

    def __post_init__(self):
        for name in ("kp", "ki", "kd", "kv"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v >= 0):
                hint = " (a negative --vary gain_scale?)" if v < 0 else ""
                raise GainError(GainError.PID_NEGATIVE.format(name=name, value=v, hint=hint))
        for name in ("derivative_filter", "feedforward_filter"):
            v = getattr(self, name)
            if not 0 < v <= 1:
                raise GainError(GainError.PID_FILTER.format(name=name.replace("_", " "), value=v))


@dataclass(frozen=True)
class ControllerConfig:
    """Everything a controller needs: timing, gains, the fixed-point IK's number format (default the
    DSP's: 16-bit words, integer millimetres, the tfr16 sine/cosine) and the reference's convention."""

    timing: DspTiming = field(default_factory=DspTiming)
    gains: PidGains = field(default_factory=PidGains)
    ik_format: QFormat = field(default_factory=lambda: QFormat(16, 1e-3, "tfr16"))
    convention: str = "utn"

    @classmethod
    def for_platform(
        cls, platform: Platform, timing: DspTiming | None = None, actuator_lag: float = 2e-3, poses=None, **kwargs
    ) -> ControllerConfig:
        """The configuration designed for ``platform``: ``timing`` (default ``DspTiming()`` with its
        command range the platform's actuator force ``legs.max_force``; a given timing is used as is) and
        the gains of ``design_gains`` for that timing, an actuator lag ``actuator_lag`` (s) and the poses
        the loop will visit ``poses`` (``(n, 6)``, e.g. the trajectory's; None: home only). ``kwargs``:
        the other fields (``ik_format``, ``convention``, or ``gains`` to override the design)."""
        timing = timing or DspTiming(command_range=float(platform.legs.max_force))
        if "gains" not in kwargs:
            kwargs["gains"] = design_gains(platform, timing, actuator_lag, poses=poses)
        return cls(timing=timing, **kwargs)


# ----------------------------------------------------------------------------------------------
# Gain design from the platform.

# Damping ratio of the heaviest leg-space mode under the PD part (sets kp from kd).
HEAVY_MODE_DAMPING = 0.25
# kp is at least this multiple of the struts' largest negative stiffness over the poses the loop visits
# (``strut_stiffness``, ``design_gains(poses=...)``): the heaviest mode keeps a net stiffness kp − K of at
# least half of kp everywhere on the trajectory.
STIFFNESS_MARGIN = 2.0
# Without the visited poses only home is known: the trajectories tried reach up to ~1.6 × home's stiffness
# (utn-kinematic seed: 5.1 → 8.0 kN/m); the design assumes this factor (× STIFFNESS_MARGIN: 3 × home).
UNKNOWN_POSE_STIFFNESS_FACTOR = 1.5
# The integral gain is at most this fraction of the heaviest mode's Routh limit kd·(kp − K)/m_max (the PID
# on a mass m with net stiffness k: m s³ + kd s² + k s + ki, stable iff ki < kd·k/m).
ROUTH_FRACTION = 0.5
# At most this many poses of a trajectory are used for the design (evenly spread; the extremes of mass and
# stiffness vary slowly along a trajectory).
DESIGN_POSES = 64


def leg_space_inertia(platform: Platform, pose=None) -> np.ndarray:
    """``(..., 6, 6)`` leg-space inertia M_L = J⁻ᵀ M J⁻¹ (kg) at ``pose`` (``(..., 6)``; default home): the
    force on each leg per unit leg acceleration, plate and legs (``dynamics.leg_forces_with_legs`` without
    gravity and at rest; J = ∂L/∂q). Its eigenvalues are the masses the leg PIDs see in the platform's modes."""

    q0 = platform.home_pose() if pose is None else np.asarray(pose, dtype=float)
    z = np.zeros_like(q0)
    JtM = _columns(leg_forces_with_legs(platform, _tiled(q0, 6), _tiled(z, 6), z + _steps(np.eye(6), q0), gravity=0.0))
    M_L = JtM @ np.linalg.inv(length_jacobian(platform, q0))  # JtM: J⁻ᵀ M
    return (M_L + np.swapaxes(M_L, -1, -2)) / 2


def strut_stiffness(platform: Platform, pose=None, h: float = 1e-6):
    """The largest negative stiffness (N/m) the static leg forces present to the leg loops at ``pose``
    (``(6,)`` → float, ``(..., 6)`` → array ``(...)``; default home): with constant forces, a leg-length
    error e changes the forces needed to hold the plate by (∂F_static/∂L)·e; where that is negative (struts
    pushing the plate up act like inverted pendulums, ``dynamics.open_loop_growth_rates``) the error grows
    unless kp exceeds it. The largest eigenvalue of −sym(∂F_static/∂L) (0 if none is positive); central
    differences of step ``h``."""
    q0 = platform.home_pose() if pose is None else np.asarray(pose, dtype=float)
    z = np.zeros_like(q0)
    steps = _steps(h * np.eye(6), q0)
    try:  # the twelve poses in one batch: the inverse dynamics is row by row, so the same numbers as twelve calls
        F = leg_forces_with_legs(platform, np.concatenate([q0 + steps, q0 - steps]), _tiled(z, 12), _tiled(z, 12))
    except SingularPoseError:  # named by its index in the call it came from, as always
        for e in np.eye(6):
            leg_forces_with_legs(platform, q0 + h * e, z, z)
            leg_forces_with_legs(platform, q0 - h * e, z, z)
        raise
    dFdq = _columns((F[:6] - F[6:]) / (2 * h))
    K = dFdq @ np.linalg.inv(length_jacobian(platform, q0))
    k = np.maximum(0.0, np.linalg.eigvalsh(-(K + np.swapaxes(K, -1, -2)) / 2)[..., -1])
    return float(k) if k.ndim == 0 else k


def _steps(rows, q0) -> np.ndarray:
    """``(6, ..., 6)``: row k of ``rows`` (6, 6) as a step for each pose of ``q0`` (``(..., 6)``), contiguous."""
    return np.ascontiguousarray(
        np.broadcast_to(rows.reshape((6,) + (1,) * (np.ndim(q0) - 1) + (6,)), (6, *np.shape(q0)))
    )


def _tiled(a, n: int) -> np.ndarray:
    """``(n, ...)`` contiguous copies of ``a``: a batch whose rows are laid out as ``a``'s own."""
    return np.ascontiguousarray(np.broadcast_to(a, (n, *np.shape(a))))


def _columns(F) -> np.ndarray:
    """``(..., 6, k)`` contiguous from ``(k, ..., 6)``: the k batched results as columns, as ``np.stack(…, -1)`` lays them out."""
    return np.ascontiguousarray(np.moveaxis(F, 0, -1))


def design_gains(
    platform: Platform, timing: DspTiming | None = None, actuator_lag: float = 2e-3, pose=None, poses=None
) -> PidGains:
    """Leg PID gains for ``platform`` from its leg-space inertia (``leg_space_inertia``: lightest mode
    m_min, heaviest m_max), the struts' negative stiffness K (``strut_stiffness``) and the loop delay t_d
    (``loop_delay``). The extremes are taken over ``pose`` (default home) and ``poses`` (``(n, 6)``, the
    poses the loop will visit, e.g. samples of the trajectory; without them K is assumed to reach
    ``UNKNOWN_POSE_STIFFNESS_FACTOR`` × its value at ``pose``):

        ω_c = PHASE_BUDGET / t_d           crossover of the lightest mode (rad/s)
        kd = kv = m_min · ω_c              the derivative dominates there (and the velocity feed-forward
                                           matches it: kd·(dS/dt − dL/dt) acts on the error's rate)
        kp = kd² / (4 ζ_h² m_max)          damping ratio ζ_h = HEAVY_MODE_DAMPING of the heaviest mode,
                                           at most kd·ω_c/3 (the lightest mode keeps ≥ 70° of PD lead),
                                           at least STIFFNESS_MARGIN × K (the struts' negative stiffness
                                           eats into kp: heavy plates on flat legs need it)
        ki = min(kp · ω_h / 4,             integral corner a quarter of the heaviest mode's frequency
                 ROUTH_FRACTION · kd · (kp − K) / m_max)   and half its Routh limit

    The Routh cap matters where the stiffness floor sets kp: kp then outgrows kd²/(4 ζ_h² m_max), the
    heaviest mode's damping falls below ζ_h and kp·ω_h/4 exceeds kd·(kp − K)/m_max — a slow oscillation
    (~2 Hz on utn-kinematic) that grows wherever the trajectory raises K.
    On utn-dynamic (m 0.17 … 8.1 kg, t_d 4 ms at 1 kHz with a 2 ms actuator lag) this gives the
    order of the sweep's kp 3000, ki 15000, kd 80; heavier platforms get proportionally stiffer gains.
    """
    timing = timing or DspTiming()
    if not (math.isfinite(actuator_lag) and actuator_lag >= 0):
        raise GainError(GainError.ACTUATOR_LAG.format(value=actuator_lag))
    q0 = platform.home_pose() if pose is None else np.asarray(pose, dtype=float).reshape(6)
    visited = np.concatenate([q0[None], design_pose_subset(poses)])
    m_min, m_max, K = _mass_and_stiffness_extremes(platform, visited)
    if not m_min > 0:
        raise GainError(GainError.INERTIA.format(name=platform.name, m_min=m_min))
    if poses is None:
        K *= UNKNOWN_POSE_STIFFNESS_FACTOR
    w_c = PHASE_BUDGET / loop_delay(timing, actuator_lag)
    kd = m_min * w_c
    # ... but keep the PD zero kp/kd at most ω_c/3 (≥ 70° of phase lead at the light mode's crossover),
    # and at least STIFFNESS_MARGIN × the struts' negative stiffness (else the plate falls away)
    kp = max(min(kd**2 / (4 * HEAVY_MODE_DAMPING**2 * m_max), kd * w_c / 3), STIFFNESS_MARGIN * K)
    ki = min(kp * math.sqrt(kp / m_max) / 4, ROUTH_FRACTION * kd * (kp - K) / m_max)
    return PidGains(kp=kp, ki=ki, kd=kd, kv=kd)


_EXTREMES: dict[bytes, tuple[float, float, float]] = {}  # content hash -> (m_min, m_max, K), newest last
_EXTREMES_KEPT = 16


def _mass_and_stiffness_extremes(platform: Platform, visited) -> tuple[float, float, float]:
    """``(m_min, m_max, K)`` over the poses ``visited`` ``(n, 6)``: the lightest and heaviest leg-space
    modes (kg) and the struts' largest negative stiffness (N/m), the costly part of ``design_gains``.
    Remembered by content (the platform's pickle and the poses' bytes, the last ``_EXTREMES_KEPT``), so that
    the runs of a study, which design for the same nominal platform and reference, compute it once per
    process: the same numbers, computed once."""
    key = hashlib.sha256(pickle.dumps(platform, protocol=4) + np.ascontiguousarray(visited, float).tobytes()).digest()
    hit = _EXTREMES.get(key)
    if hit is None:
        m = np.linalg.eigvalsh(leg_space_inertia(platform, visited))
        m_min, m_max = float(m[:, 0].min()), float(m[:, -1].max())
        if not m_min > 0:  # refused by the caller before the stiffness is asked for
            return m_min, m_max, math.nan
        hit = (m_min, m_max, float(strut_stiffness(platform, visited).max()))
        _EXTREMES[key] = hit
        while len(_EXTREMES) > _EXTREMES_KEPT:
            del _EXTREMES[next(iter(_EXTREMES))]
    return hit


def design_pose_subset(poses) -> np.ndarray:
    """At most ``DESIGN_POSES`` of ``poses`` ``(n, 6)`` (None: none), evenly spread, first and last kept."""
    if poses is None:
        return np.zeros((0, 6))
    poses = np.asarray(poses, dtype=float).reshape(-1, 6)
    if not np.all(np.isfinite(poses)):
        bad = int(np.flatnonzero(~np.all(np.isfinite(poses), axis=1))[0])
        raise GainError(GainError.DESIGN_POSE.format(index=bad, value=poses[bad]))
    if len(poses) > DESIGN_POSES:
        poses = poses[np.unique(np.round(np.linspace(0, len(poses) - 1, DESIGN_POSES)).astype(int))]
    return poses


# ----------------------------------------------------------------------------------------------
# Q15 gains.


@dataclass(frozen=True)
class Q15Gain:
    """A gain as the firmware stores it: a Q15 mantissa and a left shift, value = mantissa / 2^15 · 2^shift."""

    mantissa: int
    shift: int

    @property
    def value(self) -> float:
        return self.mantissa / 32768.0 * 2.0**self.shift


def q15_gain(x: float) -> Q15Gain:
    """The Q15 mantissa and smallest shift >= 0 representing ``x`` >= 0 (rounded to nearest)."""
    if not (math.isfinite(x) and x >= 0):
        raise GainError(GainError.GAIN.format(value=x))
    shift = 0
    while shift <= 30 and x / 2.0**shift * 32768.0 >= 32767.5:  # compared as floats: x may be ~1e308
        shift += 1
    if shift > 30:
        raise GainError(GainError.Q15_RANGE.format(value=x))
    return Q15Gain(int(round(x / 2.0**shift * 32768.0)), shift)


@dataclass(frozen=True)
class FixedGains:
    """The PID gains in the firmware's units: the error a Q15 fraction of 2^15 sensor counts, the
    measurement difference of 2^15 / 2^DIFF_SHIFT counts, the command a Q15/Q31 fraction of the command range.

    ``kp``, ``ki``, ``kd``, ``kv`` (the last three per tick) as ``Q15Gain``; ``alpha``, ``alpha_ff`` the
    filter weights (Q15).
    """

    kp: Q15Gain
    ki: Q15Gain
    kd: Q15Gain
    kv: Q15Gain
    alpha: int
    alpha_ff: int

    @classmethod
    def from_si(cls, gains: PidGains, timing: DspTiming) -> FixedGains:
        # command fraction per error fraction: k_phys · (2^15 counts · resolution) / command_range
        scale = 32768.0 * timing.sensor_resolution / timing.command_range
        T = timing.sample_period
        words = {
            "kp": gains.kp * scale,
            "ki": gains.ki * T * scale,
            "kd": gains.kd / T * scale / 2**DIFF_SHIFT,
            "kv": gains.kv / T * scale / 2**DIFF_SHIFT,
        }
        for name, x in words.items():  # name the gain and the inputs that scale it, not a bare number
            if not (math.isfinite(x) and x < 32768.0 * 2.0**30):
                raise GainError(
                    GainError.Q15_SCALE.format(
                        name=name,
                        value=getattr(gains, name),
                        range=timing.command_range,
                        r=timing.sensor_resolution,
                        T=T,
                    )
                )
        return cls(
            kp=q15_gain(words["kp"]),
            ki=q15_gain(words["ki"]),
            kd=q15_gain(words["kd"]),
            kv=q15_gain(words["kv"]),
            alpha=min(32767, int(round(gains.derivative_filter * 32768.0))),
            alpha_ff=min(32767, int(round(gains.feedforward_filter * 32768.0))),
        )


def counts_per_lsb(config: ControllerConfig) -> int:
    """Sensor counts per length LSB of the fixed-point IK (the set-point's scaling to counts); raises
    ValueError unless the sensor resolution divides the LSB into a whole number of counts."""
    r, lsb = config.timing.sensor_resolution, config.ik_format.length_lsb
    cpl = lsb / r
    if abs(cpl - round(cpl)) > 1e-9 * cpl or round(cpl) < 1:
        raise GainError(GainError.SENSOR_COUNTS.format(r=r, lsb=lsb))
    if cpl > MAX_COUNTS_PER_LSB:  # one LSB step must fit the firmware's 16-bit error word (a C overflow before)
        raise GainError(GainError.COUNTS_PER_LSB.format(r=r, lsb=lsb, cpl=cpl, limit=MAX_COUNTS_PER_LSB))
    return int(round(cpl))


# The firmware's error word is 16 bits: a set-point step of one LSB, in sensor counts, must fit it.
MAX_COUNTS_PER_LSB = 32767
