"""The closed-loop plant's integrators side by side, in one run: discrete SAP at the plant step vs Drake's
error-controlled CENIC on a continuous plant.

For each integrator: the controller-in-the-loop run (``--trajectory`` on ``--platform``, both controllers)
and the bare plant (no controller: the legs pushed with the static forces of home, so the plate stays
near home; the integrator is free to take its own steps). Printed per case: wall time, real-time factor
(simulated s / wall s), the largest ball-constraint gap over every logged state (m), the largest leg
tracking error, the largest difference of leg lengths and pose between the two integrators, and each
one's distance from a reference run (the float twin under CENIC at accuracy 1e-8: the accuracy, not
only the agreement).

    PYTHONPATH=. python benchmarks/bench_integrators.py [--platform utn-dynamic] [--duration 4]
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

import stewart_drake.drake.integrators as integrators
from stewart_drake.core.geometry import load_platform
from stewart_drake.core.trajectory import get_trajectory
from stewart_drake.drake.integrators import INTEGRATORS, apply_integrator, constraint_gaps
from stewart_drake.drake.simulation import Scenario, build_simulation

REFERENCE_ACCURACY = 1e-8


def closed_loop(platform, trajectory, controller, integrator, duration):
    sim = build_simulation(Scenario(platform, trajectory, controller, integrator=integrator, design_duration=duration))
    t0 = time.perf_counter()
    log = sim.run(duration)
    wall = time.perf_counter() - t0
    X = sim.loggers["state"].FindLog(sim.simulator.get_context()).data().T
    gap = constraint_gaps(sim.plant, X)
    err = log.length_error(sim.trajectory, platform)
    return log, {
        "wall_s": wall,
        "realtime_factor": duration / wall,
        "max_constraint_gap_m": float(gap.max()),
        "max_leg_error_m": float(np.abs(err).max()),
        "plant_samples": len(log.t),
    }


def bare_plant(platform, integrator, duration):
    """The plant alone, its legs pushed with home's static leg forces (constant actuation)."""
    from pydrake.systems.analysis import Simulator
    from pydrake.systems.framework import DiagramBuilder
    from pydrake.systems.primitives import ConstantVectorSource, LogVectorOutput

    from stewart_drake.core.dynamics import leg_forces_with_legs
    from stewart_drake.drake.platform_model import build_plant, set_pose

    builder = DiagramBuilder()
    plant, _ = build_plant(platform, 1e-3, builder, continuous=integrator == "cenic")
    home = platform.home_pose()
    F = leg_forces_with_legs(platform, home, np.zeros(6), np.zeros(6))
    src = builder.AddSystem(ConstantVectorSource(F))
    builder.Connect(src.get_output_port(), plant.get_actuation_input_port())
    logger = LogVectorOutput(plant.get_state_output_port(), builder, 1e-3)
    sim = Simulator(builder.Build())
    apply_integrator(sim, integrator)
    set_pose(plant, plant.GetMyMutableContextFromRoot(sim.get_mutable_context()), platform, home)
    sim.Initialize()
    t0 = time.perf_counter()
    sim.AdvanceTo(duration)
    wall = time.perf_counter() - t0
    X = logger.FindLog(sim.get_context()).data().T
    return {
        "wall_s": wall,
        "realtime_factor": duration / wall,
        "max_constraint_gap_m": float(constraint_gaps(plant, X).max()),
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--platform", default="utn-dynamic")
    ap.add_argument("--trajectory", default="seed")
    ap.add_argument("--duration", type=float, default=4.0)
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)
    platform = load_platform(args.platform)
    traj = get_trajectory(args.trajectory)
    out = {}
    for controller in ("fixed", "float"):
        logs = {}
        for integ in INTEGRATORS:
            logs[integ], out[f"{controller}/{integ}"] = closed_loop(platform, traj, controller, integ, args.duration)
        a, b = (logs[i] for i in INTEGRATORS)
        out[f"{controller}/difference"] = {
            "max_leg_length_difference_m": float(np.abs(a.lengths - b.lengths).max()),
            "max_position_difference_m": float(np.abs(a.pose[:, :3] - b.pose[:, :3]).max()),
            "max_angle_difference_rad": float(np.abs(a.pose[:, 3:] - b.pose[:, 3:]).max()),
        }
    default = integrators.CENIC_ACCURACY
    integrators.CENIC_ACCURACY = REFERENCE_ACCURACY
    try:
        ref, out["float/reference"] = closed_loop(platform, traj, "float", "cenic", args.duration)
    finally:
        integrators.CENIC_ACCURACY = default
    for integ in INTEGRATORS:
        log = build_simulation(Scenario(platform, traj, "float", integrator=integ, design_duration=args.duration)).run(
            args.duration
        )
        out[f"float/{integ}_vs_reference"] = {
            "max_leg_length_difference_m": float(np.abs(log.lengths - ref.lengths).max()),
            "max_position_difference_m": float(np.abs(log.pose[:, :3] - ref.pose[:, :3]).max()),
        }
    for integ in INTEGRATORS:
        out[f"bare/{integ}"] = bare_plant(platform, integ, args.duration)
    if args.json:
        print(json.dumps(out, indent=2))
        return 0
    print(f"{args.platform}, {args.trajectory} trajectory, {args.duration:g} s simulated")
    for k, v in out.items():
        print(f"{k:18s} " + "  ".join(f"{n}={x:.3g}" if isinstance(x, float) else f"{n}={x}" for n, x in v.items()))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
