"""The DSP controller as discrete Drake systems: typed timing, fixed-point and floating-point leg controllers.

One controller tick (every ``T`` seconds, at exactly t = k·T) does what the MC56F8367 firmware does:

1. read the pose reference and the six measured leg lengths, quantised to the sensor resolution
   (integer counts, as the firmware's position words);
2. compute the leg set-points with the inverse kinematics (fixed point: the ``fixedpoint`` package's
   Q15 IK, integer millimetres; float: the closed-form IK in float64);
3. run a leg-position PID per leg (fixed point: Q15 gains, Q31 accumulators, saturating intrinsics;
   float: the same law in float64) plus the model-based force feed-forward read from a table (see
   below), with command saturation and anti-windup by conditional integration;
4. release the new command to the actuators after the output delay (``DspTiming.latency``):
   ``"sample"`` (default, conservative) one full sample later, at (k+1)·T; ``"computation"`` after the
   cycle model's computation time, at k·T + t_comp; ``"none"`` at k·T (an ideal controller).
   Between releases the command is held (zero-order hold: the output ports read discrete state).

Ports of both controllers: inputs ``reference`` (6: pose, metres/radians, ``utn`` convention unless
configured), ``leg_lengths`` (6: metres, the true prismatic positions: the controller quantises them) and
the optional ``feedforward`` (6: leg forces, newtons; left unconnected it is zero); outputs ``command``
(6: leg forces, newtons), ``setpoint`` (6: metres) and ``status`` (see ``STATUS``).

Design for any platform (``ControllerConfig.for_platform``; what ``make_controller`` and
``simulation.build_simulation`` use when no configuration is given):

- the command range is the platform's actuator force (``legs.max_force``);
- the gains come from the leg-space inertia M_L = J⁻ᵀ M J⁻¹ at home (plate **and** legs,
  ``leg_space_inertia``) and the loop's delay (``design_gains``): one diagonal PID must serve the
  lightest mode m_min and the heaviest m_max of M_L. The lightest sets the derivative gain
  (kd = m_min·ω_c, crossover ω_c = ``PHASE_BUDGET``/t_d from the delay t_d = output delay + T (zero-order
  hold and backward difference) + actuator lag), the heaviest the stiffness (kp = kd²/(4 ζ_h² m_max): its
  damping ratio is ζ_h) and the integral (ki = kp·ω_h/4, ω_h = √(kp/m_max));
- the force feed-forward F_ff(t) = ``dynamics.leg_forces_with_legs`` of the reference, sampled at the
  ticks and advanced by the known delays (``simulation.feedforward_forces``) carries the plate and legs
  along the reference; the PID only corrects what the model misses. On the DSP it is a table (six Q15
  words per tick, written by the host with the pose table: 12 bytes per tick, 12 kB per second at 1 kHz)
  and costs one ``L_deposit_h`` and one ``L_add`` per leg (``FEEDFORWARD_OPS_PER_LEG``, in the cycle
  model). Computing it on the DSP instead would take the inverse dynamics per tick (``ONLINE_FEEDFORWARD_OPS``:
  a linearised model F = F_home + M_L·L̈_ref, 36 multiply-accumulates and the second differences, is
  ~150 cycles; the full model with the Jacobian solve is several thousand cycles, more than the IK).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from stewart_drake.errors import StewartError
from stewart_drake.fixedpoint import QFormat, estimate_cycles, fixed_point_leg_lengths, tp17_cycles
from stewart_drake.core.geometry import Platform

# Layout of the ``status`` output (discrete state): tick count, time of the last tick, time of the last
# release of a command, saturated ticks in total, then per leg (6) saturated ticks.
STATUS = ("ticks", "last_tick_time", "last_release_time", "saturations") + tuple(f"saturations_{i}" for i in range(1, 7))
LATENCY_MODES = ("sample", "computation", "none")

# The per-tick work besides the IK, per leg, as fixed-point operations (see ``_FixedLaw.compute``): error,
# measurement and set-point differences and their filters (sub ×5, shl ×2, mult_r ×2, add ×2), P, I, D, V
# terms (L_mult ×4, L_shl ×4), the sums (L_add ×3, L_sub), the command word (extract_h), the set-point
# scalings to counts (L_mult ×2).
PID_OPS_PER_LEG = {"sub": 5, "add": 2, "shl": 2, "mult_r": 2, "L_mult": 6, "extract_h": 1, "L_shl": 4, "L_add": 3, "L_sub": 1}
# The force feed-forward from its table: the word to the high half of a long (L_deposit_h), added to the sum.
FEEDFORWARD_OPS_PER_LEG = {"L_deposit_h": 1, "L_add": 1}
# The alternative, not implemented: a linearised feed-forward computed on the DSP per tick,
# F = F_home + M_L·L̈_ref: six second differences of the set-points (sub ×2 each, scaled: shl), a 6×6
# matrix-vector product (36 L_mult + 36 L_add), the constant (L_add ×6), the words (extract_h ×6).
ONLINE_FEEDFORWARD_OPS = {"sub": 12, "shl": 6, "L_mult": 36, "L_add": 42, "extract_h": 6}
# The measurement difference is scaled up by 2^DIFF_SHIFT before its 16-bit filter, so that a
# difference of a few counts keeps its resolution (±512 counts per tick still fit a word).
DIFF_SHIFT = 6
# Interrupt entry/exit, reading six position words and writing six PWM words (moves, ~2 cycles each).
ISR_OVERHEAD_CYCLES = 60


class TimingError(StewartError):
    """A DSP timing configuration that cannot run (the computation does not fit in the sample period)."""

    TEMPLATE = (
        "infeasible DSP timing: one controller tick needs {cycles} cycles = {t_comp_us:.3f} µs at {clock_mhz:g} MHz, "
        "longer than the sample period {period_us:.3f} µs"
    )


# ----------------------------------------------------------------------------------------------
# Configuration.


@dataclass(frozen=True)
class DspTiming:
    """The DSP's timing, sensor and actuator interface (SI units).

    clock_hz            CPU clock (the MC56F8367 runs at 60 MHz, one instruction per cycle)
    sample_period       T, seconds between controller ticks
    latency             "sample" (output at (k+1)·T, default), "computation" (at k·T + t_comp) or "none"
    computation_cycles  cycles of one tick; None: the cycle model (IK + PID + ISR overhead)
    sensor_resolution   metres per count of the leg-length sensor (the firmware sees integer counts)
    command_range       newtons of leg force at full-scale command (Q15 1.0)
    """

    clock_hz: float = 60e6
    sample_period: float = 1e-3
    latency: str = "sample"
    computation_cycles: int | None = None
    sensor_resolution: float = 1e-5
    command_range: float = 200.0

    def __post_init__(self):
        for name in ("clock_hz", "sample_period", "sensor_resolution", "command_range"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise ValueError(f"DspTiming.{name} must be a positive number, got {v!r}")
        if self.latency not in LATENCY_MODES:
            raise ValueError(f"DspTiming.latency must be one of {', '.join(LATENCY_MODES)}, got {self.latency!r}")
        if self.computation_cycles is not None and not (int(self.computation_cycles) == self.computation_cycles and self.computation_cycles > 0):
            raise ValueError(f"DspTiming.computation_cycles must be a positive integer, got {self.computation_cycles!r}")

    def cycles(self) -> int:
        """Cycles of one controller tick (given, or from the cycle model: IK + 6 PIDs + ISR overhead)."""
        if self.computation_cycles is not None:
            return int(self.computation_cycles)
        return tick_cycles()

    @property
    def computation_time(self) -> float:
        """Seconds of one tick's computation at ``clock_hz``."""
        return self.cycles() / self.clock_hz

    @property
    def output_delay(self) -> float:
        """Seconds from a tick to the release of its command."""
        return {"sample": self.sample_period, "computation": self.computation_time, "none": 0.0}[self.latency]

    def check(self) -> "DspTiming":
        """Return self, or raise ``TimingError`` if a tick's computation is longer than the sample period."""
        n = self.cycles()
        t = n / self.clock_hz
        if t > self.sample_period:
            raise TimingError(
                TimingError.TEMPLATE.format(
                    cycles=n, t_comp_us=t * 1e6, clock_mhz=self.clock_hz / 1e6, period_us=self.sample_period * 1e6
                )
            )
        return self


