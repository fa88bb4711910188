"""The closed loop's ticks outside the Diagram (``drake.tick_loop``) against the same loop built all in Drake
(a ``ControllerSystem`` LeafSystem wired to the plant, sources for the reference and feed-forward, Drake
loggers): the logs must be equal bit for bit, for each integrator, latency and actuator model whose event
order differs (a lagged or direct actuator, a tick with or without a separate release, a discrete plant
that steps before the tick reads it). Short runs (50 ms) of the seed trajectory on ``utn-dynamic``.
"""

from dataclasses import replace

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder, LeafSystem
from pydrake.systems.primitives import LogVectorOutput, MatrixGain

from stewart_drake.control import ControllerConfig, DspTiming
from stewart_drake.control.feedforward import FeedforwardTable, feedforward_engine, feedforward_lead, initial_leg_forces
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.trajectory import SEED
from stewart_drake.drake.integrators import CONTINUOUS, apply_integrator
from stewart_drake.drake.platform_model import build_plant, set_pose
from stewart_drake.drake.simulation import ActuatorModel, Scenario, SimulationLog, build_simulation, set_velocity
from stewart_drake.drake.systems import Actuators, PoseSource, make_controller
from stewart_drake.drake.tick_loop import schedule

PLATFORM = load_preset("utn-dynamic")
DURATION = 0.05


class _FeedforwardSource(LeafSystem):
    """The feed-forward table's row at the context's time (a tick time)."""

    def __init__(self, table: FeedforwardTable):
        super().__init__()
        self.table = table
        self.DeclareVectorOutputPort("ff", 6, lambda c, out: out.SetFromVector(table.force(c.get_time())))


def all_drake_run(sc: Scenario, duration: float) -> dict:
    """The loop of ``sc`` (ideal sensor, the scenario's config) as one Drake Diagram; its logs."""
    b = DiagramBuilder()
    integrator, h, cfg = sc.integrator, sc.plant_time_step, sc.config
    plant, _ = build_plant(PLATFORM, h, b, continuous=integrator in CONTINUOUS)
    ctrl = b.AddSystem(make_controller(sc.controller, PLATFORM, cfg, sc.engine))
    src = b.AddSystem(PoseSource(SEED))
    act = b.AddSystem(Actuators(float(PLATFORM.legs.max_force), sc.actuators.time_constant, h))
    D = np.zeros((6, plant.num_multibody_states()))
    for i in range(6):
        D[i, plant.GetJointByName(f"prismatic_{i + 1}").position_start()] = 1.0
    sensor = b.AddSystem(MatrixGain(D))
    T = cfg.timing.sample_period
    lead = feedforward_lead(cfg, sc.actuators.time_constant)
    ff = FeedforwardTable(PLATFORM, SEED, lead, T, feedforward_engine(sc.controller))  # the loop's own table
    ff.prime(np.arange(int(duration / T + 1e-9) + 1) * T)
    ffs = b.AddSystem(_FeedforwardSource(ff))
    b.Connect(src.get_output_port(), ctrl.GetInputPort("reference"))
    b.Connect(ffs.get_output_port(), ctrl.GetInputPort("feedforward"))
    b.Connect(plant.get_state_output_port(), sensor.get_input_port())
    b.Connect(sensor.get_output_port(), ctrl.GetInputPort("leg_lengths"))
    b.Connect(ctrl.GetOutputPort("command"), act.get_input_port())
    b.Connect(act.get_output_port(), plant.get_actuation_input_port())
    lp = () if integrator == "sap" else (h,)
    ports = {
        "state": plant.get_state_output_port(),
        "command": ctrl.GetOutputPort("command"),
        "setpoint": ctrl.GetOutputPort("setpoint"),
        "status": ctrl.GetOutputPort("status"),
        "force": act.get_output_port(),
    }
    loggers = {k: LogVectorOutput(p, b, *lp) for k, p in ports.items()}
    sim = Simulator(b.Build())
    apply_integrator(sim, integrator, h)
    root = sim.get_mutable_context()
    pc = plant.GetMyMutableContextFromRoot(root)
    set_pose(plant, pc, PLATFORM, SEED.pose(0.0))
    set_velocity(plant, pc, PLATFORM, SEED, 0.0)
    F0 = initial_leg_forces(PLATFORM, SEED)
    e = 1e-6
    rates0 = (leg_lengths(PLATFORM, SEED.pose(e)) - leg_lengths(PLATFORM, SEED.pose(-e))) / (2 * e)
    L0 = leg_lengths(PLATFORM, SEED.pose(0.0))
    ctrl.initialize(ctrl.GetMyMutableContextFromRoot(root), L0, F0, ff.force(0.0), rates0)
    act.set_force(root, F0)
    sim.Initialize()
    sim.AdvanceTo(duration)
    logs = {k: lg.FindLog(sim.get_context()) for k, lg in loggers.items()}
    return {"t": logs["state"].sample_times()} | {k: v.data().T for k, v in logs.items()}


