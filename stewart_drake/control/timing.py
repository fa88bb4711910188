"""The DSP's timing: sample period, output latency, the cycle model of one controller tick, and the checks
that a period and a plant step can hold a platform.

One controller tick (every ``T`` seconds, at exactly t = k·T) does what the MC56F8367 firmware does: read
the pose reference and the six leg lengths (quantised to the sensor's counts), compute the leg set-points
with the inverse kinematics, run a leg-position PID per leg plus the force feed-forward word, and release
the command after the output delay (``DspTiming.latency``): ``"sample"`` (default, conservative) one full
sample later, at (k+1)·T; ``"computation"`` after the cycle model's computation time, at k·T + t_comp;
``"none"`` at k·T (an ideal controller).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from stewart_drake.core.dynamics import open_loop_growth_rates
from stewart_drake.core.sanity import check_positive, fmt_value, has_plate
from stewart_drake.errors import (
    INFEASIBLE_TIMING,
    PERIOD_TOO_SLOW,
    PLANT_STEP_ABOVE_LAG,
    PLANT_STEP_TOO_LONG,
    TIMING_CYCLES,
    TIMING_LATENCY,
    TIMING_POSITIVE,
    StewartError,
    TimingError,
)
from stewart_drake.fixedpoint import estimate_cycles, tp17_cycles

LATENCY_MODES = ("sample", "computation", "none")

# The per-tick work besides the IK, per leg, as fixed-point operations (see ``FixedPointLaw.step``): error,
# measurement and set-point differences and their filters (sub ×5, shl ×2, mult_r ×2, add ×2), P, I, D, V
# terms (L_mult ×4, L_shl ×4), the sums (L_add ×3, L_sub), the command word (extract_h), the set-point
# scalings to counts (L_mult ×2).
PID_OPS_PER_LEG = {
    "sub": 5,
    "add": 2,
    "shl": 2,
    "mult_r": 2,
    "L_mult": 6,
    "extract_h": 1,
    "L_shl": 4,
    "L_add": 3,
    "L_sub": 1,
}
# The force feed-forward from its table: the word to the high half of a long (L_deposit_h), added to the sum.
FEEDFORWARD_OPS_PER_LEG = {"L_deposit_h": 1, "L_add": 1}
# The alternative, not implemented: a linearised feed-forward computed on the DSP per tick,
# F = F_home + M_L·L̈_ref: six second differences of the set-points (sub ×2 each, scaled: shl), a 6×6
# matrix-vector product (36 L_mult + 36 L_add), the constant (L_add ×6), the words (extract_h ×6).
ONLINE_FEEDFORWARD_OPS = {"sub": 12, "shl": 6, "L_mult": 36, "L_add": 42, "extract_h": 6}
# Interrupt entry/exit, reading six position words and writing six PWM words (moves, ~2 cycles each).
ISR_OVERHEAD_CYCLES = 60
# Phase the loop's delay may use at the crossover of the lightest leg-space mode: ω_c = PHASE_BUDGET / t_d
# (radians). Calibrated on utn-dynamic, where it gives the sweep's kd (80 N·s/m); the measured margin: the
# loop stays within its tracking bounds up to ~1.3 × this crossover (``analyses/controller_in_the_loop``).
PHASE_BUDGET = 1.2
# The crossover of the leg loops must exceed the platform's fastest open-loop growth rate by this factor:
# an unstable pole is held only by a loop several times faster than it.
CROSSOVER_MARGIN = 2.0


# The fields a user sets, named as the spec paths and study keys that set them (not the class's attribute names;
# a command turns a spec path into its flag).
TIMING_FIELDS = {
    "clock_hz": "clock (Hz)",
    "sample_period": "sample period (controller.period, vary sample_period; s)",
    "sensor_resolution": "sensor resolution (sensors.resolution, vary sensor_resolution; m per count)",
    "command_range": "command range (legs.max_force, vary force_limit; N)",
}


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
        for name in TIMING_FIELDS:
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise TimingError(TIMING_POSITIVE.format(name=TIMING_FIELDS[name], value=v))
        if self.latency not in LATENCY_MODES:
            raise TimingError(TIMING_LATENCY.format(valid=", ".join(LATENCY_MODES), value=self.latency))
        if self.computation_cycles is not None and not (
            int(self.computation_cycles) == self.computation_cycles and self.computation_cycles > 0
        ):
            raise TimingError(TIMING_CYCLES.format(value=self.computation_cycles))

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

    def check(self) -> DspTiming:
        """Return self, or raise ``TimingError`` if a tick's computation is longer than the sample period."""
        n = self.cycles()
        t = n / self.clock_hz
        if t > self.sample_period:
            raise TimingError(
                INFEASIBLE_TIMING.format(
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


def loop_delay(timing: DspTiming, actuator_lag: float = 2e-3) -> float:
    """Seconds of delay around the leg loop at low frequency: the output delay, half a sample of
    zero-order hold, half a sample of the backward-difference derivative, and the actuator lag."""
    return timing.output_delay + timing.sample_period + actuator_lag


def check_timing(platform, period: float, plant_step: float, actuator_lag: float, output_delay: float) -> None:
    """``StewartError`` unless the controller period and the plant step resolve the dynamics:

    - the plant step is at most the controller period (the plant must advance between ticks) and at
      most the actuator lag (the fastest modelled dynamics: a longer step skips it);
    - the leg loops' achievable crossover ω_c = PHASE_BUDGET / (output delay + period + actuator lag)
      (``loop_delay``) is at least ``CROSSOVER_MARGIN`` × the platform's fastest open-loop growth
      rate λ at home (``dynamics.open_loop_growth_rates``): a slower loop cannot hold the plate up.
    """
    T = check_positive(period, "controller.period", "seconds")
    h = check_positive(plant_step, "run.plant_step", "seconds")
    if h > T * (1 + 1e-12):
        raise StewartError(PLANT_STEP_TOO_LONG.format(step=fmt_value(h), period=fmt_value(T)))
    if actuator_lag > 0 and h > actuator_lag * (1 + 1e-12):
        raise StewartError(PLANT_STEP_ABOVE_LAG.format(step=fmt_value(h), lag=fmt_value(actuator_lag)))
    if has_plate(platform):
        lam = float(np.max(open_loop_growth_rates(platform, platform.home_pose())))
        w_c = PHASE_BUDGET / (output_delay + T + actuator_lag)
        if w_c < CROSSOVER_MARGIN * lam:
            t_max = PHASE_BUDGET / (CROSSOVER_MARGIN * lam) - actuator_lag
            raise StewartError(
                PERIOD_TOO_SLOW.format(
                    period=fmt_value(T),
                    name=platform.name,
                    lam=lam,
                    w_c=w_c,
                    margin=CROSSOVER_MARGIN,
                    t_max=max(t_max / 2, 0),
                )
            )
