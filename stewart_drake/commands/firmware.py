"""``stewart-drake firmware``: generate the C firmware module for a platform, or check a user's C
firmware against the bit-exact emulation."""

from __future__ import annotations

import sys
from pathlib import Path

from stewart_drake.api import firmware
from stewart_drake.commands._certify import register as register_certify
from stewart_drake.commands._common import add_platform_arg, machine_from_args, platform_arg, print_json
from stewart_drake.core.geometry import load_platform
from stewart_drake.core.isolate import FIRMWARE_TIME_LIMIT_S
from stewart_drake.firmware.fingerprint import DEFAULTS as FP_DEFAULTS


def _format_args(p, recorded: bool = False) -> None:
    """The module's options; with ``recorded`` (``check``) their defaults are those recorded in the file
    (``firmware.fingerprint``), the generator's defaults for a file without a record; else those of the machine
    file ``--platform`` names (its ``firmware`` format, ``1 / controller.period``, ``sensors.resolution``), the
    generator's defaults for a platform."""
    d = lambda k: None  # noqa: E731  (filled by _format: the record, a machine file's value or FP_DEFAULTS)
    note = " (default: as recorded in FILE.c's header, else" if recorded else " (default: a machine file's, else"
    add_platform_arg(p, default=None if recorded else FP_DEFAULTS["platform"])
    p.set_defaults(recorded_format=recorded)
    p.add_argument(
        "--word-bits",
        type=int,
        default=d("word_bits"),
        metavar="N",
        help="data word width, 8..16" + note + " 16, the DSP)",
    )
    p.add_argument(
        "--length-lsb",
        type=float,
        default=d("length_lsb"),
        metavar="M",
        help="metres per length LSB" + note + " 1e-3: integer mm)",
    )
    p.add_argument(
        "--trig",
        choices=["tfr16", "exact"],
        default=d("trig"),
        help="sin/cos: tfr16 (the DSP library polynomial, 16-bit words) or exact (a correctly rounded table)"
        + note
        + " tfr16)",
    )
    p.add_argument(
        "--convention",
        choices=["utn", "zyx"],
        default=d("convention"),
        help="Euler convention of the pose angles" + note + " utn)",
    )
    p.add_argument(
        "--rate",
        type=float,
        default=d("rate"),
        metavar="HZ",
        help="controller rate, Hz" + note + " 1000)",
    )
    p.add_argument(
        "--sensor-resolution",
        type=float,
        default=d("sensor_resolution"),
        metavar="M",
        help="leg sensor, m per count" + note + " 1e-5)",
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
    fs = p.add_subparsers(dest="firmware_command", required=True, metavar="generate|check|certify|optimize")
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
    _format_args(c, recorded=True)
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
    register_certify(fs, _format_args, _format)


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


def _format(args) -> dict:
    """The number format, rate, sensor and design reference the options give (``api.firmware``'s keywords);
    an option left out is, for ``check``, None (the record's), else the machine file's value or the default."""
    given = {
        k: getattr(args, k) for k in ("word_bits", "length_lsb", "trig", "convention", "rate", "sensor_resolution")
    }
    if not args.recorded_format:
        m = machine_from_args(args)
        own = (
            {}
            if m is None
            else dict(
                word_bits=m.firmware.word_bits,
                length_lsb=m.firmware.length_lsb,
                trig=m.firmware.trig,
                convention=m.firmware.convention,
                rate=1.0 / m.controller.period,
                sensor_resolution=m.sensors.resolution,
            )
        )
        given = {k: own.get(k, FP_DEFAULTS[k]) if v is None else v for k, v in given.items()}
    return dict(given, trajectory=args.trajectory)


def run_generate(args) -> int:
    note = lambda n: print(f"stewart-drake firmware generate: note: {n}", file=sys.stderr)  # noqa: E731
    machine = machine_from_args(args)
    platform = load_platform(args.platform) if machine is None else machine.platform
    r = firmware.generate(
        platform if machine is None else machine,
        args.out,
        compile=not args.no_compile,
        on_note=note,
        platform_source=args.platform if machine is None else None,
        **_format(args),
    )
    summary, out, compiled, written = r.to_dict(), Path(args.out), r.summary["compiled_with"], r.files
    clock_hz = r.config.timing.clock_hz
    if args.json:
        print_json(summary)
    else:
        print(
            f"wrote {len(written)} files to {out}/ for {platform.name}: "
            + ", ".join(f"{f['name']} ({f['bytes']} B)" for f in summary["files"])
        )
        print(
            f"cycle estimate at {clock_hz / 1e6:g} MHz: sd_ik {summary['ik_cycles']} cycles ({summary['ik_us']} µs), "
            f"sd_tick {summary['tick_cycles']} cycles ({summary['tick_us']} µs)"
        )
        if not args.no_compile:
            print("compile-checked (-std=c99 -Wall -Wextra -Werror -pedantic) with: " + (", ".join(compiled) or "none"))
    return 0


def run_check(args) -> int:
    result = firmware.check(
        args.file,
        platform_arg(args),  # None: as recorded in the file
        poses=args.poses,
        seed=args.seed,
        trace=args.trace,
        duration=args.duration,
        compiler=args.compiler,
        time_limit=args.time_limit,
        **_format(args),
    )
    r = result.to_dict()
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