@pytest.mark.parametrize(
    "kind, integrator, latency, time_constant",
    [
        ("float", "cenic-fixed", "sample", 2e-3),  # the default loop
        ("fixed", "cenic-fixed", "sample", 2e-3),  # the compiled firmware in the loop's C kernel
        ("float", "cenic-fixed", "computation", 0.0),  # a release between ticks; the plant integrates the new command
        ("float", "sap", "computation", 2e-3),  # a discrete plant steps before the tick reads it
        ("float", "sap", "none", 0.0),
    ],
)
def test_tick_loop_logs_equal_the_all_drake_diagram(kind, integrator, latency, time_constant):
    """The loop (its compiled kernel here: ``firmware.loop_kernel``) against the all-Drake Diagram, whose
    LeafSystem runs the law's numpy ``step`` (the firmware's ``sd_tick`` through ``CFixedPointLaw.step``)."""
    timing = DspTiming(latency=latency, computation_cycles=15000)
    cfg = ControllerConfig.for_platform(PLATFORM, timing, actuator_lag=time_constant)
    sc = Scenario(
        PLATFORM,
        SEED,
        kind,
        cfg,
        engine="c",
        actuators=ActuatorModel(time_constant=time_constant),
        integrator=integrator,
    )
    sim = build_simulation(sc)
    assert sim.controller.kernel is not None  # a compiler is found here
    log = sim.run(DURATION)
    ref = all_drake_run(sc, DURATION)
    np.testing.assert_array_equal(log.t, ref["t"])
    np.testing.assert_array_equal(sim.states(), ref["state"])
    for name in ("command", "setpoint", "status", "force"):
        np.testing.assert_array_equal(getattr(log, name), ref[name], err_msg=name)
    assert log.saturations().sum() == 0 and np.ptp(log.command, axis=0).min() > 0.1  # the command moved


def test_tick_loop_logs_equal_the_all_drake_diagram_past_one_second():
    """The default loop for 1.01 s: past t = 1 s, where a Diagram without an event at every plant step (an
    ``AdvanceTo`` boundary alone) integrates to a slightly different state (``loop_diagram``'s clock)."""
    sc = Scenario(
        PLATFORM, SEED, "float", ControllerConfig.for_platform(PLATFORM), engine="c", integrator="cenic-fixed"
    )
    sim = build_simulation(sc)
    log = sim.run(1.01)
    ref = all_drake_run(sc, 1.01)
    np.testing.assert_array_equal(sim.states(), ref["state"])
    for name in ("command", "force"):
        np.testing.assert_array_equal(getattr(log, name), ref[name], err_msg=name)


def test_schedule_stops_at_every_event_and_logs_at_the_plant_steps():
    """Plant steps 0.5 ms, ticks 1 ms, releases 0.25 ms after each tick, an extra boundary: every stop in
    order, once, the ticks numbered, and a continuous plant logs only at its steps."""
    s = schedule(0.003, 0.5e-3, 1e-3, 0.25e-3, False, extra=[0.0011])
    expect = sorted({k * 0.5e-3 for k in range(1, 7)} | {0.25e-3 + k * 1e-3 for k in range(3)} | {0.0011})
    np.testing.assert_allclose(s.times, expect, rtol=0, atol=1e-15)
    assert [t for t, k in zip(s.times, s.tick) if k >= 0] == [k * 1e-3 for k in range(1, 4)]
    assert [k for k in s.tick if k >= 0] == [1, 2, 3]
    assert sum(s.release) == 3 and sum(s.boundary) == 1
    assert sum(s.log) == 6  # the six plant steps, not the releases or the boundary
    assert all(schedule(0.003, 0.5e-3, 1e-3, 0.25e-3, True).log)  # a discrete plant logs at every stop


def test_a_reused_diagram_gives_the_logs_of_a_fresh_one():
    """``loop_diagram.DIAGRAM_CACHE``: a second run of the same plant and actuators reuses the Diagram
    (with its own context and Simulator) and logs what a freshly built one logs, bit for bit, also after
    a run of another plant in between; another plant (a heavier plate) gets its own Diagram."""
    from stewart_drake.drake.loop_diagram import DIAGRAM_CACHE

    sc = Scenario(PLATFORM, SEED, "float")
    heavier = replace(PLATFORM, mass=PLATFORM.mass * 1.2)
    DIAGRAM_CACHE.clear()
    fresh_sim = build_simulation(sc)
    fresh = fresh_sim.run(DURATION)
    other = build_simulation(replace(sc, plant_platform=heavier))
    assert other.diagram is not fresh_sim.diagram
    other.run(DURATION)
    again_sim = build_simulation(sc)
    assert again_sim.diagram is fresh_sim.diagram
    again = again_sim.run(DURATION)
    for name in SimulationLog.ARRAYS:
        np.testing.assert_array_equal(getattr(again, name), getattr(fresh, name), err_msg=name)
