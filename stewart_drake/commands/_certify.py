"""``stewart-drake firmware certify`` and ``firmware optimize`` (registered by ``commands.firmware``): the
firmware's word ranges, saturation and error bound proven over a pose box, and the word formats chosen
by that proof."""

from __future__ import annotations

import math

from stewart_drake.api import firmware
from stewart_drake.commands._common import print_json
from stewart_drake.core.rotations import ANGLE_UNITS, LENGTH_UNITS
from stewart_drake.errors import OptionError


def add_box_args(p) -> None:
    """``--box KEY=LO..HI ...`` / ``--workspace``, the units, the budget."""
    g = p.add_mutually_exclusive_group()
    g.add_argument(
        "--box",
        nargs="+",
        metavar="KEY=LO..HI",
        default=None,
        help="pose box words, KEY one of px py pz a b g (e.g. pz=120..250 a=-0.08..0.08); "
        "keys not given keep the workspace box's range",
    )
    g.add_argument(
        "--workspace", action="store_true", help="the platform's workspace box (the default when --box is not given)"
    )
    p.add_argument("--length-unit", choices=list(LENGTH_UNITS), default="mm", help="unit of px py pz (default mm)")
    p.add_argument(
        "--angle-unit", choices=list(ANGLE_UNITS), default="pi", help="unit of a b g (default pi: fractions of pi)"
    )
    p.add_argument(
        "--max-cells",
        type=int,
        default=None,
        metavar="N",
        help="branch-and-bound budget: cells evaluated (default 200000; memory stays bounded whatever N)",
    )


# the format options left out take the machine's values (a platform's machine has the DSP's defaults)
MACHINE_DEFAULTS = dict.fromkeys(("word_bits", "length_lsb", "trig", "convention", "rate", "sensor_resolution"))


def register(fs, format_args, format_kwargs, call_api) -> None:
    """Add ``certify`` and ``optimize`` to the ``firmware`` subparsers ``fs``; ``format_args`` adds
    generate's format options, ``format_kwargs(args)`` turns them into the API's keywords,
    ``call_api(function, args, ...)`` calls the API naming the options by their flags."""
    c = fs.add_parser(
        "certify",
        help="prove every sd_ik word's range, saturation and a bound on |L_firmware - L_float| over a pose box",
    )
    format_args(c)
    add_box_args(c)
    c.add_argument(
        "--implementation",
        choices=["generated", "tp17"],
        default="generated",
        help="generated: the sd_ik of `firmware generate` with these format options (default); "
        "tp17: the seed's DSP firmware (utn-kinematic; its own 16-bit, 1 mm, tfr16 words)",
    )
    c.add_argument(
        "--tick",
        action="store_true",
        help="also certify sd_tick's PID words for the stated bounds (--tick-error, --tick-speed, --tick-feedforward)",
    )
    c.add_argument("--tick-error", type=float, default=5.0, metavar="MM", help="|set-point - measured| bound, mm (5)")
    c.add_argument("--tick-speed", type=float, default=0.1, metavar="M/S", help="leg speed bound, m/s (0.1)")
    c.add_argument("--tick-feedforward", type=float, default=0.0, metavar="N", help="|feed-forward| bound, N (0: none)")
    c.add_argument("--json", action="store_true", help="print JSON")
    c.set_defaults(func=run_certify, format_kwargs=format_kwargs, call_api=call_api, **MACHINE_DEFAULTS)
    o = fs.add_parser(
        "optimize",
        help="choose the length LSB, word bits and trig so the proven error meets a budget without saturation",
    )
    format_args(o)
    add_box_args(o)
    o.add_argument("--error-budget", required=True, metavar="LEN", help="e.g. 0.5mm, 500um, 0.0005 (metres)")
    o.add_argument("--objective", choices=["bits", "cycles"], default="bits", help="minimise word bits or sd_ik cycles")
    o.add_argument("--out", default=None, metavar="DIR", help="write the chosen firmware (sd_firmware.h/.c, README)")
    o.add_argument("--json", action="store_true", help="print JSON")
    o.set_defaults(func=run_optimize, format_kwargs=format_kwargs, call_api=call_api, **MACHINE_DEFAULTS)


def _call(function, args, **keywords):
    """``function`` (``firmware.certify`` or ``optimize``) of ``--platform`` with ``keywords`` and the options
    both share (the format, the box and its units, the budget), through ``call_api``."""
    shared = dict(box=args.box, length_unit=args.length_unit, angle_unit=args.angle_unit, max_cells=args.max_cells)
    return args.call_api(function, args, args.platform, **keywords, **shared, **args.format_kwargs(args))


