"""The closed loop's compiled DSP side (``firmware.loop_kernel``, ``fixedpoint/c/sd_loop.c``) against the Python
loop it replaces (``TickLoop.run`` with ``kernel = None``: the numpy laws, ``dsp_state``, the Python sensor): the
logs must be equal bit for bit — float law and compiled firmware, a noisy, jittery, offset sensor, every
latency, a continuous and a discrete plant, progress boundaries with a callback. And the zero-copy views of
Drake's memory the kernel reads and writes: the same memory after ``AdvanceTo``, seen by Drake.
Short runs (40 ms) of the seed trajectory on ``utn-dynamic``.
"""

import subprocess
import sys

import numpy as np
import pytest

from stewart_drake.control import ControllerConfig, DspTiming
from stewart_drake.core.geometry import load_preset
from stewart_drake.drake.simulation import ActuatorModel, Scenario, SensorModel, SimulationLog, build_simulation

PLATFORM = load_preset("utn-dynamic")
DURATION = 0.04


def noisy_sensor(seed: int = 3) -> SensorModel:
    """Noise of a few counts, jitter of a few µs and an offset per leg: every term of the reading non-zero."""
    rng = np.random.default_rng(seed)
    n = int(DURATION / 1e-3) + 1
    return SensorModel(rng.normal(0, 2e-5, 6), rng.normal(0, 1.5e-5, (n, 6)), rng.normal(0, 5e-6, n), 1e-3)


def run_both(sc: Scenario, boundaries=False, prepare=lambda sim: sim) -> tuple:
    """The logs (and plant states) of ``sc`` with the compiled kernel and with the Python loop (``prepare``:
    applied to each built Simulation)."""
    out = []
    for compiled in (True, False):
        sim = prepare(build_simulation(sc))
        assert sim.controller.kernel is not None  # a compiler is found here
        if not compiled:
            sim.controller.kernel = None
        calls = []
        if boundaries:  # the progress bar's path: stops with a Python callback between log and update
            real = sim.controller.run
            sim.controller.run = lambda d, frames: real(d, [0.0105, 0.02, d], calls.append)
        log = sim.run(DURATION)
        out.append((log, sim.states(), calls))
    return out


@pytest.mark.parametrize(
    "kind, integrator, latency, time_constant",
    [
        ("float", "cenic-fixed", "sample", 2e-3),
        ("fixed", "cenic-fixed", "sample", 2e-3),
        ("float", "cenic-fixed", "computation", 0.0),  # a separate release; the input after the update
        ("fixed", "sap", "computation", 2e-3),  # a discrete plant: steps before its tick, loop-logged forces
        ("float", "sap", "none", 0.0),
    ],
)
def test_kernel_logs_equal_the_python_loop(kind, integrator, latency, time_constant):
    cfg = ControllerConfig.for_platform(PLATFORM, DspTiming(latency=latency, computation_cycles=15000))
    sc = Scenario(
        PLATFORM,
        "seed",
        kind,
        cfg,
        engine="c",
        actuators=ActuatorModel(time_constant=time_constant),
        integrator=integrator,
        sensor=noisy_sensor(),
    )
    (a, xa, _), (b, xb, _) = run_both(sc)
    np.testing.assert_array_equal(xa, xb)
    for name in SimulationLog.ARRAYS:
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert np.ptp(a.command, axis=0).min() > 0.1  # the command moved


def test_kernel_with_boundaries_and_without_feedforward():
    """Progress boundaries (a callback at three stops, the last the end) and no feed-forward table."""
    sc = Scenario(PLATFORM, "seed", "float", feedforward=False, sensor=noisy_sensor(5))
    (a, xa, calls_a), (b, xb, calls_b) = run_both(sc, boundaries=True)
    assert calls_a == calls_b == [0.0105, 0.02, DURATION]
    np.testing.assert_array_equal(xa, xb)
    for name in SimulationLog.ARRAYS:
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)


def test_kernel_adds_the_float_laws_setpoint_offset():
    """The float law's ``setpoint_offset`` (the probe of ``setpoint_step_gain``): the compiled loop adds it to
    its set-point table, the Python loop per tick (``FloatLaw.setpoints``); the logs are equal bit for bit, and
    the logged set-points are those of a run without the offset plus the offset (the rest run's IK, one addition)."""
    offset = np.array([1e-3, 0.0, -2e-4, 0.0, 0.0, 3e-5])

    def with_offset(sim):
        sim.controller.law.setpoint_offset = offset
        return sim

    sc = Scenario(PLATFORM, "seed", "float", sensor=noisy_sensor(7))
    (a, xa, _), (b, xb, _) = run_both(sc, prepare=with_offset)
    np.testing.assert_array_equal(xa, xb)
    for name in SimulationLog.ARRAYS:
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    plain = build_simulation(sc).run(DURATION)
    released = plain.status[:, 2] > 0  # rows after the first release: the held set-points are the ticks'
    assert released.sum() > 30
    np.testing.assert_array_equal(a.setpoint[released], plain.setpoint[released] + offset)


