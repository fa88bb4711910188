"""Chatter (a quantisation limit cycle) and saturation at a trajectory's ends, measured on a closed-loop log.

What an engineer sees in the force plot: the actuator forces swinging far around the force that moves the
plate. The measure chosen here is the **force ripple**: the RMS over the run of (actuator force − the
quasi-static force), where the quasi-static force is the inverse dynamics (plate and legs) along the
reference, ``feedforward.feedforward_forces`` without lead: the force a perfect loop would apply. It is
compared with two scales of the run itself:

- the RMS of the quasi-static force (the *chatter ratio* ripple / working force): above 1 the force noise
  is larger than the force doing the work;
- the actuator's command range: a ripple above ``CHATTER_RANGE_FRACTION`` of it spends that much of the
  actuator's authority on noise.

Why not "relative to the float twin": on every preset the float twin's ripple is ~0.1–1 % of the fixed
loop's (ratios 30–90 on utn-dynamic, utn-kinematic, gonzalez-dutra-2009 alike), so that ratio does not
separate a good fixed-point loop from a chattering one. Command reversals per second do not either (the
float twin reverses more often, by tiny amounts).

A run chatters (a failure) when both scales are exceeded; a ripple above the working force alone is a
warning. The cause is named from the loop's quantisation steps: a one-LSB step of the fixed-point IK's
set-point (``ik_format.length_lsb``) or one sensor count (``sensor_resolution``) reaches the actuator as
kp·step through the proportional term, and on the first tick kv·step/T through the set-point-rate
feed-forward (an IK step) or kd·step/T through the derivative on the measurement (a sensor count).
"""

from __future__ import annotations

import numpy as np

from stewart_drake.control.feedforward import feedforward_forces
from stewart_drake.control.gains import ControllerConfig
from stewart_drake.control.laws import STATUS
from stewart_drake.core.geometry import Platform
from stewart_drake.core.trajectory import Trajectory

# A ripple above this fraction of the command range (and above the working force) is chatter. The presets'
# fixed-point loops reach 1.1-1.9 % (utn-dynamic 2.2 N of 200 N, gonzalez-dutra-2009 95 N of 5 kN on the
# rotating trajectory); the newcomer's 150 kg platform 10-20 %.
CHATTER_RANGE_FRACTION = 0.05
# The ripple is compared with the working force's RMS: above it, the force noise dominates the motion.
CHATTER_RATIO = 1.0
# A saturated tick within this time of the run's start or end is flagged: the reference starts or stops
# with a velocity or acceleration the actuator cannot follow (a CSV whose last samples jump).
END_WINDOW_S = 0.05


def quantisation_forces(config: ControllerConfig) -> dict:
    """The force (N) one quantisation step reaches the actuator with on its first tick, by source and path:
    the IK's length LSB through kp and kv/T, one sensor count through kp and kd/T."""
    g, T = config.gains, config.timing.sample_period
    lsb, r = config.ik_format.length_lsb, config.timing.sensor_resolution
    ik, count = f"the IK's length LSB ({lsb * 1e3:g} mm)", f"one sensor count ({r * 1e3:g} mm)"
    # the set-point's steps enter through kp and the set-point-rate feed-forward kv (before its filter);
    # the measurement's through kp and the derivative on the measurement kd (``laws.PidGains``)
    return {
        f"{ik} through kp": g.kp * lsb,
        f"{ik} through kv/T": g.kv * lsb / T,
        f"{count} through kp": g.kp * r,
        f"{count} through kd/T": g.kd * r / T,
    }


def chatter_measure(platform: Platform, trajectory: Trajectory, log, config: ControllerConfig) -> dict:
    """The force ripple of a run (see the module docstring): ``{"force_ripple_N": (6,) RMS of force −
    quasi-static force, "working_force_rms_N": (6,), "chatter_ratio": max over legs of ripple/working,
    "ripple_range_fraction": max ripple / command range, "chatter_cause": the largest quantisation force
    and its value}``; ``log`` is a ``SimulationLog`` (forces in N at ``log.t``, s)."""
    F_qs = feedforward_forces(platform, trajectory, log.t, 0.0, config.timing.sample_period)
    ripple = np.sqrt(np.mean((np.asarray(log.force) - F_qs) ** 2, axis=0))
    working = np.sqrt(np.mean(F_qs**2, axis=0))
    ratio = ripple / np.maximum(working, 1e-12 * config.timing.command_range)
    q = quantisation_forces(config)
    cause = max(q, key=q.get)
    return {
        "force_ripple_N": ripple.tolist(),
        "working_force_rms_N": working.tolist(),
        "chatter_ratio": float(ratio.max()),
        "ripple_range_fraction": float(ripple.max() / config.timing.command_range),
        "chatter_cause": f"{cause}: {q[cause]:.4g} N per step",
    }


def end_saturation(log, window: float = END_WINDOW_S) -> list[tuple[int, float]]:
    """``[(leg, time)]``: the legs (1-based) whose command saturated on a tick within ``window`` seconds of
    the run's start or end, with the first such tick's time (s)."""
    ticks = log.status[:, STATUS.index("ticks")].astype(int)
    first = np.r_[True, np.diff(ticks) != 0] & (ticks > 0)
    counts = log.status[first][:, 4:10]
    times = log.status[first][:, STATUS.index("last_tick_time")]
    sat = np.diff(np.vstack([np.zeros((1, 6)), counts]), axis=0) > 0
    t_end = float(log.t[-1])
    near = (times <= float(log.t[0]) + window) | (times >= t_end - window)
    out = []
    for j in range(6):
        hit = np.flatnonzero(sat[:, j] & near)
        if len(hit):
            out.append((j + 1, float(times[hit[0]])))
    return out


def loop_verdict(platform: Platform, trajectory: Trajectory, log, config: ControllerConfig) -> dict:
    """``chatter_measure`` plus ``{"chatter": bool, "end_saturation": [[leg, t]], "failures": [...],
    "warnings": [...]}``: chatter (ripple above the working force and above ``CHATTER_RANGE_FRACTION`` of the
    command range), a ripple above the working force alone (a warning), and saturation within ``END_WINDOW_S``
    of the run's ends (``end_saturation``: 1-based leg, first such tick's time in s)."""
    m = chatter_measure(platform, trajectory, log, config)
    failures, warnings = [], []
    ripple = max(m["force_ripple_N"])
    text = (
        f"force ripple {ripple:.4g} N RMS about the quasi-static force, {m['chatter_ratio']:.2g} × the working "
        f"force and {m['ripple_range_fraction'] * 100:.3g} % of the {config.timing.command_range:g} N command range"
    )
    chatter = m["chatter_ratio"] > CHATTER_RATIO and m["ripple_range_fraction"] > CHATTER_RANGE_FRACTION
    if chatter:
        failures.append(
            f"chatter: {text} (bound {CHATTER_RANGE_FRACTION * 100:g} %); largest quantisation step: "
            f"{m['chatter_cause']} (a finer IK length LSB or sensor count, or lower kp/kd, reduces it)"
        )
    elif m["chatter_ratio"] > CHATTER_RATIO:
        warnings.append(f"force ripple above the working force: {text}; from {m['chatter_cause']}")
    ends = end_saturation(log)
    for leg, t in ends:
        failures.append(
            f"leg {leg} saturated at the trajectory's {'start' if t <= float(log.t[0]) + END_WINDOW_S else 'end'} "
            f"(t = {t:.4f} s): the reference starts or stops with a speed or acceleration the actuator cannot follow"
        )
    m.update(chatter=chatter, end_saturation=[[leg, t] for leg, t in ends], failures=failures, warnings=warnings)
    return m
