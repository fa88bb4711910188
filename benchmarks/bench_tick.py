"""Where a closed-loop tick's microseconds go (item 1 of the speed issue), each target beside its figure and
its reference, all measured in one run, interleaved, best of ``--repeat``:

- references: the bare plant (constant leg forces, one ``AdvanceTo``: the issue's reference), the loop's
  own Diagram (``loop_diagram``: the plant, its actuation a fixed input, an event every plant step) at rest,
  advanced tick by tick: the cost of stopping at every tick, and Drake's work in each loop alone (its Diagram
  and stops replaying its logged forces, no DSP side: the loop's states bit for bit, ``replayed_plant``);
- the loops with their compiled DSP side (``firmware.loop_kernel``: one C call per stop): the fixed-point
  law with the generated firmware (C engine) and the float law, each with its tick tables computed cold
  (``TABLE_CACHE`` cleared: a report's or a study's first run) and remembered (every later run of the same
  reference and model in the process); target ≥ 0.8 × the bare plant's real-time factor; the cold fixed/C
  loop's feed-forward by the compiled inverse dynamics (``core.leg_forces_kernel``, the default) and by numpy
  (the reference and the fallback);
- the same loops with the Python ticks (``TickLoop._run_python``, the reference and the fallback) for
  comparison;
- where a loop's tick goes: the tables, the thread CPU inside Drake's ``AdvanceTo`` (beside the bare plant's,
  the stopped plant's and the replay's: the plant's work along the loop's own motion) and outside it;
- the DSP side alone per tick, with ``AdvanceTo`` replaced by a no-op (load-robust: no Drake work in it);
- the feed-forward table's peak memory (tracemalloc) for runs of 2, 20 and 200 s beside the table itself: the
  target is a working memory independent of the run's length beyond the table (the log's own rows).

Inside ``AdvanceTo``, one change at a time from the bare plant to the loop: ``bench_loop_drake.py``.

Run by hand: ``python benchmarks/bench_tick.py [--duration 2] [--repeat 3]``. At 1 kHz a simulated
millisecond is one tick, so µs per tick = 1000 / real-time factor. Process CPU time (on a loaded machine wall
time includes waiting for a core); prints the load first and last: on a shared machine the ratios are what
travel. Measures only: it changes nothing in the loop.
"""

from __future__ import annotations

import argparse
import os
import time
import tracemalloc

os.environ.setdefault("MPLBACKEND", "Agg")

import numpy as np  # noqa: E402
from bench_integrators import CONTINUOUS, apply_integrator  # noqa: E402  (benchmarks/ is the script's folder)

from stewart_drake.control.feedforward import CHUNK_ROWS, TABLE_CACHE, feedforward_engine  # noqa: E402
from stewart_drake.core.geometry import load_preset  # noqa: E402
from stewart_drake.drake.integrators import DEFAULT_INTEGRATOR  # noqa: E402
from stewart_drake.drake.simulation import Scenario, build_simulation  # noqa: E402

TARGET = 0.8  # the loop's real-time factor over the bare plant's
MEMORY_RUNS_S = (2.0, 20.0, 200.0)  # run lengths of the table's memory measure: below one chunk, 5 and 49 chunks
NEWTON: dict[str, float] = {}  # CENIC's Newton iterations (Hessian factorisations) per step, per reference


def newton(label: str, sim) -> None:
    """Note ``sim``'s CENIC solver iterations per integrator step under ``label`` (``NEWTON``)."""
    stats = dict(sim.get_integrator().GetStatisticsSummary())
    NEWTON[label] = stats.get("cenic_total_solver_iterations", np.nan) / stats["integrator_num_steps_taken"]


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
    # built as the closed loop builds its plant when nothing is shown (no SceneGraph): a fair reference
    mbp, _ = build_plant(p, PERIOD, builder, continuous=DEFAULT_INTEGRATOR in CONTINUOUS, visuals=False)
    F = leg_forces_with_legs(p, p.home_pose(), np.zeros(6), np.zeros(6))
    src = builder.AddSystem(ConstantVectorSource(F))
    builder.Connect(src.get_output_port(), mbp.get_actuation_input_port())
    sim = Simulator(builder.Build())
    apply_integrator(sim, DEFAULT_INTEGRATOR, PERIOD)
    set_pose(mbp, mbp.GetMyMutableContextFromRoot(sim.get_mutable_context()), p, p.home_pose())
    sim.Initialize()
    c0 = time.process_time()
    sim.AdvanceTo(duration)
    us = 1e6 * PERIOD * (time.process_time() - c0) / duration
    newton(PLANT, sim)
    return us