@pytest.mark.parametrize(
    "kind, integrator, latency, compiled",
    [
        ("float", "cenic-fixed", "sample", True),
        ("fixed", "cenic-fixed", "computation", True),  # separate releases
        ("fixed", "sap", "sample", True),  # a discrete plant: a step before the tick at the resumed stop
        ("float", "sap", "computation", False),  # the Python loop
        ("fixed", "cenic-fixed", "sample", False),
    ],
)
def test_extended_run_equals_one_run(kind, integrator, latency, compiled):
    """``Simulation.extend``: a run of 20 ms continued to 40 ms logs what one 40 ms run logs, bit for bit (plant
    states included: the integrator took the same steps), with the compiled loop and the Python one. And a
    run ended between stops (20.5 ms, 31 ms) and continued is the one run with stops there (``run``'s
    boundaries): the continuation adds no other difference."""
    cfg = ControllerConfig.for_platform(PLATFORM, DspTiming(latency=latency, computation_cycles=15000))
    sc = Scenario(PLATFORM, "seed", kind, cfg, engine="c", integrator=integrator, sensor=noisy_sensor(11))

    def built():
        sim = build_simulation(sc)
        assert sim.controller.kernel is not None
        if not compiled:
            sim.controller.kernel = None
        return sim

    extended, one = built(), built()
    extended.run(0.02)
    a, b = extended.extend(DURATION), one.run(DURATION)
    assert len(a.t) == len(b.t) >= 41  # every plant step (and, for a discrete plant, every stop)
    np.testing.assert_array_equal(extended.states(), one.states())
    for name in SimulationLog.ARRAYS:
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    off_grid, stops = built(), built()
    off_grid.run(0.0205)
    off_grid.extend(0.031)
    off_grid.extend(DURATION)
    stops.prepare(DURATION)
    raw = stops.controller.run(DURATION, [0.0205, 0.031])
    for name in ("times", "command", "setpoint", "status", "state", "force"):
        np.testing.assert_array_equal(off_grid._logs[name], raw[name], err_msg=name)
    with pytest.raises(RuntimeError, match="extended to 0.03 s after 0.04 s"):
        off_grid.extend(0.03)


@pytest.mark.parametrize("integrator", ["cenic-fixed", "sap"])
def test_views_of_drake_memory_hold_across_advance(integrator):
    """The plant state view (the context's continuous or discrete state vector) is the memory Drake writes each
    step into: after ``AdvanceTo`` it shows the new state — equal to ``GetPositionsAndVelocities`` — at the same
    address; a force written through the actuation view, then ``GetMutableData`` (Drake told), is what the
    plant's actuation port evaluates to, and what the plant integrates with (a different force, a different
    motion)."""
    runs = []
    for push in (0.0, 50.0):
        sim = build_simulation(Scenario(PLATFORM, "seed", "float", integrator=integrator))
        loop = sim.controller
        x, actuation = loop._views()
        address, x0 = x.__array_interface__["data"][0], x.copy()
        actuation[:] = loop.lag_force + push
        loop._fixed.GetMutableData()
        port = sim.plant.get_actuation_input_port()
        np.testing.assert_array_equal(port.Eval(loop.plant_context), loop.lag_force + push)
        sim.simulator.AdvanceTo(0.003)
        assert x.__array_interface__["data"][0] == address
        assert not np.array_equal(x, x0)  # it moved with the plant
        np.testing.assert_array_equal(x, sim.plant.GetPositionsAndVelocities(loop.plant_context))
        again = loop._views()
        assert [a.__array_interface__["data"][0] for a in again] == [
            a.__array_interface__["data"][0] for a in (x, actuation)
        ]
        runs.append(x.copy())
    assert not np.array_equal(*runs)


def test_float_loop_without_a_compiler_runs_python_with_one_note(tmp_path):
    """No C compiler (``$STEWART_DRAKE_CC`` not one, an empty build cache): the float loop runs the Python
    ticks, says so once on stderr, and logs what the compiled loop logs."""
    code = (
        "import numpy as np\n"
        "from stewart_drake.core.geometry import load_preset\n"
        "from stewart_drake.drake.simulation import Scenario, build_simulation\n"
        "sims = [build_simulation(Scenario(load_preset('utn-dynamic'), 'seed', 'float')) for _ in range(2)]\n"
        "print(sims[0].controller.kernel is None)\n"
        "np.save(sys.argv[1], sims[0].run(0.02).command)\n"
    )
    import os

    env = dict(os.environ, STEWART_DRAKE_CC="false", STEWART_DRAKE_CACHE=str(tmp_path / "cache"))
    out = tmp_path / "command.npy"
    r = subprocess.run(
        [sys.executable, "-c", "import sys\n" + code, str(out)], env=env, capture_output=True, text=True, timeout=300
    )
    assert r.returncode == 0, r.stderr
    assert r.stdout.split() == ["True"]
    from stewart_drake.firmware.loop_kernel import NO_COMPILER_NOTE

    assert r.stderr.count(NO_COMPILER_NOTE) == 1
    compiled = build_simulation(Scenario(PLATFORM, "seed", "float"))
    assert compiled.controller.kernel is not None
    np.testing.assert_array_equal(np.load(out), compiled.run(0.02).command)


def test_kernel_leaves_sensor_tables_it_cannot_index_to_python():
    """Noise rows that do not match the jitter rows, or none at all: the C code would read outside them, so
    the Python loop runs (and raises where numpy does)."""
    from stewart_drake.control.laws import FloatLaw
    from stewart_drake.control.loop_sensor import SensorReading
    from stewart_drake.firmware.loop_kernel import make_kernel

    law, pos = FloatLaw(PLATFORM), np.arange(6)

    def sensor(noise_rows, jitter_rows):
        return SensorReading(pos, pos + 6, np.zeros(6), np.zeros((noise_rows, 6)), np.zeros(jitter_rows), 1e-3)

    assert make_kernel(law, sensor(3, 3)) is not None
    assert make_kernel(law, sensor(2, 3)) is None
    assert make_kernel(law, sensor(0, 0)) is None
