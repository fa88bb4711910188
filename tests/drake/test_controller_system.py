"""The controller LeafSystem on its own (no plant): timing, causality, bit-exact set-points.

The controller is driven by time functions (a pose reference, a leg-length "measurement"), and its
held outputs are logged finely between ticks, so what is checked is what the plant would see. Drake
publishes (logs) at time t *before* the discrete updates scheduled at t: a sample at t shows what every
other system reads at t; a tick's or release's effect appears in the samples after it.
"""

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import LogVectorOutput

from stewart_drake.control import STATUS, ControllerConfig, DspTiming
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.trajectory import SEED, Trajectory
from stewart_drake.drake.systems import PoseSource, make_controller
from stewart_drake.fixedpoint import QFormat, fixed_point_leg_lengths

PLATFORM = load_preset("utn-dynamic")
T = 1e-3


def run_open_loop(kind, config, reference, measurement, duration, log_period):
    """Controller alone: reference and measurement from time functions; returns the logs (times, command,
    setpoint, status, reference) sampled every ``log_period`` and the controller."""
    b = DiagramBuilder()
    ctrl = b.AddSystem(make_controller(kind, PLATFORM, config))
    ref = b.AddSystem(PoseSource(reference))
    meas = b.AddSystem(PoseSource(measurement))
    b.Connect(ref.get_output_port(), ctrl.GetInputPort("reference"))
    b.Connect(meas.get_output_port(), ctrl.GetInputPort("leg_lengths"))
    logs = {
        name: LogVectorOutput(ctrl.GetOutputPort(name), b, log_period) for name in ("command", "setpoint", "status")
    }
    logs["reference"] = LogVectorOutput(ref.get_output_port(), b, log_period)
    d = b.Build()
    sim = Simulator(d)
    ctx = sim.get_mutable_context()
    L0 = measurement.pose(0.0)
    ctrl.initialize(ctrl.GetMyMutableContextFromRoot(ctx), L0, np.full(6, 5.0))
    sim.Initialize()
    sim.AdvanceTo(duration)
    out = {k: v.FindLog(sim.get_context()) for k, v in logs.items()}
    t = out["command"].sample_times()
    return t, {k: v.data().T for k, v in out.items()}, ctrl


def _fast(t):
    """Every pose coordinate moving quickly, so that 60 ticks visit many set-points."""
    t = np.asarray(t, dtype=float)[..., None]
    amp = np.array([0.03, 0.03, 0.03, 0.15, 0.15, 0.3])
    return np.array([0.0, 0.0, 0.7, 0, 0, 0]) + amp * np.sin(np.array([31.0, 37, 41, 43, 47, 53]) * t)


FAST = Trajectory("fast", _fast, None)
HOME = Trajectory("home", lambda t: SEED.pose(np.zeros_like(t)), None)
L_HOME = leg_lengths(PLATFORM, SEED.pose(0.0))


def step_measurement(t_step, delta):
    """Leg lengths L_HOME, plus ``delta`` on every leg from ``t_step`` on."""

    def fn(t):
        t = np.asarray(t, dtype=float)
        return L_HOME + delta * (t >= t_step)[..., None]

    return Trajectory("step", fn, None)


def test_controller_kind_is_named():
    with pytest.raises(ValueError, match="controller must be 'fixed' or 'float', got 'analog'"):
        make_controller("analog", PLATFORM)


@pytest.mark.parametrize("kind", ["fixed", "float"])
def test_ticks_happen_exactly_at_k_T(kind):
    T2 = 2e-3  # a period other than the plant's usual step
    config = ControllerConfig(timing=DspTiming(sample_period=T2))
    t, logs, _ = run_open_loop(kind, config, HOME, step_measurement(0.01, 1e-3), 0.05, T2 / 4)
    st = logs["status"]
    ticks = st[:, STATUS.index("ticks")]
    tick_time = st[:, STATUS.index("last_tick_time")]
    # one tick per period: a sample at t has seen the ticks strictly before t
    k = np.ceil(t / T2 - 1e-9)
    np.testing.assert_array_equal(ticks, k)
    first = np.r_[False, np.diff(ticks) > 0]
    # the logged tick times are k·T exactly (bit for bit: Drake schedules offset + k·period)
    np.testing.assert_array_equal(tick_time[first], np.arange(first.sum()) * T2)


@pytest.mark.parametrize(
    "latency, cycles, delay",
    [("sample", None, T), ("computation", 15000, 15000 / 60e6), ("none", None, 0.0)],
)
@pytest.mark.parametrize("kind", ["fixed", "float"])
def test_output_depends_only_on_measurements_before_the_release(kind, latency, cycles, delay):
    """A measurement step at tick 5 changes the output first at 5T + delay: with the default latency
    ("sample") the output at tick k depends only on measurements up to tick k−1."""
    config = ControllerConfig(timing=DspTiming(latency=latency, computation_cycles=cycles))
    t_step, dt = 5 * T, T / 8
    t, base, _ = run_open_loop(kind, config, HOME, step_measurement(1.0, 0.0), 0.012, dt)
    t, step, _ = run_open_loop(kind, config, HOME, step_measurement(t_step, 1e-3), 0.012, dt)
    changed = np.any(step["command"] != base["command"], axis=1)
    assert changed.any()
    t_first = t[np.argmax(changed)]
    assert t_first == pytest.approx(t_step + delay + dt, abs=1e-12)  # the first sample after the release
    # held between releases (zero-order hold): the command changes only at release instants k·T + delay
    moves = t[1:][np.any(np.diff(step["command"], axis=0) != 0, axis=1)]
    phase = np.mod(moves - dt - delay + 1e-12, T)
    assert len(moves) > 3 and np.all(phase < 1e-9), moves


# ----------------------------------------------------------------------------------------------
# Bit-exact set-points


@pytest.mark.parametrize("latency, lag", [("none", 1), ("sample", 2)])
def test_fixed_setpoints_equal_the_standalone_fixed_point_ik(latency, lag):
    """The set-points the controller releases are, bit for bit, ``fixed_point_leg_lengths`` of the
    reference it read (16-bit words, integer mm, the tfr16 sine/cosine). Not primed: every tick
    computes the IK itself. Logged at k·T (before tick k), so the sample at k·T shows the set-point of
    tick k − 1 (latency none) or k − 2 (one full sample)."""
    config = ControllerConfig(timing=DspTiming(latency=latency))
    meas = Trajectory("L", lambda t: leg_lengths(PLATFORM, FAST.pose(t)), None)
    t, logs, ctrl = run_open_loop("fixed", config, FAST, meas, 0.06, T)
    ref = logs["reference"]  # the reference at each tick, as the controller read it
    np.testing.assert_array_equal(t, np.arange(len(t)) * T)
    words = fixed_point_leg_lengths(PLATFORM, ref, QFormat(16, 1e-3, "tfr16"), return_words=True)
    sp = logs["setpoint"]
    np.testing.assert_array_equal(sp[lag:], words[: len(words) - lag] * 1e-3)
    assert ctrl.law.cache_misses == len(t) - 1  # one IK per tick (the last sample's tick is not run)
    assert len(np.unique(words, axis=0)) > 40  # the reference moved through many set-points