def stopped_plant(p, duration: float) -> float:
    """CPU µs per tick of the loop's own Diagram (``loop_diagram``: the plant, its actuation a fixed input, the
    clock's event at every plant step) held at home by constant leg forces and advanced tick by tick: the cost
    of stopping at every tick, without a law, a changing force or motion."""
    from pydrake.systems.analysis import Simulator

    from stewart_drake.core.dynamics import leg_forces_with_legs
    from stewart_drake.drake.loop_diagram import loop_diagram
    from stewart_drake.drake.platform_model import set_pose

    built = loop_diagram(p, PERIOD, DEFAULT_INTEGRATOR)
    sim = Simulator(built.diagram)
    apply_integrator(sim, DEFAULT_INTEGRATOR, PERIOD)
    root = sim.get_mutable_context()
    set_pose(built.plant, built.plant.GetMyMutableContextFromRoot(root), p, p.home_pose())
    F = leg_forces_with_legs(p, p.home_pose(), np.zeros(6), np.zeros(6))
    built.diagram.GetInputPort("actuation").FixValue(root, F)
    advance = sim.AdvanceTo
    sim.Initialize()
    n = int(round(duration / PERIOD))
    c0 = time.process_time()
    for k in range(1, n + 1):
        advance(k * PERIOD)
    us = 1e6 * (time.process_time() - c0) / n
    newton(STOPPED, sim)
    return us


def replayed_plant(p, kind: str, engine: str, duration: float) -> float:
    """CPU µs per tick of Drake's work in one closed-loop run, without its DSP side: the loop's own Diagram,
    initial state and stops (a fresh ``build_simulation`` of the same scenario), its actuation input written
    (and Drake notified) only where the force the loop logged changes, as the compiled kernel does. The
    plant's states are the loop's bit for bit (checked: else a RuntimeError), so this is the plant's work
    along the loop's own motion — the floor of the loop's cost inside ``AdvanceTo``.

    (Why not the plant alone replaying those forces in one ``AdvanceTo`` from a ``TrajectorySource``: without
    the loop's clock events its integration is not the loop's — Drake reaches a time that is no event time by
    an extra short step after t = 1 s, 2496 steps for 2000 plant steps when stopped every tick — and an
    open-loop replay's states leave the loop's: not the same motion.)"""
    loop_run = build_simulation(Scenario(p, "seed", kind, engine=engine))
    loop_run.prepare(duration)
    logged = loop_run.controller.run(duration)
    sim = build_simulation(Scenario(p, "seed", kind, engine=engine))
    loop = sim.controller
    s = loop._schedule(duration, ())
    x, actuation = loop._views()
    # the force logged at a plant step t_r acted over (t_r-1, t_r]: write row r before advancing to t_r (and to
    # the stops between, where it does not change); None where it equals the force already written
    force, rows, row = logged["force"], [], 1
    for logs_here in s.log:
        rows.append(row)
        row += logs_here
    writes, written = [], actuation.copy()
    for r in rows:
        writes.append(None if np.array_equal(force[r], written) else force[r])
        written = force[r]
    notify, advance = loop._fixed.GetMutableData, sim.simulator.AdvanceTo
    c0 = time.process_time()
    for t, f in zip(s.times, writes):
        if f is not None:
            actuation[:] = f
            notify()
        advance(t)
    us = 1e6 * PERIOD * (time.process_time() - c0) / duration
    if not np.array_equal(x, logged["state"][-1]):
        raise RuntimeError("the replay left the loop's states: not a reference for its Drake work")
    newton(f"{kind} loop", sim.simulator)
    return us