def tick_cycles() -> int:
    """Cycles of one controller tick on the MC56F8367 from the ``fixedpoint`` cycle model: the firmware's
    IK (``tp17_cycles``), six leg PIDs (``PID_OPS_PER_LEG``) with their feed-forward words
    (``FEEDFORWARD_OPS_PER_LEG``) and ``ISR_OVERHEAD_CYCLES``."""
    ik = tp17_cycles().cycles
    ops = {k: 6 * v for k, v in PID_OPS_PER_LEG.items()}
    for k, v in FEEDFORWARD_OPS_PER_LEG.items():
        ops[k] = ops.get(k, 0) + 6 * v
    pid = estimate_cycles(ops).cycles
    return int(math.ceil(ik + pid + ISR_OVERHEAD_CYCLES))


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
                raise ValueError(f"PidGains.{name} must be a finite number >= 0, got {v!r}")
        for name in ("derivative_filter", "feedforward_filter"):
            v = getattr(self, name)
            if not 0 < v <= 1:
                raise ValueError(f"PidGains.{name} must be in (0, 1], got {v!r}")


@dataclass(frozen=True)
class ControllerConfig:
    """Everything a controller needs: timing, gains, the fixed-point IK's number format (default the
    DSP's: 16-bit words, integer millimetres, the tfr16 sine/cosine) and the reference's convention."""

    timing: DspTiming = field(default_factory=DspTiming)
    gains: PidGains = field(default_factory=PidGains)
    ik_format: QFormat = field(default_factory=lambda: QFormat(16, 1e-3, "tfr16"))
    convention: str = "utn"

    @classmethod
    def for_platform(cls, platform: Platform, timing: DspTiming | None = None, actuator_lag: float = 2e-3, poses=None, **kwargs) -> "ControllerConfig":
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

