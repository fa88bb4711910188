"""What the closed loop costs inside Drake's ``AdvanceTo``, configuration by configuration: from the bare plant at rest to the
loop, one change at a time — the loop's clock event, a stop at every plant step, the force as a fixed input
and its notification (``GetMutableData``), the motion along the reference (the loop's own forces, from a
``TrajectorySource`` or written into the fixed input before each step as the loop does: its states bit for
bit), and the loop itself — each with CENIC's Newton iterations per step and the integrator's steps. Also
the plant stopped at every step without the clock (why the loop's Diagram has one).

A run, quoted: where a tick's time goes (``benchmarks/bench_loop_drake.py --duration 2 --repeat 8``: process CPU µs per plant
step, best of 8, interleaved in one process; 2-core machine at load ~3): Drake's work inside ``AdvanceTo`` is
the plant's along the loop's own motion, nothing more. The bare plant at rest 63.5; with the loop's clock
event (``loop_diagram``) 64.5; stopped at every step (2000 ``AdvanceTo``) 66.6; its force a fixed input 64.6,
notified (``GetMutableData``) at every step 67.8 (no Newton iteration more: 0.48 per step either way); moving
along the reference (the loop's forces from a ``TrajectorySource``, one ``AdvanceTo``) 72.3, stopped at every
step 75.2, through the fixed input notified at every step — the loop's states bit for bit
(``tests/drake/test_loop_steps.py``) — 74.8 beside the fixed-point loop's 75.4 (float: 73.0 beside 77.1). The
motion's ~8 µs are CENIC's Newton iterations (each a Hessian factorisation): 0.48 per step at rest (a warm
start often needs none), 1.00 along the reference; so the loop's ceiling is ~0.85–0.88 × the bare plant's
real-time factor, and the DSP side, the Python ``for`` and the logs are its 1–4 µs beyond. The kernel notifies
Drake only when the force changed (with a lag: at every plant step). Tried for the clock, bit-identical and
within ±1 µs (noise): a hold of no values, a log sink's publish.

Run by hand: ``python benchmarks/bench_loop_drake.py [--duration 2] [--repeat 5]``. Process CPU µs per plant
step, best of the repetitions, the configurations interleaved in one process; prints the load first and last
(on a shared machine the ratios are what travel). Measures only.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from bench_tick import PERIOD, load  # benchmarks/ is the script's folder
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource, TrajectorySource, ZeroOrderHold
from pydrake.trajectories import PiecewisePolynomial

from stewart_drake.core.dynamics import leg_forces_with_legs
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.trajectory import get_trajectory
from stewart_drake.drake.integrators import apply_integrator
from stewart_drake.drake.platform_model import build_plant, set_pose
from stewart_drake.drake.simulation import Scenario, build_simulation, set_velocity

PLATFORM = "utn-dynamic"


def _stats(simulator) -> tuple[float, int]:
    """(CENIC's solver iterations per integrator step, integrator steps) of ``simulator``'s run."""
    s = dict(simulator.get_integrator().GetStatisticsSummary())
    steps = s["integrator_num_steps_taken"]
    return s.get("cenic_total_solver_iterations", np.nan) / steps, steps


def plant_run(p, forces, source: str, clock: bool, moving: bool, mode: str, duration: float):
    """One run of the plant alone (no SceneGraph, as the loop builds it): its actuation from a constant
    source at home's static forces (``source`` "const"), a ``TrajectorySource`` holding ``forces`` over each
    step ("traj") or a fixed input ("fixed": at rest home's forces, moving ``forces[k]`` written before the step
    to k·h as the loop does); ``clock``: the loop's event at every plant step; ``moving``: from the seed's
    initial pose and velocity, else at home; ``mode``: "one" ``AdvanceTo``, "steps" one per plant step,
    "notify" one per plant step with the input notified before each. Returns (µs per step, iterations per
    step, integrator steps, final state)."""
    b = DiagramBuilder()
    mbp, _ = build_plant(p, PERIOD, b, continuous=True, visuals=False)
    home = leg_forces_with_legs(p, p.home_pose(), np.zeros(6), np.zeros(6))
    n = round(duration / PERIOD)
    if source == "const":
        b.Connect(b.AddSystem(ConstantVectorSource(home)).get_output_port(), mbp.get_actuation_input_port())
    elif source == "traj":  # forces[k] over [t_k-1, t_k)
        hold = PiecewisePolynomial.ZeroOrderHold(PERIOD * np.arange(n), forces[1 : n + 1].T)
        b.Connect(b.AddSystem(TrajectorySource(hold)).get_output_port(), mbp.get_actuation_input_port())
    else:
        b.ExportInput(mbp.get_actuation_input_port(), "actuation")
    if clock:
        hold = b.AddSystem(ZeroOrderHold(PERIOD, 1))
        b.Connect(b.AddSystem(ConstantVectorSource(np.zeros(1))).get_output_port(), hold.get_input_port())
    diagram = b.Build()
    sim = Simulator(diagram)
    apply_integrator(sim, "cenic-fixed", PERIOD)
    root = sim.get_mutable_context()
    pc = mbp.GetMyMutableContextFromRoot(root)
    if moving:
        trajectory = get_trajectory("seed")
        set_pose(mbp, pc, p, trajectory.pose(0.0))
        set_velocity(mbp, pc, p, trajectory, 0.0)
    else:
        set_pose(mbp, pc, p, p.home_pose())
    rows = forces if moving else np.tile(home, (n + 1, 1))
    fixed = diagram.GetInputPort("actuation").FixValue(root, rows[0]) if source == "fixed" else None
    sim.Initialize()
    times = [k * PERIOD for k in range(n + 1)]  # Drake's periodic times, offset + k·period
    advance = sim.AdvanceTo
    c0 = time.process_time()
    if mode == "one":
        advance(times[-1])
    elif mode == "steps":
        for k in range(1, n + 1):
            advance(times[k])
    else:
        view, notify = fixed.GetMutableData().get_mutable_value().get_mutable_value(), fixed.GetMutableData
        for k in range(1, n + 1):
            view[:] = rows[k]
            notify()
            advance(times[k])
    us = 1e6 * (time.process_time() - c0) / n
    return (us, *_stats(sim), mbp.GetPositionsAndVelocities(pc).copy())


def loop_run(p, kind: str, engine: str, duration: float):
    """One closed-loop run (tick tables filled before): (µs per step, iterations per step, steps, final state)."""
    sim = build_simulation(Scenario(p, "seed", kind, engine=engine))
    sim.prepare(duration)
    c0 = time.process_time()
    sim.controller.run(duration)
    us = 1e6 * PERIOD * (time.process_time() - c0) / duration
    plant, pc = sim.controller.plant, sim.controller.plant_context
    return (us, *_stats(sim.simulator), plant.GetPositionsAndVelocities(pc).copy())


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--duration", type=float, default=2.0)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args(argv)
    D = args.duration
    print(f"# the loop inside Drake's AdvanceTo, {PLATFORM}, seed trajectory, cenic-fixed, 1 kHz; {load()}")
    p = load_preset(PLATFORM)
    forces = {}
    for kind, engine in (("fixed", "c"), ("float", "python")):
        sim = build_simulation(Scenario(p, "seed", kind, engine=engine))
        sim.prepare(D)
        forces[kind] = sim.controller.run(D)["force"]  # at t = 0 and every plant step (this loop logs there)
    F = forces["fixed"]
    runs = {
        "bare plant at rest, one AdvanceTo (the reference)": lambda: plant_run(p, F, "const", False, False, "one", D),
        "+ the loop's clock event": lambda: plant_run(p, F, "const", True, False, "one", D),
        "+ an AdvanceTo every plant step": lambda: plant_run(p, F, "const", True, False, "steps", D),
        "+ the force a fixed input": lambda: plant_run(p, F, "fixed", True, False, "steps", D),
        "+ notified (GetMutableData) every step": lambda: plant_run(p, F, "fixed", True, False, "notify", D),
        "  (the same without the clock)": lambda: plant_run(p, F, "fixed", False, False, "notify", D),
        "moving (fixed/C loop's forces), TrajectorySource, clock, one AdvanceTo": lambda: plant_run(
            p, F, "traj", True, True, "one", D
        ),
        "  the same, an AdvanceTo every step": lambda: plant_run(p, F, "traj", True, True, "steps", D),
        "  fixed input written and notified every step (the loop's states)": lambda: plant_run(
            p, F, "fixed", True, True, "notify", D
        ),
        "the fixed/C loop": lambda: loop_run(p, "fixed", "c", D),
        "moving (float loop's forces), fixed input written and notified": lambda: plant_run(
            p, forces["float"], "fixed", True, True, "notify", D
        ),
        "the float loop": lambda: loop_run(p, "float", "python", D),
    }
    best, result = dict.fromkeys(runs, np.inf), {}
    for _ in range(args.repeat):
        for k, f in runs.items():
            result[k] = f()
            best[k] = min(best[k], result[k][0])
    ref = best[next(iter(runs))]
    print("(process CPU µs per plant step, best of the repetitions; Newton iterations per step; integrator steps)")
    for k in runs:
        _, iters, steps, _ = result[k]
        print(f"  {k:72s} {best[k]:6.1f} µs  {ref / best[k]:.2f} × the reference  {iters:.2f} it/step  {steps} steps")
    same = {
        kind: np.array_equal(result[replay][3], result[loop][3])
        for kind, replay, loop in (
            ("fixed/C", "  fixed input written and notified every step (the loop's states)", "the fixed/C loop"),
            ("float", "moving (float loop's forces), fixed input written and notified", "the float loop"),
        )
    }
    print(
        "  the replays' final states equal their loop's bit for bit: " + ", ".join(f"{k} {v}" for k, v in same.items())
    )
    print(f"# {load()}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
