"""The closed-loop plant's integrators side by side, in one run: discrete SAP at the plant step, Drake's
error-controlled CENIC and CENIC at the fixed plant step, on a continuous plant.

For each integrator:
- the fixed-point controller in the loop (``--trajectory`` on ``--platform``) with the Python and the C
  engine: real-time factor (simulated s / wall s), largest ball-constraint gap over every logged state (m),
  largest leg tracking error, and the largest leg-length difference from the ``cenic`` run (what the
  choice changes in a tracking result);
- the accuracy: the float twin with a 1 nm sensor (so a flipped 10 µm sensor count is not mistaken for
  integration error) against a reference run under CENIC at accuracy 1e-9;
- the bare plant (no controller: the legs pushed with home's static forces, logged every 1 ms).

    PYTHONPATH=. python benchmarks/bench_integrators.py [--platform utn-dynamic] [--duration 4] [--json]
"""

from __future__ import annotations

import argparse
import json
import time
from dataclasses import replace

import numpy as np

import stewart_drake.drake.integrators as integrators
from stewart_drake.control.gains import ControllerConfig
from stewart_drake.core.geometry import load_platform
from stewart_drake.core.trajectory import design_poses, get_trajectory
from stewart_drake.drake.integrators import CONTINUOUS, INTEGRATORS, apply_integrator, constraint_gaps
from stewart_drake.drake.simulation import Scenario, build_simulation
from stewart_drake.firmware.engine import ENGINES

REFERENCE_ACCURACY = 1e-9


def closed_loop(platform, trajectory, controller, integrator, duration, engine="python", config=None):
    scenario = Scenario(
        platform, trajectory, controller, config, integrator=integrator, engine=engine, design_duration=duration
    )
    sim = build_simulation(scenario)
    t0 = time.perf_counter()
    log = sim.run(duration)
    wall = time.perf_counter() - t0
    X = sim.states()
    err = log.length_error(sim.trajectory, platform)
    return log, {
        "realtime_factor": duration / wall,
        "max_constraint_gap_m": float(constraint_gaps(sim.plant, X).max()),
        "max_leg_error_m": float(np.abs(err).max()),
    }


def bare_plant(platform, integrator, duration):
    """The plant alone, its legs pushed with home's static leg forces (constant actuation)."""
    from pydrake.systems.analysis import Simulator
    from pydrake.systems.framework import DiagramBuilder
    from pydrake.systems.primitives import ConstantVectorSource, LogVectorOutput

    from stewart_drake.core.dynamics import leg_forces_with_legs
    from stewart_drake.drake.platform_model import build_plant, set_pose

    builder = DiagramBuilder()
    # built as the closed loop builds its plant when nothing is shown (no SceneGraph): a fair reference
    plant, _ = build_plant(platform, 1e-3, builder, continuous=integrator in CONTINUOUS, visuals=False)
    home = platform.home_pose()
    F = leg_forces_with_legs(platform, home, np.zeros(6), np.zeros(6))
    src = builder.AddSystem(ConstantVectorSource(F))
    builder.Connect(src.get_output_port(), plant.get_actuation_input_port())
    logger = LogVectorOutput(plant.get_state_output_port(), builder, 1e-3)
    sim = Simulator(builder.Build())
    apply_integrator(sim, integrator, 1e-3)
    set_pose(plant, plant.GetMyMutableContextFromRoot(sim.get_mutable_context()), platform, home)
    sim.Initialize()
    t0 = time.perf_counter()
    sim.AdvanceTo(duration)
    wall = time.perf_counter() - t0
    X = logger.FindLog(sim.get_context()).data().T
    return {
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
    D = args.duration
    out = {}
    for engine in ENGINES:
        logs = {}
        for integ in INTEGRATORS:
            logs[integ], out[f"fixed/{engine}/{integ}"] = closed_loop(platform, traj, "fixed", integ, D, engine)
        for integ in INTEGRATORS:
            d = np.abs(logs[integ].lengths - logs["cenic"].lengths).max()
            out[f"fixed/{engine}/{integ}"]["max_leg_difference_from_cenic_m"] = float(d)
    config = ControllerConfig.for_platform(platform, poses=design_poses(traj, D))
    config = replace(config, timing=replace(config.timing, sensor_resolution=1e-9))
    default = integrators.CENIC_ACCURACY
    integrators.CENIC_ACCURACY = REFERENCE_ACCURACY
    try:
        ref, _ = closed_loop(platform, traj, "float", "cenic", D, config=config)
    finally:
        integrators.CENIC_ACCURACY = default
    for integ in INTEGRATORS:
        log, row = closed_loop(platform, traj, "float", integ, D, config=config)
        row["max_leg_difference_from_reference_m"] = float(np.abs(log.lengths - ref.lengths).max())
        row["max_position_difference_from_reference_m"] = float(np.abs(log.pose[:, :3] - ref.pose[:, :3]).max())
        out[f"float-1nm/{integ}"] = row
    for integ in INTEGRATORS:
        out[f"bare/{integ}"] = bare_plant(platform, integ, D)
    if args.json:
        print(json.dumps(out, indent=2))
        return 0
    print(f"{args.platform}, {args.trajectory} trajectory, {D:g} s simulated")
    for k, v in out.items():
        print(f"{k:24s} " + "  ".join(f"{n}={x:.3g}" for n, x in v.items()))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
