"""Where a closed-loop tick's microseconds go (item 1 of the speed issue): the plant alone, the loop with
the compiled firmware (C engine) and with the float law, and the same loop with the law's ``step``
replaced by a constant — all in one run, interleaved, best of ``--repeat``.

The loop's ticks run outside the Diagram (``drake.tick_loop``): Drake advances the plant and the
actuators with ``AdvanceTo`` from tick to tick, one Python loop does the DSP's side. Two plant references:
the bare plant (constant leg forces, one ``AdvanceTo``: the issue's reference) and the plant the loop
actually drives ("plant + actuators, input changing every tick": the actuators' lag and its loggers, an
``AdvanceTo`` per tick and a command that changes every tick, so the integrator cannot reuse what it
computed for the previous step; no Python law) — the ceiling of any loop with this Diagram.

Run by hand: ``python benchmarks/bench_tick.py [--duration 2] [--repeat 3]``. At 1 kHz a simulated
millisecond is one tick, so µs per tick = 1000 / real-time factor. Prints the load (``uptime``) first and
last; on a shared machine the ratios are what travel. Measures only: it changes nothing in the loop.
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
from stewart_drake.drake.simulation import Scenario, build_simulation  # noqa: E402

TARGET = 0.8  # the loop's real-time factor over the bare plant's


def load() -> str:
    return "load average " + ", ".join(f"{x:.2f}" for x in os.getloadavg())


def plant(p, duration: float) -> float:
    """CPU seconds per simulated second of the plant alone (``bench_integrators.bare_plant``'s set-up: the
    legs pushed with home's static forces; build excluded)."""
    from pydrake.systems.analysis import Simulator
    from pydrake.systems.framework import DiagramBuilder
    from pydrake.systems.primitives import ConstantVectorSource

    from stewart_drake.core.dynamics import leg_forces_with_legs
    from stewart_drake.drake.platform_model import build_plant, set_pose

    builder = DiagramBuilder()
    mbp, _ = build_plant(p, 1e-3, builder, continuous=DEFAULT_INTEGRATOR in CONTINUOUS)
    F = leg_forces_with_legs(p, p.home_pose(), np.zeros(6), np.zeros(6))
    src = builder.AddSystem(ConstantVectorSource(F))
    builder.Connect(src.get_output_port(), mbp.get_actuation_input_port())
    sim = Simulator(builder.Build())
    apply_integrator(sim, DEFAULT_INTEGRATOR, 1e-3)
    set_pose(mbp, mbp.GetMyMutableContextFromRoot(sim.get_mutable_context()), p, p.home_pose())
    sim.Initialize()
    c0 = time.process_time()
    sim.AdvanceTo(duration)
    return (time.process_time() - c0) / duration


def driven_plant(p, duration: float) -> float:
    """CPU seconds per simulated second of the plant with the loop's actuators (lag) and loggers, advanced
    tick by tick with a leg-force command that changes every tick (±1e-6 relative about home's static
    forces, written in place into the fixed input): the loop without its Python."""
    from pydrake.systems.analysis import Simulator
    from pydrake.systems.framework import DiagramBuilder
    from pydrake.systems.primitives import LogVectorOutput

    from stewart_drake.core.dynamics import leg_forces_with_legs
    from stewart_drake.drake.platform_model import build_plant, set_pose
    from stewart_drake.drake.systems import Actuators

    builder = DiagramBuilder()
    mbp, _ = build_plant(p, 1e-3, builder, continuous=DEFAULT_INTEGRATOR in CONTINUOUS)
    act = builder.AddSystem(Actuators(float(p.legs.max_force), 2e-3, 1e-3))
    builder.Connect(act.get_output_port(), mbp.get_actuation_input_port())
    builder.ExportInput(act.get_input_port(), "command")
    LogVectorOutput(mbp.get_state_output_port(), builder, 1e-3)
    LogVectorOutput(act.get_output_port(), builder, 1e-3)
    diagram = builder.Build()
    sim = Simulator(diagram)
    apply_integrator(sim, DEFAULT_INTEGRATOR, 1e-3)
    root = sim.get_mutable_context()
    set_pose(mbp, mbp.GetMyMutableContextFromRoot(root), p, p.home_pose())
    F = leg_forces_with_legs(p, p.home_pose(), np.zeros(6), np.zeros(6))
    act.set_force(root, F)
    fixed = diagram.GetInputPort("command").FixValue(root, F)
    commands = [F * (1 + 1e-6), F * (1 - 1e-6)]
    sim.Initialize()
    c0 = time.process_time()
    for k in range(1, int(round(duration / 1e-3)) + 1):
        fixed.GetMutableData().get_mutable_value().SetFromVector(commands[k % 2])
        sim.AdvanceTo(k * 1e-3)
    return (time.process_time() - c0) / duration


PREPARE: dict[str, float] = {}  # CPU s per simulated s of Simulation.prepare (the tick tables), per loop


def loop(p, kind: str, engine: str, duration: float, null_step: bool = False) -> float:
    """CPU seconds per simulated second of one closed-loop run (build excluded; the tick tables that
    ``run`` fills first included, their share noted in ``PREPARE``); ``null_step``: the law's step
    returns its first result every tick (the LeafSystem's Python around it still runs)."""
    sim = build_simulation(Scenario(p, "seed", kind, engine=engine))
    real_prepare = sim.prepare

    def prepare(d):
        c = time.process_time()
        real_prepare(d)
        PREPARE[kind] = min(PREPARE.get(kind, np.inf), (time.process_time() - c) / duration)

    sim.prepare = prepare
    if null_step:
        law = sim.controller.law
        real = law.step
        first = []

        def step(state, reference, measured, feedforward=None):
            if not first:
                first.append(real(state, reference, measured, feedforward))
            return first[0]

        law.step = step
    TABLE_CACHE.clear()  # the run's tables computed, not remembered from an earlier run of this process
    c0 = time.process_time()
    sim.run(duration)
    return (time.process_time() - c0) / duration


def warm_tables_us(p, kind: str, engine: str, duration: float) -> float:
    """CPU µs per tick of ``Simulation.prepare`` when this process has computed the same feed-forward table
    before (``control.feedforward.TABLE_CACHE``: a Monte Carlo worker's runs after its first, a report's
    repeated loops)."""
    sim = build_simulation(Scenario(p, "seed", kind, engine=engine))
    sim.prepare(duration)
    c0 = time.process_time()
    sim.prepare(duration)
    return 1e3 * (time.process_time() - c0) / duration


def step_us(p, engine: str, n: int = 3000) -> float:
    """µs of one ``law.step`` alone (the C engine's: one sd_host_tick call and its Python)."""
    sim = build_simulation(Scenario(p, "seed", "fixed", engine=engine))
    law = sim.controller.law
    ref, L = p.home_pose(), np.full(6, 0.7)
    pid, ff = law.initial_pid_state(L, np.zeros(6)), np.zeros(6)
    if hasattr(law, "prime"):
        law.prime(ref[None])
    law.step(pid, ref, L, ff)
    t0 = time.perf_counter()
    for _ in range(n):
        law.step(pid, ref, L, ff)
    return 1e6 * (time.perf_counter() - t0) / n


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--duration", type=float, default=2.0)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    print(f"# closed-loop tick breakdown, utn-dynamic, seed trajectory, {DEFAULT_INTEGRATOR}; {load()}")
    p = load_preset("utn-dynamic")
    loop(p, "fixed", "c", 0.01)  # compile and cache the firmware before timing
    runs = {
        "plant": lambda: plant(p, args.duration),
        "plant + actuators, input changing every tick": lambda: driven_plant(p, args.duration),
        "fixed, C engine": lambda: loop(p, "fixed", "c", args.duration),
        "fixed, C, null step": lambda: loop(p, "fixed", "c", args.duration, null_step=True),
        "float": lambda: loop(p, "float", "python", args.duration),
        "float, null step": lambda: loop(p, "float", "python", args.duration, null_step=True),
    }
    best = dict.fromkeys(runs, np.inf)
    for _ in range(args.repeat):
        for k, f in runs.items():
            best[k] = min(best[k], f())
    us = {k: 1e3 * v for k, v in best.items()}  # CPU µs per simulated ms = per tick
    print("(process CPU time, best of the repetitions: on a loaded machine wall time includes waiting for a core)")
    for k, v in us.items():
        extra = "" if k == "plant" else f"  ({us['plant'] / v:.2f} × plant's real-time factor; target >= {TARGET})"
        print(f"{k:45s} {v:6.1f} CPU µs per tick = real-time factor {1e3 / v:6.2f}x{extra}")
    for kind, full, null in (
        ("fixed/C", "fixed, C engine", "fixed, C, null step"),
        ("float", "float", "float, null step"),
    ):
        prep_us = 1e3 * PREPARE[kind.split("/")[0]]
        driven = us["plant + actuators, input changing every tick"]
        loop_us = us[null] - driven - prep_us
        law_us = us[full] - us[null]
        print(
            f"{kind:8s} tick {us[full]:6.1f} µs = plant {us['plant']:6.1f} + driving it (actuators, loggers, an "
            f"AdvanceTo per tick, a changing input) {driven - us['plant']:5.1f} + tick tables (reference, IK "
            f"words, feed-forward: before the run) {prep_us:5.1f} + the loop's Python (state read, sensor, "
            f"status, release, input, logs) {loop_us:5.1f} + law.step {law_us:5.1f}"
        )
    print(
        f"tick tables when remembered from an earlier run of the process: {warm_tables_us(p, 'fixed', 'c', args.duration):.1f}"
        " µs per tick (fixed/C)"
    )
    print(
        f"ceiling of this Diagram (no Python at all): {us['plant'] / us['plant + actuators, input changing every tick']:.2f}"
        " × plant's real-time factor"
    )
    print(f"law.step alone, C engine: {step_us(p, 'c'):.1f} µs per call (of it the sd_host_tick C call is < 1 µs)")
    print(f"# {load()}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
