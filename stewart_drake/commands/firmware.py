"""``stewart-drake firmware``: generate the C firmware module for a platform, or check a user's C
firmware against the bit-exact emulation."""

from __future__ import annotations

import sys
from pathlib import Path

from stewart_drake.api import firmware
from stewart_drake.commands._certify import register as register_certify
from stewart_drake.commands._common import add_platform_arg, flag_error, print_json
from stewart_drake.errors import StewartError, UsageError
from stewart_drake.firmware.fingerprint import DEFAULTS as FP_DEFAULTS
from stewart_drake.spec import load_machine
from stewart_drake.system.isolate import FIRMWARE_TIME_LIMIT_S


def _format_args(p, recorded: bool = False) -> None:
    """The module's options; with ``recorded`` (``check``) their defaults are those recorded in the file
    (``firmware.fingerprint``), the generator's defaults for a file without a record."""
    d = (lambda k: None) if recorded else FP_DEFAULTS.get
    note = " (default: as recorded in FILE.c's header" if recorded else ""
    add_platform_arg(p, default=d("platform"))
    p.add_argument(
        "--word-bits",
        type=int,
        default=d("word_bits"),
        metavar="N",
        help="data word width, 8..16" + (note + ", else 16)" if recorded else " (default 16, the DSP)"),
    )
    p.add_argument(
        "--length-lsb",
        type=float,
        default=d("length_lsb"),
        metavar="M",
        help="metres per length LSB" + (note + ", else 1e-3)" if recorded else " (default 1e-3: integer mm)"),
    )
    p.add_argument(
        "--trig",
        choices=["tfr16", "exact"],
        default=d("trig"),
        help="sin/cos: tfr16 (the DSP library polynomial, 16-bit words) or exact (a correctly rounded table)"
        + (note + ", else tfr16)" if recorded else "; default tfr16"),
    )
    p.add_argument(
        "--convention",
        choices=["utn", "zyx"],
        default=d("convention"),
        help="Euler convention of the pose angles" + (note + ", else utn)" if recorded else " (default utn)"),
    )
    p.add_argument(
        "--rate",
        type=float,
        default=d("rate"),
        metavar="HZ",
        help="controller rate, Hz" + (note + ", else 1000)" if recorded else " (default 1000)"),
    )
    p.add_argument(
        "--sensor-resolution",
        type=float,
        default=d("sensor_resolution"),
        metavar="M",
        help="leg sensor, m per count" + (note + ", else 1e-5)" if recorded else " (default 1e-5)"),
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
    fs = p.add_subparsers(dest="firmware_command", required=True, metavar="generate|build|check|certify|optimize")
    g = fs.add_parser("generate", help="emit a self-contained C99 module: sd_ik, sd_init, sd_tick (+ README)")
    _format_args(g)
    g.add_argument(
        "--out", required=True, metavar="DIR", help="output folder (created; only its own files are replaced)"
    )
    g.add_argument(
        "--no-compile", action="store_true", help="do not compile-check the module with the available compilers"
    )
    g.add_argument("--json", action="store_true", help="print the summary as JSON")
    g.add_argument(
        "--machine",
        default=None,
        metavar="FILE",
        help="a machine file (see `simulate --machine`): its platform, payload, firmware format, rate (1/period) "
        "and sensor resolution; the options above replace them",
    )
    # None: the machine's (a platform's machine has the defaults the options' help names)
    g.set_defaults(func=run_generate, **dict.fromkeys(MACHINE_OPTIONS))
    b = fs.add_parser(
        "build", help="cross-compile the generated firmware with the PIL runtime: ELF, map, code/data size, stack depth"
    )
    _format_args(b)
    b.add_argument(
        "--target",
        default="cortex-m4",
        metavar="NAME",
        help="the processor: cortex-m4 (the MPS2+ AN386 board, as QEMU models it), cortex-m4-semihosting (the same "
        "board, its link on the semihosting console: QEMU or a debug probe) or stm32f405 (an STM32F405/F407 board "
        "such as the STM32F4 Discovery: USART2 on PA2/PA3) (arm-none-eabi-gcc; default cortex-m4)",
    )
    b.add_argument(
        "--out", required=True, metavar="DIR", help="output folder (created; only its own files are replaced)"
    )
    b.add_argument("--json", action="store_true", help="print the summary as JSON")
    b.set_defaults(func=run_build, **dict.fromkeys(MACHINE_OPTIONS))
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
    register_certify(fs, _format_args, _format, call_api)


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
    """The number format, rate, sensor and design reference the options give (``api.firmware``'s keywords)."""
    return dict(
        word_bits=args.word_bits,
        length_lsb=args.length_lsb,
        trig=args.trig,
        convention=args.convention,
        rate=args.rate,
        sensor_resolution=args.sensor_resolution,
        trajectory=args.trajectory,
    )


# option (argparse dest) -> (flag, spec path): the API's messages name the spec path or the keyword
# (``length_lsb=0.001 here``); the command line names the flag the user gave.
FORMAT_FLAGS = {
    "platform": ("--platform", None),
    "word_bits": ("--word-bits", "firmware.word_bits"),
    "length_lsb": ("--length-lsb", "firmware.length_lsb"),
    "trig": ("--trig", "firmware.trig"),
    "convention": ("--convention", "firmware.convention"),
    "rate": ("--rate", None),
    "sensor_resolution": ("--sensor-resolution", "sensors.resolution"),
    "trajectory": ("--trajectory", None),
    "tick_speed": ("--tick-speed", None),
    "tick_feedforward": ("--tick-feedforward", None),
    "box": ("--box", None),
    "max_cells": ("--max-cells", None),
    "error_budget": ("--error-budget", None),
    "implementation": ("--implementation", None),
}


def call_api(function, args, *positional, **keywords):
    """``function(*positional, **keywords)`` (an ``api.firmware`` function), its errors about the format options
    the user gave named by their flags."""
    try:
        return function(*positional, **keywords)
    except StewartError as e:
        raise flag_error(e, FORMAT_FLAGS, [d for d in FORMAT_FLAGS if getattr(args, d, None) is not None]) from None


# firmware generate's options that default to the machine's
MACHINE_OPTIONS = ("platform", "word_bits", "length_lsb", "trig", "convention", "rate", "sensor_resolution")


def run_generate(args) -> int:
    note = lambda n: print(f"stewart-drake firmware generate: note: {n}", file=sys.stderr)  # noqa: E731
    if args.machine is not None and args.platform is not None:
        raise UsageError(UsageError.NOT_BOTH.format(first="--machine", second="--platform"))
    source = args.machine or args.platform or FP_DEFAULTS["platform"]
    machine = load_machine(source)
    platform = machine.platform
    r = call_api(
        firmware.generate,
        args,
        machine,
        args.out,
        compile=not args.no_compile,
        on_note=note,
        platform_source=source,
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


def run_build(args) -> int:
    source = args.platform or FP_DEFAULTS["platform"]
    r = call_api(firmware.build, args, source, args.out, target=args.target, platform_source=source, **_format(args))
    s = r.to_dict()
    if args.json:
        print_json(s)
        return 0
    print(f"wrote {', '.join(s['files'])} to {Path(args.out)}/ for {s['platform']} on {s['target']} ({s['board']})")
    print(f"code {s['code_bytes']} B (flash), data {s['data_bytes']} B + bss {s['bss_bytes']} B (RAM)")
    if s["stack_bytes"] is None:
        print("stack depth: unbounded (" + " -> ".join(s["stack_path"]) + ")")
    else:
        print(f"stack depth: {s['stack_bytes']} B worst case (" + " -> ".join(s["stack_path"]) + ")")
    fs = s["functions"]
    stack = lambda v: "unbounded" if v is None else f"{v} B"  # noqa: E731
    print("; ".join(f"{f}: code {v['code_bytes']} B, stack {stack(v['stack_bytes'])}" for f, v in fs.items()))
    return 0


def run_check(args) -> int:
    result = call_api(
        firmware.check,
        args,
        args.file,
        args.platform,  # None: as recorded in the file
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