# Phase the loop's delay may use at the crossover of the lightest leg-space mode: ω_c = PHASE_BUDGET / t_d
# (radians). Calibrated on utn-dynamic, where it gives the sweep's kd (80 N·s/m); the measured margin: the
# loop stays within its tracking bounds up to ~1.3 × this crossover (``analyses/controller_in_the_loop``).
PHASE_BUDGET = 1.2
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
    from stewart_drake.core.dynamics import leg_forces_with_legs
    from stewart_drake.core.kinematics import length_jacobian

    q0 = platform.home_pose() if pose is None else np.asarray(pose, dtype=float)
    z = np.zeros_like(q0)
    JtM = np.stack([leg_forces_with_legs(platform, q0, z, z + e, gravity=0.0) for e in np.eye(6)], -1)  # J⁻ᵀ M
    M_L = JtM @ np.linalg.inv(length_jacobian(platform, q0))
    return (M_L + np.swapaxes(M_L, -1, -2)) / 2


def strut_stiffness(platform: Platform, pose=None, h: float = 1e-6):
    """The largest negative stiffness (N/m) the static leg forces present to the leg loops at ``pose``
    (``(6,)`` → float, ``(..., 6)`` → array ``(...)``; default home): with constant forces, a leg-length
    error e changes the forces needed to hold the plate by (∂F_static/∂L)·e; where that is negative (struts
    pushing the plate up act like inverted pendulums, ``dynamics.open_loop_growth_rates``) the error grows
    unless kp exceeds it. The largest eigenvalue of −sym(∂F_static/∂L) (0 if none is positive); central
    differences of step ``h``."""
    from stewart_drake.core.dynamics import leg_forces_with_legs
    from stewart_drake.core.kinematics import length_jacobian

    q0 = platform.home_pose() if pose is None else np.asarray(pose, dtype=float)
    z = np.zeros_like(q0)
    dFdq = np.stack([(leg_forces_with_legs(platform, q0 + h * e, z, z) - leg_forces_with_legs(platform, q0 - h * e, z, z)) / (2 * h) for e in np.eye(6)], -1)
    K = dFdq @ np.linalg.inv(length_jacobian(platform, q0))
    k = np.maximum(0.0, np.linalg.eigvalsh(-(K + np.swapaxes(K, -1, -2)) / 2)[..., -1])
    return float(k) if k.ndim == 0 else k


