"""``stewart-drake simulate``: the DSP controller in the loop with the closed-loop plant; writes logs and plots."""

from __future__ import annotations

from pathlib import Path

from ._common import add_platform_arg, print_json


def register(sub) -> None:
    p = sub.add_parser("simulate", help="run the fixed-point (or float) controller in the loop with the Drake plant")
    add_platform_arg(p, default="utn-dynamic")
    p.add_argument("--trajectory", default="seed", metavar="seed|rotating|FILE.csv",
                   help="the pose reference: the seed's (px=-0.1, py=0.1 sin 2t, pz=0.7 m), a rotating one, or a CSV "
                        "of t,px,py,pz,ax,ay,az rows (SI unless --length-unit/--angle-unit)")
    p.add_argument("--fit", action="store_true",
                   help="move and scale the trajectory (made for utn-dynamic: pz 0.7 m, 0.4 m stroke) to the platform's home height and stroke")
    p.add_argument("--length-unit", choices=["m", "mm"], default="m", help="CSV length unit (default m)")
    p.add_argument("--angle-unit", choices=["rad", "deg", "pi"], default="rad", help="CSV angle unit (default rad)")
    p.add_argument("--controller", choices=["fixed", "float"], default="fixed", help="fixed-point DSP controller or its float twin")
    p.add_argument("--period", type=float, default=1e-3, metavar="S", help="controller sample period, s (default 0.001)")
    p.add_argument("--latency", choices=["sample", "computation", "none"], default="sample",
                   help="when a tick's output is released: one sample later (default), after the cycle model's computation time, or at once")
    p.add_argument("--sensor-resolution", type=float, default=1e-5, metavar="M",
                   help="leg-length sensor resolution, m per count (default 1e-5; 1e-3: integer mm as the firmware's words)")
    p.add_argument("--plant-step", type=float, default=None, metavar="S", help="plant time step, s (default: the period, at most 1 ms)")
    p.add_argument("--integrator", choices=["cenic", "sap"], default=None,
                   help="plant integrator: cenic (default; error-controlled, continuous plant) or sap (discrete plant at --plant-step); "
                        "see benchmarks/bench_integrators.py")
    p.add_argument("--no-feedforward", action="store_true", help="no model-based force feed-forward (the PID alone carries the plate)")
    p.add_argument("--duration", type=float, default=None, metavar="S", help="simulated seconds (default: the trajectory's, 4 s for seed)")
    p.add_argument("--out", default="simulation", metavar="DIR", help="output folder for log.npz, log.csv, summary.json, plots (default simulation/)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=run)


def run(args) -> int:
    import json

    import numpy as np

    from ..atomic import atomic_folder
    from ..control import ControllerConfig, DspTiming
    from ..geometry import load_platform
    from ..simulation import build_simulation, design_poses, fit_trajectory, get_trajectory

    platform = load_platform(args.platform)
    traj = get_trajectory(args.trajectory, length_unit=args.length_unit, angle_unit=args.angle_unit)
    if args.fit:
        traj = fit_trajectory(traj, platform)
    duration = args.duration if args.duration is not None else (traj.duration or 1.0)
    if not duration > 0:
        raise ValueError(f"--duration must be a positive number of seconds, got {args.duration}")
    timing = DspTiming(sample_period=args.period, latency=args.latency, sensor_resolution=args.sensor_resolution,
                       command_range=float(platform.legs.max_force)).check()
    plant_step = args.plant_step if args.plant_step is not None else min(args.period, 1e-3)
    # command range and gains designed for the platform over the poses of the run
    config = ControllerConfig.for_platform(platform, timing, poses=design_poses(traj, max(duration, traj.duration or 0.0)))
    sim = build_simulation(platform, traj, args.controller, config, plant_time_step=plant_step, feedforward=not args.no_feedforward,
                           integrator=args.integrator)
    log = sim.run(duration, progress=not args.no_progress)
    out = Path(args.out)
    e = log.length_error(traj, platform)
    pe = log.pose_error(traj)
    summary = {
        "platform": platform.name,
        "trajectory": traj.name,
        "controller": args.controller,
        "sample_period_s": args.period,
        "latency": args.latency,
        "feedforward": not args.no_feedforward,
        "gains": {k: getattr(config.gains, k) for k in ("kp", "ki", "kd", "kv")},
        "command_range_N": config.timing.command_range,
        "output_delay_s": timing.output_delay,
        "computation_time_s": timing.computation_time,
        "plant_time_step_s": plant_step,
        "integrator": sim.integrator,
        "duration_s": duration,
        "ticks": int(len(log.tick_times())),
        "max_leg_error_mm": float(np.abs(e).max() * 1e3),
        "rms_leg_error_mm": float(np.sqrt(np.mean(e**2)) * 1e3),
        "max_position_error_mm": float(np.abs(pe[:, :3]).max() * 1e3),
        "max_angle_error_deg": float(np.degrees(np.abs(pe[:, 3:]).max())),
        "saturated_ticks_per_leg": log.saturations().astype(int).tolist(),
    }
    with atomic_folder(out) as tmp:
        written = log.save(tmp) + write_plots(log, e, tmp) + [tmp / "summary.json"]
        summary["files"] = [str(out / p.relative_to(tmp)) for p in written]
        (tmp / "summary.json").write_text(json.dumps(summary, indent=2))
    print_json(summary)
    return 0


def write_plots(log, length_error, out: Path) -> list[Path]:
    """Leg-length errors and leg forces over time, as PNG files in ``out``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    ax[0].plot(log.t, length_error * 1e3)
    ax[0].set_ylabel("leg length − IK(reference) [mm]")
    ax[0].legend([f"leg {i}" for i in range(1, 7)], ncol=6, fontsize=7)
    ax[1].plot(log.t, log.force)
    ax[1].set_ylabel("actuator force [N]")
    ax[1].set_xlabel("t [s]")
    fig.suptitle(f"{log.kind} controller, {log.trajectory} trajectory on {log.platform}, T = {log.sample_period * 1e3:g} ms")
    path = out / "tracking.png"
    fig.savefig(path, dpi=100, bbox_inches="tight")
    plt.close(fig)
    return [path]
