"""``stewart-drake tune``: gains that meet the margins at every pose of the workspace box's grid, the finest
proven length LSB, the predicted ripple, the tuned machine verified by the nonlinear loop; writes the tuned
machine file (the original is never modified)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

from stewart_drake.api.tune import tune
from stewart_drake.commands._common import flag_error, print_json
from stewart_drake.control.frequency import MIN_GAIN_MARGIN_DB, MIN_PHASE_MARGIN_DEG
from stewart_drake.errors import TuneError
from stewart_drake.spec import apply_overrides, load_machine
from stewart_drake.spec.quantity import parse_number

HELP = "tune the leg PID gains and length LSB of a machine to stated margins; write the tuned machine"
# the API's argument names -> the flags that set them
FLAGS = {
    "bandwidth": ("--bandwidth", None),
    "gain_margin_db": ("--gain-margin", None),
    "phase_margin_deg": ("--phase-margin", None),
    "error_budget": ("--error-budget", None),
    "out": ("--out", None),
}


def register(sub) -> None:
    p = sub.add_parser("tune", help=HELP)
    p.add_argument("--machine", required=True, metavar="FILE", help="the machine file to tune (never modified)")
    p.add_argument(
        "--set", action="append", default=[], metavar="PATH=VALUE", help="set one field of the machine by its spec path"
    )
    p.add_argument("--bandwidth", default=None, metavar="HZ", help="worst-pose bandwidth to reach, e.g. 8Hz")
    p.add_argument("--gain-margin", default=f"{MIN_GAIN_MARGIN_DB:g}dB", metavar="DB", help="default 6dB")
    p.add_argument("--phase-margin", default=f"{MIN_PHASE_MARGIN_DEG:g}deg", metavar="DEG", help="default 30deg")
    p.add_argument("--error-budget", default="0.5mm", metavar="LEN", help="certified IK error allowed (0.5mm)")
    p.add_argument(
        "--box",
        action="append",
        default=None,
        metavar="KEY=LO..HI",
        help="narrow the workspace box (px py pz in mm, a b g in degrees; repeatable) whose grid the gains must "
        "hold on and over which the format is certified",
    )
    p.add_argument("--out", required=True, metavar="FILE", help="the tuned machine file to write (a new file)")
    p.add_argument("--force", action="store_true", help="replace an existing --out file")
    p.set_defaults(func=run)


def _db(text: str) -> float:
    s = str(text).strip()
    return parse_number(s[:-2] if s.endswith("dB") else s, "ratio", "--gain-margin")


def run(args) -> int:
    out = Path(args.out)
    if out.exists() and out.resolve() == Path(args.machine).resolve():
        raise flag_error(TuneError(TuneError.OUT_IS_MACHINE.format(path=args.out)), FLAGS)
    if out.is_dir():
        raise flag_error(TuneError(TuneError.OUT_FOLDER.format(path=args.out)), FLAGS)
    if out.exists() and not args.force:
        raise flag_error(TuneError(TuneError.OUT_EXISTS.format(path=args.out)), FLAGS)
    options = {
        "bandwidth": None if args.bandwidth is None else parse_number(args.bandwidth, "frequency", "--bandwidth"),
        "gain_margin_db": _db(args.gain_margin),
        "phase_margin_deg": float(
            f"{math.degrees(parse_number(args.phase_margin, 'angle', '--phase-margin', bare=math.pi / 180)):.12g}"
        ),
        "error_budget": parse_number(args.error_budget, "length", "--error-budget"),
        "box": args.box,
    }
    machine = apply_overrides(load_machine(args.machine), args.set)
    try:
        r = tune(machine, **options)
    except TuneError as e:
        raise flag_error(e, FLAGS) from None
    d = r.to_dict()
    d.pop("grid_poses")
    if r.ok:  # a machine that falls short is shown, not written
        tmp = out.with_name(f".{out.name}.tmp")
        tmp.write_text(r.machine.to_yaml())
        tmp.replace(out)  # complete or absent
        d["out"] = str(out)
    print_json(d)
    for f in r.failures:
        print(f"stewart-drake tune: {f}", file=sys.stderr)
    return 0 if r.ok else 1
