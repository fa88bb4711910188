"""``stewart-drake simulate``: the DSP controller in the loop with the closed-loop plant; writes logs and plots."""

from __future__ import annotations

import sys
from pathlib import Path

from stewart_drake.api.simulation import firmware_source, plan_run, run_plan
from stewart_drake.commands._common import (
    FLAG_PATHS,
    add_force_arg,
    add_machine_args,
    add_platform_arg,
    dumps_strict,
    flag_error,
    flag_text,
    machine_from_args,
    output_folder,
    print_json,
    reject_unused,
)
from stewart_drake.commands.firmware import add_time_limit_arg
from stewart_drake.drake.integrators import INTEGRATORS
from stewart_drake.errors import StewartError
from stewart_drake.firmware.engine import ENGINES
from stewart_drake.system.isolate import FIRMWARE_IDLE_LIMIT_S
from stewart_drake.system.output_folder import atomic_folder


def register(sub) -> None:
    p = sub.add_parser("simulate", help="run the fixed-point (or float) controller in the loop with the Drake plant")
    add_platform_arg(p, default=None)
    add_machine_args(p)
    p.add_argument(
        "--trajectory",
        default=None,
        metavar="seed|rotating|FILE.csv|FILE.stw",
        help="the pose reference: the seed's (px=-0.1, py=0.1 sin 2t, pz=0.7 m), a rotating one, a CSV "
        "of t,px,py,pz,ax,ay,az rows (SI unless --length-unit/--angle-unit) or a motion program "
        "(default: the machine's first motion, seed)",
    )
    p.add_argument(
        "--fit",
        action="store_true",
        help="move and scale the trajectory (made for utn-dynamic: pz 0.7 m, 0.4 m stroke) to the platform's home height and stroke",
    )
    p.add_argument("--length-unit", choices=["m", "mm"], default="m", help="CSV length unit (default m)")
    p.add_argument("--angle-unit", choices=["rad", "deg", "pi"], default="rad", help="CSV angle unit (default rad)")
    p.add_argument(
        "--smooth",
        type=float,
        default=None,
        metavar="TOL",
        help="differentiate a CSV through a smoothing spline within TOL (RMS, in the file's units) of its samples: "
        "for files rounded so coarsely that their second differences are noise (refused without it)",
    )
    add_loop_args(p)
    p.set_defaults(controller=None)  # None: the machine's controller.law (fixed)
    p.add_argument(
        "--firmware",
        default=None,
        metavar="DIR|FILE.c",
        help="run your own C firmware (implementing sd_firmware.h's ABI; see `firmware generate`: its folder or "
        "a C file) as the controller tick; the loop adopts the number format, sensor resolution and rate the "
        "firmware records (a warning names each that differs), and a firmware for another platform is refused",
    )
    p.add_argument("--word-bits", default=None, metavar="N", help="the IK's word width, 8..31 (default 16)")
    p.add_argument(
        "--length-lsb", default=None, metavar="LEN", help="the IK's length LSB, e.g. 30um (default 1mm; bare: m)"
    )
    p.add_argument(
        "--trig",
        default=None,
        choices=["tfr16", "exact"],
        help="the IK's sine/cosine (default tfr16; exact for words other than 16 bits)",
    )
    add_time_limit_arg(p, FIRMWARE_IDLE_LIMIT_S, "--firmware")
    p.add_argument(
        "--period", default=None, metavar="T", help="controller sample period, e.g. 0.5ms (default 1ms; bare: s)"
    )
    p.add_argument(
        "--latency",
        choices=["sample", "computation", "none"],
        default=None,
        help="when a tick's output is released: one sample later (default), after the cycle model's computation time, or at once",
    )
    p.add_argument(
        "--sensor-resolution",
        default=None,
        metavar="LEN",
        help="leg-length sensor resolution per count, e.g. 10um (default 1e-5 m; 1mm: integer mm as the firmware's words)",
    )
    p.add_argument(
        "--plant-step",
        default=None,
        metavar="T",
        help="plant time step, s (default: the period, at most 1 ms)",
    )
    p.add_argument(
        "--no-feedforward",
        action="store_true",
        help="no model-based force feed-forward (the PID alone carries the plate)",
    )
    p.add_argument(
        "--duration",
        default=None,
        metavar="T",
        help="simulated time, e.g. 2 or 500ms (default: the trajectory's, 4 s for seed; bare: s)",
    )
    p.add_argument(
        "--out",
        default="simulation",
        metavar="DIR",
        help="output folder for log.npz, log.csv, summary.json, plots (default simulation/)",
    )
    p.add_argument(
        "--pil",
        default=None,
        metavar="TARGET",
        help="processor in the loop: each tick computed by the firmware on qemu (the Cortex-M4 build in QEMU's "
        "mps2-an386, the link on its UART), qemu:semihosting (the same, the link on the semihosting console: "
        "about 10 times as fast) or serial:/dev/ttyX (a flashed board) over the PIL link (pil.target)",
    )
    p.add_argument(
        "--pil-fault",
        default=None,
        metavar="KIND:RATE|KIND:@K,...",
        help="inject link faults: drop, corrupt, delay or duplicate at a seeded rate a tick (drop:0.01) or at "
        "given ticks (corrupt:@10,200) (pil.fault)",
    )
    p.add_argument(
        "--pil-on-fault",
        default=None,
        choices=["hold", "stop"],
        help="a tick without a command: hold the last command (default) or stop (zero force, exit 1) (pil.on_fault)",
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


# the files simulate writes into --out (SimulationLog.save, write_plots, the summary)
FILES = ("log.npz", "log.csv", "tracking.png", "summary.json", "pil.csv")  # pil.csv: a --pil run's ticks

# the options the API's messages name by keyword (``length_unit=m``, ``allow_out_of_stroke=True``)
KEYWORD_FLAGS = {
    "length_unit": ("--length-unit", None),
    "angle_unit": ("--angle-unit", None),
    "allow_out_of_stroke": ("--allow-out-of-stroke", None),
}


def run(args) -> int:
    reject_unused(
        args,
        "--trajectory FILE.csv",
        args.trajectory not in (None, "seed", "rotating"),
        length_unit="m",
        angle_unit="rad",
        smooth=None,
    )
    out_folder = output_folder(args, names=FILES)
    reject_unused(args, "--firmware", args.firmware is not None, time_limit=FIRMWARE_IDLE_LIMIT_S)
    firmware = None if args.firmware is None else firmware_source(args.firmware, "--firmware")
    machine = machine_from_args(args)
    try:  # the API names spec paths; the user gave flags
        plan = plan_run(
            machine,
            args.trajectory,
            firmware=firmware,
            time_limit=args.time_limit,
            allow_out_of_stroke=args.allow_out_of_stroke,
            length_unit=args.length_unit,
            angle_unit=args.angle_unit,
            smooth=args.smooth,
            duration_shown=args.duration,
        )
    except StewartError as e:
        raise flag_error(e, {**FLAG_PATHS, **KEYWORD_FLAGS}) from None
    warn = lambda w: print(f"stewart-drake simulate: warning: {flag_text(w, FLAG_PATHS)}", file=sys.stderr)  # noqa: E731
    try:  # a PIL target is started by the run: its errors name spec paths too
        result = run_plan(plan, progress=not args.no_progress, on_warning=warn)
    except StewartError as e:
        raise flag_error(e, FLAG_PATHS) from None
    summary = result.to_dict()
    out = Path(args.out)
    with atomic_folder(out_folder) as tmp:
        log = result.log
        written = log.raw.save(tmp) + write_plots(log.raw, log.length_error, tmp) + [tmp / "summary.json"]
        if "pil" in summary:  # the per-tick round trips and clock counts in a CSV, not the summary
            written.append(write_pil_ticks(summary["pil"].pop("per_tick"), tmp / "pil.csv"))
        summary["files"] = [str(out / p.relative_to(tmp)) for p in written]
        (tmp / "summary.json").write_text(dumps_strict(summary))
    print_json(summary)
    rtf = summary["real_time_factor"]
    print(
        f"stewart-drake simulate: simulated {summary['duration_s']:g} s in {summary['wall_s']:.3g} s of wall time"
        + (f" ({rtf:.3g} × real time)" if rtf else ""),
        file=sys.stderr,
    )
    if "pil" in summary:
        print(f"stewart-drake simulate: {pil_line(summary['pil'])}", file=sys.stderr)
    for f in result.verdict["failures"]:
        print(f"stewart-drake simulate: {f}", file=sys.stderr)
    return 0 if result.ok else 1


def write_pil_ticks(per_tick: dict, path: Path) -> Path:
    """``pil.csv``: each tick the target answered (from 1), its round trip (s) and ``sd_tick``'s clock counts."""
    rows = zip(per_tick["tick"], per_tick["round_trip_s"], per_tick["clock_counts"], strict=True)
    lines = ["tick,round_trip_s,clock_counts"] + [f"{k},{t!r},{'' if c is None else c}" for k, t, c in rows]
    path.write_text("\n".join(lines) + "\n")
    return path


def pil_line(pil: dict) -> str:
    """The PIL run in one line: ticks, those without a command, and the measured tick beside the DSP's estimate."""
    text = f"PIL {pil['target']}: {pil['ticks']} ticks, {pil['ticks_without_command']} without a command"
    t = pil["timing"]
    if t:
        what = f"{t['instructions_worst']} instructions" if t["instructions_worst"] else "measured"
        share = t["period_share"]["stm32f405_168mhz"]
        text += (
            f"; sd_tick worst {what}, {t['cortex_m4_cycles_worst']:.0f} Cortex-M4 cycles ({share:.1%} of the period "
            f"at 168 MHz), DSP56800E estimate {t['dsp56800e_cycles']:.0f} cycles ({t['dsp56800e_period_share']:.1%} at "
            f"{t['dsp56800e_clock_hz'] / 1e6:g} MHz)"
        )
    return text


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
    ax[1].legend([f"leg {i}" for i in range(1, 7)], ncol=6, fontsize=7)
    ax[1].set_xlabel("t [s]")
    fig.suptitle(
        f"{log.kind} controller, {log.trajectory} trajectory on {log.platform.replace('$', r'\$')}, T = {log.sample_period * 1e3:g} ms"
    )
    path = out / "tracking.png"
    fig.savefig(path, dpi=100, bbox_inches="tight")
    plt.close(fig)
    return [path]