def loop_delay(timing: DspTiming, actuator_lag: float = 2e-3) -> float:
    """Seconds of delay around the leg loop at low frequency: the output delay, half a sample of
    zero-order hold, half a sample of the backward-difference derivative, and the actuator lag."""
    return timing.output_delay + timing.sample_period + actuator_lag


def design_gains(platform: Platform, timing: DspTiming | None = None, actuator_lag: float = 2e-3, pose=None, poses=None) -> PidGains:
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
        raise ValueError(f"actuator_lag must be >= 0 s, got {actuator_lag!r}")
    q0 = platform.home_pose() if pose is None else np.asarray(pose, dtype=float).reshape(6)
    visited = np.concatenate([q0[None], _design_poses(poses)])
    m = np.linalg.eigvalsh(leg_space_inertia(platform, visited))
    m_min, m_max = float(m[:, 0].min()), float(m[:, -1].max())
    if not m_min > 0:
        raise ValueError(f"platform {platform.name!r}: the leg-space inertia is not positive definite (smallest eigenvalue {m_min:.3g} kg)")
    K = float(strut_stiffness(platform, visited).max())
    if poses is None:
        K *= UNKNOWN_POSE_STIFFNESS_FACTOR
    w_c = PHASE_BUDGET / loop_delay(timing, actuator_lag)
    kd = m_min * w_c
    # ... but keep the PD zero kp/kd at most ω_c/3 (≥ 70° of phase lead at the light mode's crossover),
    # and at least STIFFNESS_MARGIN × the struts' negative stiffness (else the plate falls away)
    kp = max(min(kd**2 / (4 * HEAVY_MODE_DAMPING**2 * m_max), kd * w_c / 3), STIFFNESS_MARGIN * K)
    ki = min(kp * math.sqrt(kp / m_max) / 4, ROUTH_FRACTION * kd * (kp - K) / m_max)
    return PidGains(kp=kp, ki=ki, kd=kd, kv=kd)


def _design_poses(poses) -> np.ndarray:
    """At most ``DESIGN_POSES`` of ``poses`` ``(n, 6)`` (None: none), evenly spread, first and last kept."""
    if poses is None:
        return np.zeros((0, 6))
    poses = np.asarray(poses, dtype=float).reshape(-1, 6)
    if not np.all(np.isfinite(poses)):
        bad = int(np.flatnonzero(~np.all(np.isfinite(poses), axis=1))[0])
        raise ValueError(f"design pose {bad} is not finite: {poses[bad]!r}")
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
        raise ValueError(f"a gain must be a finite number >= 0, got {x!r}")
    shift = 0
    while round(x / 2.0**shift * 32768.0) > 32767:
        shift += 1
    if shift > 30:
        raise ValueError(f"gain {x!r} is too large for a Q15 mantissa with a 32-bit shift")
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
    def from_si(cls, gains: PidGains, timing: DspTiming) -> "FixedGains":
        # command fraction per error fraction: k_phys · (2^15 counts · resolution) / command_range
        scale = 32768.0 * timing.sensor_resolution / timing.command_range
        T = timing.sample_period
        return cls(
            kp=q15_gain(gains.kp * scale),
            ki=q15_gain(gains.ki * T * scale),
            kd=q15_gain(gains.kd / T * scale / 2**DIFF_SHIFT),
            kv=q15_gain(gains.kv / T * scale / 2**DIFF_SHIFT),
            alpha=min(32767, int(round(gains.derivative_filter * 32768.0))),
            alpha_ff=min(32767, int(round(gains.feedforward_filter * 32768.0))),
        )


# ----------------------------------------------------------------------------------------------
# The controllers.