TABLES: dict[str, float] = {}  # CPU µs per tick of Simulation.prepare (the tick tables), per loop label


def loop(
    p, label: str, kind: str, engine: str, duration: float, cold: bool, python: bool = False, ff: str = ""
) -> float:
    """CPU µs per tick of one closed-loop run (build excluded; the tick tables that ``run`` fills first
    included, their share noted in ``TABLES``). ``cold``: the feed-forward table computed, not remembered
    from an earlier run of the process; ``python``: the Python ticks instead of the compiled kernel; ``ff``:
    the feed-forward's inverse dynamics (``"numpy"``; else the law's default, ``feedforward_engine``)."""
    sim = build_simulation(Scenario(p, "seed", kind, engine=engine))
    if python:
        sim.controller.kernel = None
    if ff:
        sim.feedforward.engine = ff
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


class _TimedAdvance(_NoAdvance):
    """A Simulator whose ``AdvanceTo`` adds its thread CPU time to ``inside``."""

    inside = 0.0

    def AdvanceTo(self, t):  # noqa: N802  (Drake's name)
        c = time.thread_time()
        self._simulator.AdvanceTo(t)
        self.inside += time.thread_time() - c


def split(p, kind: str, engine: str, duration: float) -> tuple[float, float]:
    """``(inside, outside)``: thread CPU µs per tick of one loop run (tables filled before) spent inside Drake's
    ``AdvanceTo`` and outside it (the DSP side and the Python loop), the two timer reads per call (calibrated)
    taken out of the outside share."""
    c = time.thread_time()
    for _ in range(10000):
        time.thread_time()
    read = (time.thread_time() - c) / 10000  # one timer read
    sim = build_simulation(Scenario(p, "seed", kind, engine=engine))
    sim.prepare(duration)
    timed = _TimedAdvance(sim.simulator)
    sim.controller.simulator = timed
    c = time.thread_time()
    sim.controller.run(duration)
    total = time.thread_time() - c
    n = duration / PERIOD
    return 1e6 * timed.inside / n, 1e6 * (total - timed.inside - 2 * read * n) / n


def dsp_side(p, kind: str, engine: str, duration: float) -> float:
    """Wall µs per tick of the loop without Drake's work (``AdvanceTo`` a no-op, tables filled before): the
    compiled kernel's call, Drake's notification and the Python ``for`` per stop."""
    sim = build_simulation(Scenario(p, "seed", kind, engine=engine))
    sim.prepare(duration)
    sim.controller.simulator = _NoAdvance(sim.simulator)
    t0 = time.perf_counter()
    sim.controller.run(duration)
    return 1e6 * (time.perf_counter() - t0) / (duration / PERIOD)


def table_memory(p, duration: float) -> tuple[int, int]:
    """``(peak bytes, table bytes)``: tracemalloc's peak while a cold feed-forward table of ``duration`` s is
    computed (``FeedforwardTable.prime``, the fixed-point loop's engine), and the table's own size."""
    from stewart_drake.control.feedforward import FeedforwardTable
    from stewart_drake.core.trajectory import get_trajectory

    TABLE_CACHE.clear()
    ticks = np.arange(int(round(duration / PERIOD)) + 1) * PERIOD
    table = FeedforwardTable(p, get_trajectory("seed"), 3.5e-3, PERIOD, feedforward_engine("fixed"))
    tracemalloc.start()
    try:
        rows = table.prime(ticks)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    TABLE_CACHE.clear()
    return peak, rows.nbytes + ticks.nbytes  # the table and the tick times the caller holds


