"""``stewart-drake firmware``: generate the C firmware module for a platform, or check a user's C
firmware against the bit-exact emulation."""

from __future__ import annotations

import sys
from pathlib import Path

from stewart_drake.commands._common import add_platform_arg, print_json
from stewart_drake.errors import (
    OPTION_FIRMWARE_RATE,
    OPTION_FIRMWARE_TFR16,
    OPTION_FIRMWARE_WORD_BITS,
    OptionError,
    UsageError,
)


def _format_args(p) -> None:
    add_platform_arg(p, default="utn-dynamic")
    p.add_argument(
        "--word-bits", type=int, default=16, metavar="N", help="data word width, 8..16 (default 16, the DSP)"
    )
    p.add_argument(
        "--length-lsb", type=float, default=1e-3, metavar="M", help="metres per length LSB (default 1e-3: integer mm)"
    )
    p.add_argument(
        "--trig",
        choices=["tfr16", "exact"],
        default="tfr16",
        help="sin/cos: tfr16 (the DSP library polynomial, 16-bit words; default) or exact (a correctly rounded table)",
    )
    p.add_argument(
        "--convention", choices=["utn", "zyx"], default="utn", help="Euler convention of the pose angles (default utn)"
    )
    p.add_argument("--rate", type=float, default=1000.0, metavar="HZ", help="controller rate, Hz (default 1000)")
    p.add_argument(
        "--sensor-resolution", type=float, default=1e-5, metavar="M", help="leg sensor, m per count (default 1e-5)"
    )
    p.add_argument(
        "--trajectory",
        default=None,
        metavar="seed|rotating|FILE.csv",
        help="design the gains over this reference's poses, as `simulate` does (default: home only)",
    )


def register(sub) -> None:
    p = sub.add_parser(
        "firmware", help="generate the C firmware (IK + controller tick) or check a C firmware against the emulation"
    )
    fs = p.add_subparsers(dest="firmware_command", required=True, metavar="generate|check")
    g = fs.add_parser("generate", help="emit a self-contained C99 module: sd_ik, sd_init, sd_tick (+ README)")
    _format_args(g)
    g.add_argument(
        "--out", required=True, metavar="DIR", help="output folder (created; only its own files are replaced)"
    )
    g.add_argument(
        "--no-compile", action="store_true", help="do not compile-check the module with the available compilers"
    )
    g.add_argument("--json", action="store_true", help="print the summary as JSON")
    g.set_defaults(func=run_generate)
    c = fs.add_parser("check", help="compile FILE.c (implementing the ABI) and compare it with the emulation")
    c.add_argument(
        "file",
        metavar="FILE.c",
        help='C source including "sd_firmware.h" and defining sd_ik (and optionally sd_init/sd_tick/sd_ik_trace)',
    )
    _format_args(c)
    c.add_argument("--poses", type=int, default=100_000, metavar="N", help="workspace poses for sd_ik (default 100000)")
    c.add_argument("--seed", type=int, default=0, help="random seed of the poses (default 0)")
    c.add_argument(
        "--duration",
        type=float,
        default=0.5,
        metavar="S",
        help="closed-loop seconds replayed into sd_tick (default 0.5)",
    )
    c.add_argument(
        "--trace", action="store_true", help="show both sides' intermediate words at the first differing pose"
    )
    c.add_argument(
        "--compiler", default=None, metavar="NAME", help="gcc, clang, cc or zig (default: the first available)"
    )
    add_time_limit_arg(c)
    c.add_argument("--json", action="store_true", help="print JSON")
    c.set_defaults(func=run_check)


FIRMWARE_TIME_LIMIT_S = 120.0  # the whole check: compile, 100000 poses, 0.5 s closed loop (~10 s here)


def add_time_limit_arg(p, default: float = FIRMWARE_TIME_LIMIT_S, what: str = "the check") -> None:
    """``--time-limit S``: how long the user's firmware (compiled and run in a child process) may take."""
    p.add_argument(
        "--time-limit",
        type=float,
        default=default,
        metavar="S",
        help=f"seconds {what} may run the firmware without progress (default {default:g}); the firmware runs in "
        "a child process: a hang, exit() or crash is one line naming the file",
    )


def _check_in_child(beat, *args) -> dict:
    """``check_firmware(*args)``, run by ``core.isolate`` in a child process."""
    from stewart_drake.drake.firmware_check import check_firmware

    return check_firmware(*args)


def check_time_limit(value: float) -> float:
    """``--time-limit`` as given, if it is a positive number of seconds (at most a day)."""
    if not 0 < value <= 86400:
        raise OptionError(OptionError.BETWEEN.format(option="--time-limit", lo="0 (excluded)", hi=86400, value=value))
    return float(value)