class _ControllerBase:
    """Timing, ports and state shared by the fixed-point and float controllers (mixed into a LeafSystem).

    Discrete state groups: 0 ``held`` (12: released command N, released set-point m), 1 ``pending``
    (12: the same, computed but not yet released), 2 ``pid`` (30: integrator, previous measurement,
    its filtered difference, previous set-point, its filtered difference, in the controller's own
    number format), 3 ``status`` (``STATUS``).
    """

    def _declare(self, platform: Platform, config: ControllerConfig):
        self.platform = platform
        self.config = config
        self.timing = config.timing.check()
        T = self.timing.sample_period
        self.DeclareVectorInputPort("reference", 6)
        self.DeclareVectorInputPort("leg_lengths", 6)
        self._ff_port = self.DeclareVectorInputPort("feedforward", 6)
        self._held = self.DeclareDiscreteState(12)
        self._pending = self.DeclareDiscreteState(12)
        self._pid = self.DeclareDiscreteState(30)
        self._status = self.DeclareDiscreteState(len(STATUS))
        self.DeclareVectorOutputPort("command", 6, lambda c, o: o.SetFromVector(c.get_discrete_state(self._held).value()[:6]))
        self.DeclareVectorOutputPort("setpoint", 6, lambda c, o: o.SetFromVector(c.get_discrete_state(self._held).value()[6:]))
        self.DeclareStateOutputPort("status", self._status)
        self.DeclarePeriodicDiscreteUpdateEvent(T, 0.0, self._tick)
        d = self.timing.output_delay
        self._release_separately = 0.0 < d < T
        if self._release_separately:
            self.DeclarePeriodicDiscreteUpdateEvent(T, d, self._release)

    # -- events ---------------------------------------------------------------------------------
    def _tick(self, context, discrete_state):
        ref = self.get_input_port(0).Eval(context)
        L = self.get_input_port(1).Eval(context)
        ff = self._ff_port.Eval(context) if self._ff_port.HasValue(context) else None
        pid = context.get_discrete_state(self._pid).value()
        command, setpoint, pid_new, saturated = self.compute(ref, L, pid, ff)
        st = context.get_discrete_state(self._status).value().copy()
        t = context.get_time()
        st[0] += 1
        st[1] = t
        st[3] += float(np.any(saturated))
        st[4:10] += saturated
        out = np.concatenate([command, setpoint])
        if self.timing.latency == "none":
            discrete_state.set_value(self._held, out)
            st[2] = t
        elif self.timing.latency == "sample" or not self._release_separately:
            # release the previous tick's result now, (k+1)·T, then compute the next one
            if st[0] > 1:
                discrete_state.set_value(self._held, context.get_discrete_state(self._pending).value())
                st[2] = t
        discrete_state.set_value(self._pending, out)
        discrete_state.set_value(self._pid, pid_new)
        discrete_state.set_value(self._status, st)

    def _release(self, context, discrete_state):
        st = context.get_discrete_state(self._status).value().copy()
        if st[0] < 1:
            return
        discrete_state.set_value(self._held, context.get_discrete_state(self._pending).value())
        st[2] = context.get_time()
        discrete_state.set_value(self._status, st)

    # -- initial state --------------------------------------------------------------------------
    def initialize(self, context, lengths, hold_forces=None, feedforward=None, rates=None) -> None:
        """Set the controller's state (in its own ``context``) as if it had been holding ``lengths``
        (6, metres) with ``hold_forces`` (6, newtons; e.g. the static forces against gravity) for a while;
        with a ``feedforward`` (6, N) the integrator holds only the difference hold − feed-forward; with
        ``rates`` (6, m/s) as if the legs had been moving at those rates (the difference filters start
        there: no start-up kick from a derivative that sees the motion but a feed-forward that does not)."""
        lengths = np.asarray(lengths, dtype=float).reshape(6)
        F = np.zeros(6) if hold_forces is None else np.asarray(hold_forces, dtype=float).reshape(6)
        ff = np.zeros(6) if feedforward is None else np.asarray(feedforward, dtype=float).reshape(6)
        pid = self.initial_pid_state(lengths, F - ff, rates)
        context.SetDiscreteState(self._pid, pid)
        held = np.concatenate([self.command_from_integrator(pid[:6], ff), lengths])
        context.SetDiscreteState(self._held, held)
        context.SetDiscreteState(self._pending, held)
        context.SetDiscreteState(self._status, np.zeros(len(STATUS)))