LOOPS = {  # label: (kind, engine, cold tables, Python ticks, feed-forward engine)
    "fixed/C, cold tables": ("fixed", "c", True, False),
    "fixed/C, cold tables, numpy feed-forward": ("fixed", "c", True, False, "numpy"),
    "fixed/C, remembered tables": ("fixed", "c", False, False),
    "float, cold tables": ("float", "python", True, False),
    "float, remembered tables": ("float", "python", False, False),
    "fixed/C, Python ticks, remembered tables": ("fixed", "c", False, True),
    "float, Python ticks, remembered tables": ("float", "python", False, True),
}
PLANT, STOPPED = "bare plant (the reference)", "the loop's Diagram stopped every tick, at rest"
REPLAYS = {  # label: (kind, engine) of the loop whose Drake work is replayed
    "Drake's work in the fixed/C loop (replayed)": ("fixed", "c"),
    "Drake's work in the float loop (replayed)": ("float", "python"),
}


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
    runs = {PLANT: lambda: plant(p, D), STOPPED: lambda: stopped_plant(p, D)}
    runs |= {label: (lambda a=a: replayed_plant(p, a[0], a[1], D)) for label, a in REPLAYS.items()}
    runs |= {label: (lambda a=a, label=label: loop(p, label, *a[:2], D, *a[2:])) for label, a in LOOPS.items()}
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
    print(
        "where a tick's µs go (the loop = tick tables + Drake's AdvanceTo + the rest; thread CPU, best of the repetitions):"
    )
    splits = {"fixed/C": ("fixed", "c"), "float": ("float", "python")}
    best_split = {}
    for _ in range(args.repeat):
        for label, (kind, engine) in splits.items():
            inside, outside = split(p, kind, engine, D)
            if label not in best_split or inside + outside < sum(best_split[label]):
                best_split[label] = (inside, outside)
    for label, (inside, outside) in best_split.items():
        cold, warm = TABLES[f"{label}, cold tables"], TABLES[f"{label}, remembered tables"]
        print(
            f"  {label:8s} tables {cold:5.1f} cold / {warm:4.1f} remembered + inside AdvanceTo {inside:6.1f} + outside "
            f"{outside:4.1f} (the DSP side, the Python loop)"
        )
    fixed_replay, float_replay = (us[k] for k in REPLAYS)
    print(
        f"  (inside AdvanceTo: the bare plant's {us[PLANT]:.1f} at rest, {us[STOPPED]:.1f} stopped every tick at rest; "
        f"Drake's work along each loop's own motion, replayed: fixed/C {fixed_replay:.1f}, float {float_replay:.1f}; "
        "the loop beyond it: the DSP side, the Python loop and the tables)"
    )
    print(
        "  CENIC's Newton iterations (each one Hessian factorisation) per plant step: "
        + ", ".join(f"{label} {v:.2f}" for label, v in NEWTON.items())
        + " (at rest a warm start often needs none; along the reference every step needs one)"
    )
    print("the DSP side alone, AdvanceTo a no-op (wall µs per tick, best of the repetitions):")
    alone = {
        "fixed/C, compiled kernel": lambda: dsp_side(p, "fixed", "c", D),
        "float, compiled kernel": lambda: dsp_side(p, "float", "python", D),
    }
    for k, f in alone.items():
        print(f"  {k:48s} {min(f() for _ in range(args.repeat)):6.2f} µs")
    print(
        f"the feed-forward table's peak memory (tracemalloc; engine {feedforward_engine('fixed')}, {CHUNK_ROWS} ticks a chunk):"
    )
    beyond = {}
    for seconds in MEMORY_RUNS_S:
        peak, own = table_memory(p, seconds)
        beyond[seconds] = peak - own
        print(
            f"  {seconds:5.0f} s run: peak {peak / 1e6:7.2f} MB = the table and its times {own / 1e6:7.2f} MB + {beyond[seconds] / 1e6:5.2f} MB working"
        )
    ok = beyond[MEMORY_RUNS_S[-1]] <= 1.1 * beyond[MEMORY_RUNS_S[1]]
    print(
        f"  target: working memory independent of the run's length beyond the table (from one chunk on): "
        f"{MEMORY_RUNS_S[-1]:.0f} s vs {MEMORY_RUNS_S[1]:.0f} s {beyond[MEMORY_RUNS_S[-1]] / beyond[MEMORY_RUNS_S[1]]:.2f}x; "
        f"{'met' if ok else 'NOT met'}"
    )
    print(f"# {load()}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