def run_certify(args) -> int:
    if not (math.isfinite(args.tick_error) and args.tick_error >= 0):  # in mm here, in m in the API's message
        raise OptionError(OptionError.AT_LEAST.format(option="--tick-error", min=0, value=f"{args.tick_error:g}"))
    r = _call(
        firmware.certify,
        args,
        implementation=args.implementation,
        tick=args.tick,
        tick_error=args.tick_error * 1e-3,
        tick_speed=args.tick_speed,
        tick_feedforward=args.tick_feedforward,
    )
    if args.json:
        print_json(r.to_dict())
    else:
        print(format_certificate(r.certificate))
        if r.tick is not None:
            print(format_tick(r.tick))
    return 1 if r.saturation_possible else 0


def format_tick(tick) -> str:
    """The tick's certificate as text."""
    lines = [
        f"sd_tick for |error| <= {tick.max_error_m * 1e3:g} mm, leg speed <= {tick.max_speed_mps:g} m/s, "
        f"|feed-forward| <= {tick.max_feedforward_n:g} N:",
        f"{'word':>28} {'proven min':>12} {'proven max':>12} {'headroom':>9}  saturation",
    ]
    for w in tick.words:
        rail = " (its rail: the law's limit)" if w.rail and w.saturation != "impossible" else ""
        lines.append(f"{w.name:>28} {w.min:>12} {w.max:>12} {w.headroom_bits:>8.2f}b  {w.saturation}{rail}")
    lines.append(
        "anti-windup: the integrator is proven to stay inside its Q31 rails"
        if tick.anti_windup
        else "anti-windup: not proven to keep the integrator off its rails (it may reach them; saturating adds: no wrap)"
    )
    clamped = [w.name for w in tick.words if w.saturation != "impossible" and not w.rail]
    lines.append(
        f"SATURATION POSSIBLE in sd_tick's arithmetic within these bounds: {', '.join(clamped)}"
        if clamped
        else "sd_tick: no saturation of the arithmetic within these bounds"
    )
    return "\n".join(lines)


def format_certificate(cert) -> str:
    """The certificate as text: the range table, the bounds, the verdict."""
    fmt = cert.fmt
    box = cert.box.to_units(cert.length_unit, cert.angle_unit)
    lines = [
        f"firmware certificate for {cert.platform}: {fmt.word_bits}-bit words, length LSB {fmt.length_lsb:g} m, "
        f"trig {fmt.trig}, convention {cert.convention}",
        "box: "
        + ", ".join(f"{k} {a:g}..{b:g}" for k, (a, b) in box.items())
        + f" ({cert.length_unit}, {cert.angle_unit})",
        f"{'word':>12} {'proven min':>12} {'proven max':>12} {'headroom':>9}  saturation",
    ]
    for w in cert.words:
        note = " (trig clamp, within its certified error)" if w.benign and w.saturation != "impossible" else ""
        lines.append(f"{w.name:>12} {w.min:>12} {w.max:>12} {w.headroom_bits:>8.2f}b  {w.saturation}{note}")
    mm = cert.error_bound_mm
    lines.append(
        "proven |L_firmware - L_float| per leg: "
        + ", ".join("unbounded (saturation possible)" if e is None else f"{e:.4f} mm" for e in mm)
    )
    lines.append(f"cells evaluated: {cert.cells}{' (budget reached)' if cert.exhausted else ''}")
    if cert.witness is not None:
        wt = cert.witness
        lines.append(
            "SATURATION: witness pose "
            + ", ".join(f"{k} {v:.6g}" for k, v in wt["pose"].items())
            + f" (words {wt['pose_words']}) saturates {', '.join(wt['saturates'])}; "
            + f"the emulation counts {wt['emulation_saturations']}"
        )
    elif cert.saturation_possible:
        lines.append(
            f"SATURATION POSSIBLE: {cert.unresolved_count} cells undecided within the budget, no witness found "
            "(raise --max-cells); first: " + "; ".join(str(c) for c in cert.to_dict()["unresolved_cells"][:3])
        )
    else:
        lines.append("proven: no arithmetic word saturates anywhere in the box")
    return "\n".join(lines)


def run_optimize(args) -> int:
    r = _call(firmware.optimize, args, error_budget=args.error_budget, objective=args.objective, out=args.out)
    if args.json:
        print_json(r.to_dict())
    else:
        print(r.summary())
    return 0 if r.chosen is not None else 1