def _make_class(name, compute_mixin):
    """Build ``name`` as a LeafSystem subclass mixing the base timing and a number format (built on
    first use: importing this module does not import pydrake)."""
    from pydrake.systems.framework import LeafSystem

    def __init__(self, platform: Platform, config: ControllerConfig | None = None):
        LeafSystem.__init__(self)
        self._declare(platform, config or ControllerConfig.for_platform(platform))
        self._setup()

    return type(name, (compute_mixin, _ControllerBase, LeafSystem), {"__init__": __init__})


class _FloatLaw:
    """The PID law in float64 (SI)."""

    def _setup(self):
        self._limit = self.timing.command_range
        # (6,) metres added to every set-point (None: nothing). A probe, not a feature: a constant offset
        # from t = 0 is a set-point step on the legs, whose length response measures the loop's gain from
        # set-point errors to length errors (``simulation.setpoint_step_gain``).
        self.setpoint_offset = None

    def quantise(self, L):
        r = self.timing.sensor_resolution
        return np.round(np.asarray(L) / r) * r

    def setpoints(self, ref) -> np.ndarray:
        from stewart_drake.core.kinematics import leg_lengths

        sp = leg_lengths(self.platform, np.asarray(ref, dtype=float), self.config.convention)
        return sp if self.setpoint_offset is None else sp + self.setpoint_offset

    def initial_pid_state(self, lengths, forces, rates=None):
        """PID state holding ``lengths`` (m) with integrator ``forces`` (N), legs moving at ``rates`` (m/s)."""
        lengths = np.asarray(lengths, float)
        d = np.zeros(6) if rates is None else np.asarray(rates, float) * self.timing.sample_period
        m = self.quantise(lengths - d)
        return np.concatenate([np.clip(forces, -self._limit, self._limit), m, d, lengths - d, d])

    def command_from_integrator(self, integ, ff=None):
        """The command (N) of the integrator alone plus the feed-forward ``ff`` (N), saturated."""
        u = np.asarray(integ, dtype=float) + (0.0 if ff is None else np.asarray(ff, dtype=float))
        return np.clip(u, -self._limit, self._limit)

    def compute(self, ref, L, pid, ff=None):
        """One tick: (command N, set-point m, new PID state, saturated flags) for the reference pose,
        the true leg lengths ``L`` (m), the PID state and the force feed-forward ``ff`` (N; None: none)."""
        g, T, lim = self.config.gains, self.timing.sample_period, self._limit
        sp = self.setpoints(ref)
        m = self.quantise(L)
        integ, prev, dfilt, sp_prev, vfilt = np.split(np.asarray(pid, dtype=float), 5)
        e = sp - m
        dfilt = dfilt + g.derivative_filter * ((m - prev) - dfilt)
        vfilt = vfilt + g.feedforward_filter * ((sp - sp_prev) - vfilt)
        u_raw = g.kp * e + integ - g.kd / T * dfilt + g.kv / T * vfilt
        if ff is not None:
            u_raw = u_raw + np.asarray(ff, dtype=float)
        u = np.clip(u_raw, -lim, lim)
        saturated = u_raw != u
        # anti-windup: integrate unless the output is saturated and the error pushes further into it
        grow = ~((u_raw > lim) & (e > 0) | (u_raw < -lim) & (e < 0))
        integ = np.where(grow, np.clip(integ + g.ki * T * e, -lim, lim), integ)
        return u, sp, np.concatenate([integ, m, dfilt, sp, vfilt]), saturated.astype(float)


