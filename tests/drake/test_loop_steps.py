"""Drake's work in a closed-loop run (``drake.tick_loop`` driving ``drake.loop_diagram``'s Diagram) is the
plant's alone: one integrator step per plant step, the loop's clock the only discrete update, and the
plant's states those of the bare Diagram replaying the loop's logged forces through its fixed input with
the same stops (so no time of a tick inside ``AdvanceTo`` is spent on anything but the plant along its own
motion). Counts and bits, not timings (``benchmarks/bench_tick.py`` measures the time).

Why 1.2 s: without the clock's events Drake reaches a stop that is no event time by an extra short step
from t = 1 s on (the stop times k·h and the integrator's accumulated time part by an ulp there), so a shorter
run could not tell the clock's role.
"""

import numpy as np
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder

from stewart_drake.core.dynamics import leg_forces_with_legs
from stewart_drake.core.geometry import load_preset
from stewart_drake.drake.integrators import apply_integrator
from stewart_drake.drake.loop_diagram import loop_diagram
from stewart_drake.drake.platform_model import build_plant, set_pose
from stewart_drake.drake.simulation import Scenario, build_simulation

PLATFORM = load_preset("utn-dynamic")
H = 1e-3  # s: the plant step (the default scenario's)
DURATION = 1.2  # s: past t = 1 s (see the module's docstring)
N = round(DURATION / H)  # plant steps


def test_loop_takes_one_integrator_step_per_plant_step():
    """A 1.2 s run of the compiled fixed-point loop: 1200 integrator steps, 1200 discrete updates (the clock
    alone: the actuators and the controller run outside the Diagram), no publish."""
    sim = build_simulation(Scenario(PLATFORM, "seed", "fixed", engine="c"))
    assert sim.controller.kernel is not None  # the compiled loop, not the Python fallback
    sim.run(DURATION)
    simulator = sim.simulator
    assert simulator.get_integrator().get_num_steps_taken() == N
    assert simulator.get_num_discrete_updates() == N
    assert simulator.get_num_publishes() == 0


def _stopped_every_step(diagram, plant) -> int:
    """Integrator steps of ``diagram`` (its actuation input fixed at home's static forces, the plant at home)
    advanced to every plant step k·H up to ``DURATION``."""
    simulator = Simulator(diagram)
    apply_integrator(simulator, "cenic-fixed", H)
    root = simulator.get_mutable_context()
    set_pose(plant, plant.GetMyMutableContextFromRoot(root), PLATFORM, PLATFORM.home_pose())
    force = leg_forces_with_legs(PLATFORM, PLATFORM.home_pose(), np.zeros(6), np.zeros(6))
    diagram.GetInputPort("actuation").FixValue(root, force)
    simulator.Initialize()
    for k in range(1, N + 1):
        simulator.AdvanceTo(k * H)
    return simulator.get_integrator().get_num_steps_taken()


def test_the_clock_is_what_keeps_one_step_per_stop():
    """The loop's Diagram stopped at every plant step takes one step per stop; the same plant without the
    clock takes extra steps after t = 1 s (the counter-check: the count above could fail)."""
    built = loop_diagram(PLATFORM, H, "cenic-fixed")
    assert _stopped_every_step(built.diagram, built.plant) == N
    builder = DiagramBuilder()
    plant, _ = build_plant(PLATFORM, H, builder, continuous=True, visuals=False)
    builder.ExportInput(plant.get_actuation_input_port(), "actuation")
    assert _stopped_every_step(builder.Build(), plant) > N


def test_replaying_the_logged_forces_gives_the_loop_states_bit_for_bit():
    """A fresh Simulation of the same scenario, its DSP side replaced by writing the forces the loop logged
    (the force logged at a plant step acted over the step before it) into the fixed input, stop by stop:
    the plant's states at every plant step equal the loop's bit for bit — the loop tells Drake nothing but
    the force."""
    duration = 0.2
    loop = build_simulation(Scenario(PLATFORM, "seed", "fixed", engine="c"))
    loop.run(duration)
    logged = loop.controller._raw
    replay = build_simulation(Scenario(PLATFORM, "seed", "fixed", engine="c"))
    tick_loop = replay.controller
    s = tick_loop._schedule(duration, ())
    x, actuation = tick_loop._views()
    np.testing.assert_array_equal(actuation, logged["force"][0])  # the same initial force
    states, row = [x.copy()], 1
    for t, logs_here in zip(s.times, s.log):
        actuation[:] = logged["force"][row]
        tick_loop._fixed.GetMutableData()
        replay.simulator.AdvanceTo(t)
        if logs_here:
            states.append(x.copy())
            row += 1
    assert row == len(logged["state"])
    np.testing.assert_array_equal(np.array(states), logged["state"])
