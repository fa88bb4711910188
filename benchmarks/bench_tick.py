"""Where a closed-loop tick's microseconds go (item 1 of the speed issue), each target beside its figure and
its reference, all measured in one run, interleaved, best of ``--repeat``:

- references: the bare plant (constant leg forces, one ``AdvanceTo``: the issue's reference) and the plant
  the loop drives — the loop's own Diagram (``loop_diagram``: the plant alone, its actuation a fixed input)
  advanced tick by tick with the actuators' lag stepped on a command that changes every tick, the force
  written through a view of Drake's memory (no law, no logs): the ceiling of any loop on this Diagram;
- the loops with their compiled DSP side (``firmware.loop_kernel``: one C call per stop): the fixed-point
  law with the generated firmware (C engine) and the float law, each with its tick tables computed cold
  (``TABLE_CACHE`` cleared: a report's or a study's first run) and remembered (every later run of the same
  reference and model in the process); target ≥ 0.8 × the bare plant's real-time factor;
- the same loops with the Python ticks (``TickLoop._run_python``, the reference and the fallback) for
  comparison;
- the DSP side alone per tick, with ``AdvanceTo`` replaced by a no-op (load-robust: no Drake work in it),
  against the ceiling's own Python per tick (write the command, notify Drake).

Run by hand: ``python benchmarks/bench_tick.py [--duration 2] [--repeat 3]``. At 1 kHz a simulated
millisecond is one tick, so µs per tick = 1000 / real-time factor. Process CPU time (on a loaded machine wall
time includes waiting for a core); prints the load first and last: on a shared machine the ratios are what
travel. Measures only: it changes nothing in the loop.
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("MPLBACKEND", "Agg")

import numpy as np  # noqa: E402
from bench_integrators import CONTINUOUS, apply_integrator  # noqa: E402  (benchmarks/ is the script's folder)

from stewart_drake.control.feedforward import TABLE_CACHE  # noqa: E402
from stewart_drake.core.geometry import load_preset  # noqa: E402
from stewart_drake.drake.integrators import DEFAULT_INTEGRATOR  # noqa: E402
from stewart_drake.drake.simulation import ActuatorModel, Scenario, build_simulation  # noqa: E402

TARGET = 0.8  # the loop's real-time factor over the bare plant's
PERIOD = 1e-3  # s: the plant step and the controller's sample period of the default loop


def load() -> str:
    return "load average " + ", ".join(f"{x:.2f}" for x in os.getloadavg())


def plant(p, duration: float) -> float:
    """CPU µs per tick of the plant alone (``bench_integrators.bare_plant``'s set-up: the legs pushed with
    home's static forces; build excluded)."""
    from pydrake.systems.analysis import Simulator
    from pydrake.systems.framework import DiagramBuilder
    from pydrake.systems.primitives import ConstantVectorSource

    from stewart_drake.core.dynamics import leg_forces_with_legs
    from stewart_drake.drake.platform_model import build_plant, set_pose

    builder = DiagramBuilder()
    mbp, _ = build_plant(p, PERIOD, builder, continuous=DEFAULT_INTEGRATOR in CONTINUOUS)
    F = leg_forces_with_legs(p, p.home_pose(), np.zeros(6), np.zeros(6))
    src = builder.AddSystem(ConstantVectorSource(F))
    builder.Connect(src.get_output_port(), mbp.get_actuation_input_port())
    sim = Simulator(builder.Build())
    apply_integrator(sim, DEFAULT_INTEGRATOR, PERIOD)
    set_pose(mbp, mbp.GetMyMutableContextFromRoot(sim.get_mutable_context()), p, p.home_pose())
    sim.Initialize()
    c0 = time.process_time()
    sim.AdvanceTo(duration)
    return 1e6 * PERIOD * (time.process_time() - c0) / duration


def driven_plant(p, duration: float) -> float:
    """CPU µs per tick of the loop's own Diagram (``loop_diagram``: the plant, its actuation a fixed input)
    advanced tick by tick, the actuators' lag stepped in numpy on a leg-force command that changes every tick
    (±1e-6 relative about home's static forces) and the force written through a view of the fixed input with
    Drake notified (``GetMutableData``), as the loop does: the loop without its DSP side."""
    from pydrake.systems.analysis import Simulator

    from stewart_drake.control.actuation import Actuation
    from stewart_drake.core.dynamics import leg_forces_with_legs
    from stewart_drake.drake.loop_diagram import loop_diagram
    from stewart_drake.drake.platform_model import set_pose

    built = loop_diagram(p, PERIOD, DEFAULT_INTEGRATOR)
    act = Actuation.from_time_constant(float(p.legs.max_force), ActuatorModel().time_constant, PERIOD)
    sim = Simulator(built.diagram)
    apply_integrator(sim, DEFAULT_INTEGRATOR, PERIOD)
    root = sim.get_mutable_context()
    set_pose(built.plant, built.plant.GetMyMutableContextFromRoot(root), p, p.home_pose())
    F = leg_forces_with_legs(p, p.home_pose(), np.zeros(6), np.zeros(6))
    fixed = built.diagram.GetInputPort("actuation").FixValue(root, F)
    view = fixed.GetMutableData().get_mutable_value().get_mutable_value()
    commands = [F * (1 + 1e-6), F * (1 - 1e-6)]
    notify, advance = fixed.GetMutableData, sim.AdvanceTo
    sim.Initialize()
    n = int(round(duration / PERIOD))
    c0 = time.process_time()
    for k in range(1, n + 1):
        F = act.step(F, commands[k % 2])
        view[:] = F
        notify()
        advance(k * PERIOD)
    return 1e6 * (time.process_time() - c0) / n


TABLES: dict[str, float] = {}  # CPU µs per tick of Simulation.prepare (the tick tables), per loop label


def loop(p, label: str, kind: str, engine: str, duration: float, cold: bool, python: bool = False) -> float:
    """CPU µs per tick of one closed-loop run (build excluded; the tick tables that ``run`` fills first
    included, their share noted in ``TABLES``). ``cold``: the feed-forward table computed, not remembered
    from an earlier run of the process; ``python``: the Python ticks instead of the compiled kernel."""
    sim = build_simulation(Scenario(p, "seed", kind, engine=engine))
    if python:
        sim.controller.kernel = None
    if cold:
        TABLE_CACHE.clear()
    else:
        sim.prepare(duration)  # remembered from here on (the cache keeps the table, not the Simulation)
    c0 = time.process_time()
    sim.prepare(duration)
    c1 = time.process_time()
    sim.prepare = lambda d: None  # filled above
    sim.run(duration)
    c2 = time.process_time()
    n = duration / PERIOD
    TABLES[label] = min(TABLES.get(label, np.inf), 1e6 * (c1 - c0) / n)
    return 1e6 * (c2 - c0) / n


class _NoAdvance:
    """A Simulator whose ``AdvanceTo`` does nothing (the plant stays put): the loop's DSP side alone."""

    def __init__(self, simulator):
        self._simulator = simulator

    def AdvanceTo(self, t):  # noqa: N802  (Drake's name)
        pass

    def get_context(self):
        return self._simulator.get_context()


def dsp_side(p, kind: str, engine: str, duration: float) -> float:
    """Wall µs per tick of the loop without Drake's work (``AdvanceTo`` a no-op, tables filled before): the
    compiled kernel's call, Drake's notification and the Python ``for`` per stop."""
    sim = build_simulation(Scenario(p, "seed", kind, engine=engine))
    sim.prepare(duration)
    sim.controller.simulator = _NoAdvance(sim.simulator)
    t0 = time.perf_counter()
    sim.controller.run(duration)
    return 1e6 * (time.perf_counter() - t0) / (duration / PERIOD)


def ceiling_python(p, duration: float) -> float:
    """Wall µs per tick of the ceiling's own Python (the lag stepped in numpy, the force written through the
    view, Drake notified, a no-op ``AdvanceTo``): what ``driven_plant`` spends per tick besides Drake's work."""
    sim = build_simulation(Scenario(p, "seed", "float"))
    fixed, act = sim.controller._fixed, sim.controller.actuators
    view = fixed.GetMutableData().get_mutable_value().get_mutable_value()
    commands, F = [np.ones(6), np.full(6, 2.0)], np.zeros(6)
    notify, advance = fixed.GetMutableData, _NoAdvance(None).AdvanceTo
    n = int(round(duration / PERIOD))
    t0 = time.perf_counter()
    for k in range(1, n + 1):
        F = act.step(F, commands[k % 2])
        view[:] = F
        notify()
        advance(k * PERIOD)
    return 1e6 * (time.perf_counter() - t0) / n


LOOPS = {  # label: (kind, engine, cold tables, Python ticks)
    "fixed/C, cold tables": ("fixed", "c", True, False),
    "fixed/C, remembered tables": ("fixed", "c", False, False),
    "float, cold tables": ("float", "python", True, False),
    "float, remembered tables": ("float", "python", False, False),
    "fixed/C, Python ticks, remembered tables": ("fixed", "c", False, True),
    "float, Python ticks, remembered tables": ("float", "python", False, True),
}
PLANT, DRIVEN = "bare plant (the reference)", "the loop's Diagram driven tick by tick (ceiling)"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--duration", type=float, default=2.0)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    D = args.duration
    print(f"# closed-loop tick breakdown, utn-dynamic, seed trajectory, {DEFAULT_INTEGRATOR}, 1 kHz; {load()}")
    p = load_preset("utn-dynamic")
    loop(p, "warm-up", "fixed", "c", 0.01, True)  # compile and cache the firmware and the kernel before timing
    loop(p, "warm-up", "float", "python", 0.01, True)
    runs = {PLANT: lambda: plant(p, D), DRIVEN: lambda: driven_plant(p, D)}
    runs |= {label: (lambda a=a, label=label: loop(p, label, a[0], a[1], D, a[2], a[3])) for label, a in LOOPS.items()}
    best = dict.fromkeys(runs, np.inf)
    for _ in range(args.repeat):
        for k, f in runs.items():
            best[k] = min(best[k], f())
    us = best  # CPU µs per tick
    print("(process CPU µs per tick, best of the repetitions; real-time factor = 1e3 / µs)")
    for k, v in us.items():
        extra = ""
        if k != PLANT:
            ratio = us[PLANT] / v
            target = f"; target >= {TARGET}: {'met' if ratio >= TARGET else 'NOT met'}" if k in LOOPS else ""
            extra = f"  {ratio:.2f} × the bare plant's real-time factor{target}"
        print(f"  {k:48s} {v:6.1f} µs = real-time factor {1e3 / v:6.2f}x{extra}")
    driven = us[DRIVEN]
    print(
        "where a tick's µs go (the loop = plant + driving it + tick tables + the rest: the DSP side, see below, and\n"
        "  the plant's extra work along the reference — the bare plant and the ceiling rest at home):"
    )
    for label in LOOPS:
        tables = TABLES[label]
        rest = us[label] - driven - tables
        print(
            f"  {label:48s} {us[label]:6.1f} = plant {us[PLANT]:5.1f} + driving it (an AdvanceTo per tick, a "
            f"changing force) {driven - us[PLANT]:4.1f} + tick tables {tables:4.1f} + DSP side and motion {rest:5.1f}"
        )
    print("the DSP side alone, AdvanceTo a no-op (wall µs per tick, best of the repetitions):")
    alone = {
        "fixed/C, compiled kernel": lambda: dsp_side(p, "fixed", "c", D),
        "float, compiled kernel": lambda: dsp_side(p, "float", "python", D),
        "the ceiling's own Python (lag, write, notify)": lambda: ceiling_python(p, D),
    }
    for k, f in alone.items():
        print(f"  {k:48s} {min(f() for _ in range(args.repeat)):6.2f} µs")
    print(f"# {load()}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