def counts_per_lsb(config: ControllerConfig) -> int:
    """Sensor counts per length LSB of the fixed-point IK (the set-point's scaling to counts); raises
    ValueError unless the sensor resolution divides the LSB into a whole number of counts."""
    r, lsb = config.timing.sensor_resolution, config.ik_format.length_lsb
    cpl = lsb / r
    if abs(cpl - round(cpl)) > 1e-9 * cpl or round(cpl) < 1:
        raise ValueError(
            f"sensor_resolution {r} m must divide the IK's length LSB {lsb} m into a whole number of counts for the fixed-point controller"
        )
    return int(round(cpl))


class _FixedLaw:
    """The PID law in the firmware's fixed-point arithmetic (bit-exact Q15/Q31 intrinsics)."""

    def _setup(self):
        from stewart_drake.fixedpoint import q15

        self._q = q15
        self.gains = FixedGains.from_si(self.config.gains, self.timing)
        self._counts_per_lsb = counts_per_lsb(self.config)
        self._cache: dict[bytes, np.ndarray] = {}
        self.cache_misses = 0

    def prime(self, poses) -> None:
        """Evaluate the fixed-point IK for ``(n, 6)`` poses in one batch and remember the results, so
        that a tick whose reference is bit-identical to one of them looks it up (same words: the IK is
        elementwise). A speed-up only; a miss computes the IK for that pose."""
        poses = np.ascontiguousarray(np.asarray(poses, dtype=float).reshape(-1, 6))
        words = self.ik_words(poses)
        for q, w in zip(poses, words):
            self._cache[q.tobytes()] = w

    def ik_words(self, poses) -> np.ndarray:
        """``(..., 6)`` int64 set-point words (units of the IK's length LSB) for ``(..., 6)`` poses."""
        return fixed_point_leg_lengths(self.platform, poses, self.config.ik_format, self.config.convention, return_words=True)

    def quantise(self, L) -> np.ndarray:
        """Sensor counts (int64) of true lengths ``L`` (metres), rounded to nearest."""
        return np.round(np.asarray(L, dtype=float) / self.timing.sensor_resolution).astype(np.int64)

    def setpoint_words(self, ref) -> np.ndarray:
        """``(6,)`` int64 set-point words of the pose ``ref`` (from the primed cache or computed)."""
        ref = np.ascontiguousarray(ref, dtype=float)
        w = self._cache.get(ref.tobytes())
        if w is None:
            self.cache_misses += 1
            w = self.ik_words(ref)
        return w

    def initial_pid_state(self, lengths, forces, rates=None):
        """PID state words holding ``lengths`` (m) with integrator ``forces`` (N), legs moving at ``rates``
        (m/s): the previous measurement and set-point one sample back, both difference filters at the
        per-sample difference (counts·2^DIFF_SHIFT)."""
        q = self._q
        frac = np.clip(np.asarray(forces) / self.timing.command_range, -1.0, 1.0 - 2.0**-31)
        integ = q.sat32(np.round(frac * 2.0**31).astype(np.int64))
        lengths = np.asarray(lengths, dtype=float)
        d = np.zeros(6) if rates is None else np.asarray(rates, float) * self.timing.sample_period
        sp = np.round((lengths - d) / self.config.ik_format.length_lsb).astype(np.int64)
        filt = q.sat16(np.round(d / self.timing.sensor_resolution).astype(np.int64) * 2**DIFF_SHIFT)
        return np.concatenate([integ, self.quantise(lengths - d), filt, sp, filt]).astype(float)

    def command_from_integrator(self, integ, ff=None):
        """The command (N) of the integrator word alone plus the feed-forward's table word, saturated."""
        u32 = np.asarray(integ, dtype=np.int64)
        if ff is not None:
            u32 = self._q.L_add(u32, self._q.L_deposit_h(self.feedforward_words(ff)))
        return self._q.extract_h(u32) / 32768.0 * self.timing.command_range

    def feedforward_words(self, ff) -> np.ndarray:
        """``(6,)`` Q15 command words of feed-forward forces ``ff`` (N), as the host writes the table:
        rounded to the nearest LSB of the command range, saturated to the word."""
        return self._q.sat16(np.round(np.asarray(ff, dtype=float) / self.timing.command_range * 32768.0).astype(np.int64))

    def compute(self, ref, L, pid, ff=None):
        """One tick in the firmware's arithmetic (see ``_FloatLaw.compute``); ``ff`` (N) enters as its
        table word (``feedforward_words``) added to the Q31 sum."""
        q, g = self._q, self.gains
        sp = self.setpoint_words(ref)
        m = self.quantise(L)
        st = np.asarray(pid).astype(np.int64)
        integ, prev, dfilt, sp_prev, vfilt = np.split(st, 5)
        e = q.sat16(sp * self._counts_per_lsb - m)  # Word16 error, counts
        dm = q.shl(q.sat16(m - prev), DIFF_SHIFT)  # Word16 measurement difference, counts·2^DIFF_SHIFT
        # first-order filters of the differences: f += alpha·(d − f), rounded Q15 multiplies
        dfilt = q.add(dfilt, q.mult_r(g.alpha, q.sub(dm, dfilt)))
        ds = q.shl(q.sat16((sp - sp_prev) * self._counts_per_lsb), DIFF_SHIFT)  # set-point difference
        vfilt = q.add(vfilt, q.mult_r(g.alpha_ff, q.sub(ds, vfilt)))
        P = q.L_shl(q.L_mult(g.kp.mantissa, e), g.kp.shift)
        D = q.L_shl(q.L_mult(g.kd.mantissa, dfilt), g.kd.shift)
        V = q.L_shl(q.L_mult(g.kv.mantissa, vfilt), g.kv.shift)
        u32 = q.L_add(q.L_sub(q.L_add(P, integ), D), V)
        if ff is not None:
            u32 = q.L_add(u32, q.L_deposit_h(self.feedforward_words(ff)))
        # saturation: the command is a Q15 word; the sum saturated if it hit the Q31 rails
        saturated = (u32 >= q.MAX32) | (u32 <= q.MIN32)
        u16 = q.extract_h(u32)
        grow = ~(((u32 >= q.MAX32) & (e > 0)) | ((u32 <= q.MIN32) & (e < 0)))
        dI = q.L_shl(q.L_mult(g.ki.mantissa, e), g.ki.shift)
        integ = np.where(grow, q.L_add(integ, dI), integ)
        command = u16 / 32768.0 * self.timing.command_range
        state = np.concatenate([integ, m, dfilt, sp, vfilt]).astype(float)
        return command, sp * self.config.ik_format.length_lsb, state, saturated.astype(float)