def _config(args, platform):
    from stewart_drake.control import ControllerConfig, DspTiming
    from stewart_drake.fixedpoint.generic import QFormat

    if not 8 <= args.word_bits <= 16:
        raise OptionError(OPTION_FIRMWARE_WORD_BITS.format(value=args.word_bits))
    if not (args.rate > 0 and args.rate <= 1e6):
        raise OptionError(OPTION_FIRMWARE_RATE.format(value=args.rate))
    if args.trig == "tfr16" and args.word_bits != 16:
        raise UsageError(OPTION_FIRMWARE_TFR16.format(value=args.word_bits))
    fmt = QFormat(args.word_bits, args.length_lsb, args.trig)
    timing = DspTiming(
        sample_period=1.0 / args.rate,
        sensor_resolution=args.sensor_resolution,
        command_range=float(platform.legs.max_force),
    ).check()
    poses = None
    if args.trajectory is not None:
        from stewart_drake.core.trajectory import design_poses, get_trajectory

        poses = design_poses(get_trajectory(args.trajectory))
    return ControllerConfig.for_platform(platform, timing, poses=poses, ik_format=fmt, convention=args.convention)


def run_generate(args) -> int:
    from stewart_drake.core.c_build import compilers
    from stewart_drake.core.geometry import load_platform
    from stewart_drake.core.output_folder import OutputFolder, atomic_folder
    from stewart_drake.firmware.generate import generate
    from stewart_drake.firmware.module import compile_generated

    platform = load_platform(args.platform)
    config = _config(args, platform)
    out = Path(args.out)
    folder = OutputFolder(args.out)  # the policy, before any work: new, empty, or this command's own
    g = generate(platform, config)
    compiled = []
    if not args.no_compile:
        for cc in compilers():
            compile_generated(g, compiler=cc)  # -std=c99 -Wall -Wextra -Werror -pedantic
            compiled.append(cc.name)
        if not compiled:
            print(
                "stewart-drake firmware generate: note: no C compiler found; the module was not compile-checked",
                file=sys.stderr,
            )
    with atomic_folder(folder) as tmp:
        written = g.write(tmp)
    ik = g.ik_cycles
    summary = {
        "platform": platform.name,
        "out": str(out),
        "format": {
            "word_bits": config.ik_format.word_bits,
            "length_lsb_m": config.ik_format.length_lsb,
            "trig": config.ik_format.trig,
            "convention": config.convention,
        },
        "rate_hz": args.rate,
        "gains": {k: getattr(config.gains, k) for k in ("kp", "ki", "kd", "kv")},
        "files": [{"name": p.name, "bytes": (out / p.name).stat().st_size} for p in written],
        "ik_cycles": round(ik.cycles),
        "ik_us": round(ik.microseconds, 2),
        "tick_cycles": round(g.tick_cycles),
        "tick_us": round(g.tick_cycles / config.timing.clock_hz * 1e6, 2),
        "compiled_with": compiled,
    }
    if args.json:
        print_json(summary)
    else:
        print(
            f"wrote {len(written)} files to {out}/ for {platform.name}: "
            + ", ".join(f"{f['name']} ({f['bytes']} B)" for f in summary["files"])
        )
        print(
            f"cycle estimate at {config.timing.clock_hz / 1e6:g} MHz: sd_ik {summary['ik_cycles']} cycles ({summary['ik_us']} µs), "
            f"sd_tick {summary['tick_cycles']} cycles ({summary['tick_us']} µs)"
        )
        if not args.no_compile:
            print("compile-checked (-std=c99 -Wall -Wextra -Werror -pedantic) with: " + (", ".join(compiled) or "none"))
    return 0


def run_check(args) -> int:
    from stewart_drake.core.c_build import compiler_by_name
    from stewart_drake.core.geometry import load_platform
    from stewart_drake.core.isolate import run_isolated
    from stewart_drake.firmware.module import check_source

    check_source(args.file)
    limit = check_time_limit(args.time_limit)
    platform = load_platform(args.platform)
    config = _config(args, platform)
    cc = compiler_by_name(args.compiler) if args.compiler else None
    # the user's code runs in a child process: a hang, an exit() or a crash is one line naming the file
    r = run_isolated(
        _check_in_child,
        Path(args.file),
        platform,
        config,
        args.poses,
        args.seed,
        args.trace,
        args.duration,
        cc,
        path=args.file,
        limit=limit,
    )
    if args.json:
        print_json(r)
    else:
        ik = r["ik"]
        print(
            f"sd_ik: {ik['poses']} workspace poses, {ik['differing_poses']} differ, worst difference {ik['worst_lsb']} LSB"
        )
        f = ik["first_difference"]
        if f:
            print(
                f"  first differing pose #{f['index']}: words {f['pose_words']}; emulation {f['emulation_lengths']}, "
                f"firmware {f['firmware_lengths']} (leg {f['first_leg']})"
            )
            if "trace" in f:
                t = f["trace"]
                print(f"  first differing word: {t['first_differing_word']}")
                for name, v in t["emulation"].items():
                    fw = t["firmware"][name] if t["firmware"] else "-"
                    mark = "  <--" if t["firmware"] and fw != v else ""
                    print(f"    {name:>12} emulation {v:>10} firmware {fw:>10}{mark}")
        t = r["tick"]
        if t is None:
            print("sd_tick: not defined (IK only)")
        else:
            print(
                f"sd_tick: {t['ticks']} closed-loop ticks, {t['differing_ticks']} differ, worst command difference {t['worst_command_lsb']} LSB"
            )
            if t["first_difference"]:
                d = t["first_difference"]
                print(
                    f"  first differing tick {d['tick']}: emulation command {d['emulation_command']}, firmware {d['firmware_command']}"
                )
        print("identical to the emulation" if r["identical"] else "DIFFERS from the emulation")
    return 0 if r["identical"] else 1
