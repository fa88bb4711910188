"""``stewart-drake simulate``: the DSP controller in the loop with the closed-loop plant; writes logs and plots."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

from stewart_drake.commands._common import (
    add_force_arg,
    add_platform_arg,
    dumps_strict,
    output_folder,
    print_json,
    reject_unused,
)
from stewart_drake.commands.firmware import add_time_limit_arg, check_time_limit
from stewart_drake.core.sanity import (
    check_positive,
    check_trajectory,
    check_work,
    fmt_value,
    require_plate,
)
from stewart_drake.drake.integrators import DEFAULT_INTEGRATOR, INTEGRATORS
from stewart_drake.errors import (
    OPTION_DURATION_PERIOD,
    OPTION_DURATION_POSITIVE,
    OPTION_ENGINE_FIXED,
    OPTION_FIRMWARE_ENGINE,
    SIMULATION_GAP_WARNING,
    OptionError,
    UsageError,
)
from stewart_drake.firmware.engine import ENGINES

FIRMWARE_IDLE_LIMIT_S = 60.0  # --firmware: seconds the simulated time may stand still (a tick takes µs)

# Memory per plant step of the logs (state, command, set-point, force, status: ~100 doubles) and of
# log.csv's rows while they are written, and wall time per plant step (the fixed-point controller and
# the SAP plant: ~1 ms on one core); a run is refused beyond the memory budget or MAX_RUN_SECONDS.
BYTES_PER_STEP = 4000
SECONDS_PER_STEP = 1e-3
MAX_RUN_SECONDS = 3600.0


def check_simulation_size(duration: float, plant_step: float, option: str, value) -> None:
    """Refuse a simulation whose logs would not fit in memory or that would run for more than an hour."""
    check_work(
        option,
        f"{fmt_value(value)} s",
        duration / plant_step,
        f"plant steps of {fmt_value(plant_step)} s",
        BYTES_PER_STEP,
        seconds_per=SECONDS_PER_STEP,
        max_seconds=MAX_RUN_SECONDS,
        hint=f"; use a shorter {option}",
    )


def register(sub) -> None:
    p = sub.add_parser("simulate", help="run the fixed-point (or float) controller in the loop with the Drake plant")
    add_platform_arg(p, default="utn-dynamic")
    p.add_argument(
        "--trajectory",
        default="seed",
        metavar="seed|rotating|FILE.csv",
        help="the pose reference: the seed's (px=-0.1, py=0.1 sin 2t, pz=0.7 m), a rotating one, or a CSV "
        "of t,px,py,pz,ax,ay,az rows (SI unless --length-unit/--angle-unit)",
    )
    p.add_argument(
        "--fit",
        action="store_true",
        help="move and scale the trajectory (made for utn-dynamic: pz 0.7 m, 0.4 m stroke) to the platform's home height and stroke",
    )
    p.add_argument("--length-unit", choices=["m", "mm"], default="m", help="CSV length unit (default m)")
    p.add_argument("--angle-unit", choices=["rad", "deg", "pi"], default="rad", help="CSV angle unit (default rad)")
    add_loop_args(p)
    p.add_argument(
        "--firmware",
        default=None,
        metavar="FILE.c",
        help="run your own C firmware (implementing sd_firmware.h's ABI; see `firmware generate`) as the controller tick",
    )
    add_time_limit_arg(p, FIRMWARE_IDLE_LIMIT_S, "--firmware")
    p.add_argument(
        "--period", type=float, default=1e-3, metavar="S", help="controller sample period, s (default 0.001)"
    )
    p.add_argument(
        "--latency",
        choices=["sample", "computation", "none"],
        default="sample",
        help="when a tick's output is released: one sample later (default), after the cycle model's computation time, or at once",
    )
    p.add_argument(
        "--sensor-resolution",
        type=float,
        default=1e-5,
        metavar="M",
        help="leg-length sensor resolution, m per count (default 1e-5; 1e-3: integer mm as the firmware's words)",
    )
    p.add_argument(
        "--plant-step",
        type=float,
        default=None,
        metavar="S",
        help="plant time step, s (default: the period, at most 1 ms)",
    )
    p.add_argument(
        "--no-feedforward",
        action="store_true",
        help="no model-based force feed-forward (the PID alone carries the plate)",
    )
    p.add_argument(
        "--duration",
        type=float,
        default=None,
        metavar="S",
        help="simulated seconds (default: the trajectory's, 4 s for seed)",
    )
    p.add_argument(
        "--out",
        default="simulation",
        metavar="DIR",
        help="output folder for log.npz, log.csv, summary.json, plots (default simulation/)",
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument(
        "--allow-out-of-stroke",
        action="store_true",
        help="simulate even a reference that leaves the stroke (a warning, also in summary.json 'warnings'); default: exit 1",
    )
    add_force_arg(p)
    p.set_defaults(func=run)


def add_loop_args(p) -> None:
    """The closed loop's options, shared by ``simulate`` and ``montecarlo``: ``--controller``, ``--engine``,
    ``--integrator``."""
    p.add_argument(
        "--controller", choices=["fixed", "float"], default="fixed", help="fixed-point DSP controller or its float twin"
    )
    p.add_argument(
        "--engine",
        choices=ENGINES,
        default=None,
        help="fixed-point controller tick: c (the generated firmware, compiled; the default where a C compiler is found) "
        "or python (the emulation; bit-identical, slower)",
    )
    p.add_argument(
        "--integrator",
        choices=INTEGRATORS,
        default=None,
        help="plant integrator: cenic-fixed (default: CENIC at the fixed --plant-step on a continuous plant), cenic "
        "(error-controlled) or sap (discrete plant at --plant-step); see benchmarks/bench_integrators.py",
    )


def run(args) -> int:
    from stewart_drake.control import ControllerConfig, DspTiming, check_timing
    from stewart_drake.control.simulation_log import tracking_verdict
    from stewart_drake.core.geometry import load_platform
    from stewart_drake.core.output_folder import atomic_folder
    from stewart_drake.core.trajectory import design_poses, fit_trajectory, get_trajectory
    from stewart_drake.drake.firmware_run import run_closed_loop, run_user_firmware
    from stewart_drake.drake.simulation import ActuatorModel, Scenario
    from stewart_drake.firmware.engine import default_engine
    from stewart_drake.firmware.module import check_source

    reject_unused(
        args, "--trajectory FILE.csv", args.trajectory not in ("seed", "rotating"), length_unit="m", angle_unit="rad"
    )
    out_folder = output_folder(args)
    reject_unused(args, "--firmware", args.firmware is not None, time_limit=FIRMWARE_IDLE_LIMIT_S)
    if args.firmware is not None:
        check_source(args.firmware, "--firmware")
    limit = check_time_limit(args.time_limit)
    platform = load_platform(args.platform)
    require_plate(platform, "simulate")
    period = check_positive(args.period, "--period", "seconds")
    plant_step = args.plant_step if args.plant_step is not None else min(period, 1e-3)
    if args.duration is not None:
        check_positive(args.duration, "--duration", "seconds")
    traj = get_trajectory(args.trajectory, length_unit=args.length_unit, angle_unit=args.angle_unit)
    if args.fit:
        traj = fit_trajectory(traj, platform)
    duration = args.duration if args.duration is not None else (traj.duration or 1.0)
    if not duration > 0:
        raise OptionError(OPTION_DURATION_POSITIVE.format(value=args.duration))
    timing = DspTiming(
        sample_period=period,
        latency=args.latency,
        sensor_resolution=args.sensor_resolution,
        command_range=float(platform.legs.max_force),
    ).check()
    check_timing(platform, period, plant_step, ActuatorModel().time_constant, timing.output_delay)
    if duration < period:  # the log would hold the initial state only, its errors 0: no result at all
        raise OptionError(OPTION_DURATION_PERIOD.format(value=fmt_value(duration), period=fmt_value(period)))
    check_simulation_size(duration, plant_step, "--duration", args.duration if args.duration is not None else duration)
    ticks = np.arange(int(math.floor(duration / period + 1e-9)) + 1) * period
    warnings = check_trajectory(
        platform, ticks, traj.pose(ticks), "utn", f"the {traj.name} reference", args.allow_out_of_stroke
    )
    for w in warnings:
        print(f"stewart-drake simulate: warning: {w}", file=sys.stderr)
    # command range and gains designed for the platform over the poses of the run
    config = ControllerConfig.for_platform(
        platform, timing, poses=design_poses(traj, max(duration, traj.duration or 0.0))
    )
    if (args.engine == "c" or args.firmware) and args.controller != "fixed":
        raise UsageError(OPTION_ENGINE_FIXED.format(controller=args.controller))
    if args.firmware and args.engine == "python":
        raise UsageError(OPTION_FIRMWARE_ENGINE)
    engine = "c" if args.firmware else default_engine(args.engine, args.controller, "stewart-drake simulate")
    scenario = Scenario(
        platform,
        traj,
        args.controller,
        config,
        plant_time_step=plant_step,
        feedforward=not args.no_feedforward,
        engine=engine,
        firmware=args.firmware,
        integrator=args.integrator or DEFAULT_INTEGRATOR,
        duration=duration,
    )
    if args.firmware:  # the user's C runs in a child process with a time limit (drake.firmware_run)
        log, gap = run_user_firmware(scenario, duration, not args.no_progress, args.firmware, limit)
    else:
        log, gap = run_closed_loop(scenario, duration, not args.no_progress)
    if gap > timing.sensor_resolution / 10:
        warnings.append(SIMULATION_GAP_WARNING.format(gap=gap, count=timing.sensor_resolution))
        print(f"stewart-drake simulate: warning: {warnings[-1]}", file=sys.stderr)
    out = Path(args.out)
    e = log.length_error(traj, platform)
    pe = log.pose_error(traj)
    summary = {
        "platform": platform.name,
        "trajectory": traj.name,
        "controller": args.controller,
        "engine": engine,
        "firmware": args.firmware,
        "sample_period_s": args.period,
        "latency": args.latency,
        "feedforward": not args.no_feedforward,
        "gains": {k: getattr(config.gains, k) for k in ("kp", "ki", "kd", "kv")},
        "command_range_N": config.timing.command_range,
        "output_delay_s": timing.output_delay,
        "computation_time_s": timing.computation_time,
        "plant_time_step_s": plant_step,
        "integrator": scenario.integrator,
        "max_constraint_gap_m": gap,
        "duration_s": duration,
        "ticks": int(len(log.tick_times())),
        "max_leg_error_mm": float(np.abs(e).max() * 1e3),
        "rms_leg_error_mm": float(np.sqrt(np.mean(e**2)) * 1e3),
        "max_position_error_mm": float(np.abs(pe[:, :3]).max() * 1e3),
        "max_angle_error_deg": float(np.degrees(np.abs(pe[:, 3:]).max())),
        "saturated_ticks_per_leg": log.saturations().astype(int).tolist(),
    }
    verdict = tracking_verdict(platform, e, pe, log)
    summary.update(verdict)
    summary["warnings"] = warnings
    with atomic_folder(out_folder) as tmp:
        written = log.save(tmp) + write_plots(log, e, tmp) + [tmp / "summary.json"]
        summary["files"] = [str(out / p.relative_to(tmp)) for p in written]
        (tmp / "summary.json").write_text(dumps_strict(summary))
    print_json(summary)
    if verdict["failures"]:
        for f in verdict["failures"]:
            print(f"stewart-drake simulate: {f}", file=sys.stderr)
        return 1
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
    fig.suptitle(
        f"{log.kind} controller, {log.trajectory} trajectory on {log.platform.replace('$', r'\$')}, T = {log.sample_period * 1e3:g} ms"
    )
    path = out / "tracking.png"
    fig.savefig(path, dpi=100, bbox_inches="tight")
    plt.close(fig)
    return [path]