_classes: dict[str, type] = {}


def _cls(name, law):
    if name not in _classes:
        _classes[name] = _make_class(name, law)
    return _classes[name]


def FloatController(platform: Platform, config: ControllerConfig | None = None):
    """The float64 twin of the DSP controller (same timing, same sensor quantisation, same law)."""
    return _cls("FloatController", _FloatLaw)(platform, config)


def FixedPointController(platform: Platform, config: ControllerConfig | None = None):
    """The DSP controller in bit-exact fixed point: Q15 IK (integer mm), Q15/Q31 PID."""
    return _cls("FixedPointController", _FixedLaw)(platform, config)


def make_controller(kind: str, platform: Platform, config: ControllerConfig | None = None, engine: str = "python", firmware=None):
    """``kind`` ``"fixed"`` or ``"float"``; for ``fixed``, ``engine`` ``"python"`` (the emulation) or ``"c"``
    (the compiled firmware, ``firmware.sil``; ``firmware``: a user's C file implementing the ABI). The float
    twin has no firmware: ``engine`` does not apply to it."""
    if kind == "fixed" and (engine == "c" or firmware is not None):
        from stewart_drake.firmware.sil import CFixedPointController  # the firmware package builds on this module

        return CFixedPointController(platform, config, firmware)
    if engine not in ("python", "c"):
        raise ValueError(f"engine must be 'python' or 'c', got {engine!r}")
    if kind != "fixed" and firmware is not None:
        raise ValueError(f"a firmware file runs the fixed-point controller; controller {kind!r} has no firmware")
    if kind == "fixed":
        return FixedPointController(platform, config)
    if kind == "float":
        return FloatController(platform, config)
    raise ValueError(f"controller must be 'fixed' or 'float', got {kind!r}")
