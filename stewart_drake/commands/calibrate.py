"""``stewart-drake calibrate``: identify a built platform's geometry from measurements; write the calibrated
platform file, the full result and its plots."""

from __future__ import annotations

from stewart_drake.api.calibration import calibrate
from stewart_drake.calibration.identify import CalibrationResult
from stewart_drake.calibration.measurements import TYPES
from stewart_drake.commands._common import (
    MACHINE_KINEMATIC,
    add_force_arg,
    output_folder,
    platform_machine,
    print_json,
)
from stewart_drake.core.rotations import ANGLE_UNITS, CONVENTIONS, LENGTH_UNITS
from stewart_drake.errors import CalibrationLimitError, UsageError
from stewart_drake.system.jsonout import dumps_strict

HELP = "identify a built platform's geometry from measured poses; write a calibrated platform file"


def register(sub) -> None:
    p = sub.add_parser(
        "calibrate",
        help=HELP,
        description="Kinematic calibration: robust least squares (Huber) of the joint centres and leg-sensor offsets "
        "on measured poses; the data's unidentifiable combinations are named and held at nominal; σ per parameter "
        "from the stated noise; validation on held-out poses. See docs/calibration.md.",
    )
    p.add_argument(
        "--platform",
        required=True,
        metavar="NAME|FILE",
        help=f"the nominal platform: a preset, a platform YAML file or a machine file ({MACHINE_KINEMATIC})",
    )
    p.add_argument(
        "--measurements",
        metavar="M.csv",
        help="measurement CSV (header: l1..l6 and ...); default: the file a machine file's calibration: names",
    )
    p.add_argument("--type", choices=TYPES, default=None, help="measurement kind (default: from the header)")
    g = p.add_mutually_exclusive_group()
    g.add_argument(
        "--holdout", type=float, metavar="FRACTION", help="hold out this fraction of the poses for validation"
    )
    g.add_argument("--validate", metavar="V.csv", help="validation measurements (same kind and units)")
    p.add_argument(
        "--noise",
        nargs="+",
        default=[],
        metavar="KEY=VALUE",
        help="measurement σ: length=1um position=10um angle=20urad (the defaults)",
    )
    p.add_argument("--length-unit", choices=list(LENGTH_UNITS), default="m", help="lengths in the CSV (default m)")
    p.add_argument("--angle-unit", choices=list(ANGLE_UNITS), default="rad", help="angles in the CSV (default rad)")
    p.add_argument("--convention", choices=list(CONVENTIONS), default="utn", help="Euler convention of the poses")
    p.add_argument("--gains", action="store_true", help="identify each leg sensor's gain too (legs.length_gain)")
    p.add_argument("--seed", type=int, default=0, help="seed of the --holdout split (default 0)")
    p.add_argument("--no-plots", action="store_true", help="skip residuals.png and corrections.png")
    p.add_argument("--out", required=True, metavar="DIR", help="output folder (created; only its own files replaced)")
    add_force_arg(p)
    p.add_argument("--json", action="store_true", help="print calibration.json to stdout")
    p.set_defaults(func=run)


def _summary(d: dict, result: CalibrationResult) -> str:
    ident = d["identifiability"]
    out = [
        f"platform {d['platform']}: {d['poses']} {d['measurement_type']} poses from {d['source']}; {d['message']} "
        f"({d['evaluations']} evaluations)",
        f"residual RMS (in σ of the stated noise): {d['residual_rms_sigma']['before']:.3g} nominal -> "
        f"{d['residual_rms_sigma']['after']:.3g} calibrated",
        f"identifiable {ident['identifiable']} of {ident['parameters']} parameters; condition number "
        f"{ident['condition_number']:.3g}; noise-amplification index {ident['noise_amplification_index']:.3g}",
    ]
    if ident["frame_freedoms"]:
        out.append("the data cannot fix: " + ", ".join(ident["frame_freedoms"]))
    if ident["unidentifiable"]:
        out.append(
            f"{ident['unidentifiable']} unidentifiable combinations, held at nominal by fixing: "
            + ", ".join(ident["fixed_by_convention"])
        )
    for o in d["outliers"]:
        out.append(
            f"outlier: line {o['line']} (residual {o['rms_sigma']:.3g} σ RMS; χ² {o['chi2']:.3g} > {o['limit']:.3g})"
        )
    for side in ("fit_before", "fit_after"):
        out.append(
            f"{'nominal' if side == 'fit_before' else 'calibrated'} model on the fitted poses: {_words(d[side])}"
        )
    v = d["validation"]
    if v:
        for side in ("nominal", "calibrated"):
            out.append(f"validation ({v['poses']} poses), {side}: {_words(v[side])}")
    out += [f"warning: {w}" for w in d["warnings"]]
    out += [f"failed: {f}" for f in d["failures"]]
    return "\n".join(out)


def _words(errors: dict) -> str:
    words = [f"{k} RMS {_fmt(v)} max {_fmt(v, 'max')}" for k, v in errors.items() if "unit" in v]
    if "unsolved" in errors:
        u = errors["unsolved"]
        words.append(f"forward kinematics unsolved at {u['count']} poses (lines {', '.join(map(str, u['lines'][:8]))})")
    return ", ".join(words)


def _fmt(s: dict, key: str = "rms") -> str:
    return f"{s[key] * 1e6:.3g} µm" if s["unit"] == "m" else f"{s[key] * 1e6:.3g} µrad"


def measurements_arg(args, machine) -> str:
    """``--measurements``, or the file that ``machine`` (the machine file given as ``--platform``, or None) names
    in ``calibration:``."""
    if args.measurements is not None:
        return args.measurements
    if machine is None or machine.calibration is None:
        raise UsageError(UsageError.MEASUREMENTS.format(platform=args.platform))
    return machine.calibration


def run(args) -> int:
    machine = platform_machine(args)  # read once: for its measurements and its platform
    measurements = measurements_arg(args, machine)
    out = output_folder(args)
    cal = calibrate(
        args.platform if machine is None else machine,
        measurements,
        type=args.type,
        length_unit=args.length_unit,
        angle_unit=args.angle_unit,
        holdout=args.holdout,
        validate=args.validate,
        seed=args.seed,
        gains=args.gains,
        noise=args.noise,
        convention=args.convention,
    )
    result, d = cal.identified, cal.to_dict()
    if not cal.converged:
        print_json(d) if args.json else print(_summary(d, result))
        raise CalibrationLimitError(CalibrationLimitError.NOT_CONVERGED.format(reason=result.message))
    with out.writing() as tmp:
        if cal.ok:
            (tmp / "calibrated.yaml").write_text(cal.platform_yaml(), encoding="utf-8")
        (tmp / "calibration.json").write_text(dumps_strict(d) + "\n", encoding="utf-8")
        if not args.no_plots:
            import matplotlib  # noqa: PLC0415 -- deferred: plotting only when asked, and Agg chosen first

            matplotlib.use("Agg")
            from stewart_drake.calibration.plots import plot_calibration  # noqa: PLC0415 -- imports pyplot

            plot_calibration(result, tmp)
    if args.json:
        print_json(d)
    else:
        print(_summary(d, result))
        print(
            f"wrote {args.out}/"
            + ("calibrated.yaml, " if cal.ok else "")
            + "calibration.json"
            + ("" if args.no_plots else ", residuals.png, corrections.png")
        )
    if not cal.ok:
        raise CalibrationLimitError(CalibrationLimitError.NOT_USABLE.format(reason="; ".join(result.failures)))
    return 0
