"""``stewart-drake calibrate``: identify a built platform's geometry from measurements; write the calibrated
platform file, the full result and its plots."""

from __future__ import annotations

import datetime

import numpy as np

from stewart_drake.calibration.identify import CalibrationResult, identify, min_poses
from stewart_drake.calibration.measurements import TYPES, read_measurements
from stewart_drake.calibration.model import Layout
from stewart_drake.calibration.noise import parse_noise
from stewart_drake.calibration.validate import validation_errors
from stewart_drake.commands._common import (
    add_force_arg,
    output_folder,
    platform_from_args,
    print_json,
)
from stewart_drake.core.geometry import CalibrationRecord
from stewart_drake.core.jsonout import dumps_strict
from stewart_drake.core.platform_file import platform_yaml
from stewart_drake.core.rotations import ANGLE_UNITS, CONVENTIONS, LENGTH_UNITS
from stewart_drake.errors import CalibrationError, CalibrationLimitError

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
        "--platform", required=True, metavar="NAME|FILE", help="the nominal platform: a preset or a platform YAML file"
    )
    p.add_argument("--measurements", required=True, metavar="M.csv", help="measurement CSV (header: l1..l6 and ...)")
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


def _split(args, data, layout: Layout):
    """``(fit, validation or None)`` from --holdout / --validate."""
    need = min_poses(layout)
    if args.validate is not None:
        platform = layout.nominal
        val = read_measurements(args.validate, platform, data.kind, args.length_unit, args.angle_unit)
        if val.n_targets != data.n_targets:
            raise CalibrationError(
                CalibrationError.VALIDATE_TARGETS.format(
                    path=args.validate, got=val.n_targets, fit=args.measurements, want=data.n_targets
                )
            )
        return data, val
    if args.holdout is None:
        return data, None
    if not 0 < args.holdout <= 0.5:
        raise CalibrationError(CalibrationError.HOLDOUT.format(value=args.holdout))
    n = len(data)
    held = max(1, int(round(args.holdout * n)))
    if n - held < need:
        raise CalibrationError(
            CalibrationError.HOLDOUT_TOO_FEW.format(value=args.holdout, held=held, n=n, left=n - held, need=need)
        )
    order = np.random.default_rng(args.seed).permutation(n)
    return data.subset(np.sort(order[held:])), data.subset(np.sort(order[:held]))


def calibrate(args) -> tuple[CalibrationResult, dict]:
    """Read, check, identify and validate as the options say; returns the result and its JSON dict."""
    platform = platform_from_args(args)
    noise = parse_noise(args.noise)
    data = read_measurements(args.measurements, platform, args.type, args.length_unit, args.angle_unit)
    layout = Layout(platform, data.kind, data.n_targets, args.gains)
    fit, val = _split(args, data, layout)
    need = min_poses(layout)
    if len(fit) < need:
        per = layout.rows()
        raise CalibrationError(
            CalibrationError.TOO_FEW.format(
                path=args.measurements,
                n=len(fit),
                equations=len(fit) * per,
                unknowns=layout.size + len(fit) * layout.nuisance,
                parameters=layout.size,
                nuisance=f" + {layout.nuisance} per pose" if layout.nuisance else "",
                need=need,
            )
        )
    result = identify(platform, fit, noise, args.convention, args.gains)
    if val is not None:
        targets0 = layout.split(result.theta0)[3]
        result.validation = {
            "poses": len(val),
            "lines": val.lines.tolist() if args.validate is None else None,
            "source": val.source,
            "nominal": validation_errors(platform, targets0, val, args.convention),
            "calibrated": validation_errors(result.calibrated, result.targets, val, args.convention),
        }
    return result, result.to_dict()


def record(result: CalibrationResult) -> CalibrationRecord:
    """The ``calibration:`` block of the calibrated platform file."""
    unit = {"pose": ("leg_length", "m"), "points": ("target", "m"), "inclinometer": ("tilt", "rad")}[result.layout.kind]
    v = result.validation
    vkey = "position" if result.layout.kind == "pose" else unit[0]
    return CalibrationRecord(
        source=result.source,
        sha256=result.sha256,
        date=datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
        measurement_type=result.layout.kind,
        poses=len(result.lines),
        residual_rms_before=result.fit_before[unit[0]]["rms"],
        residual_rms_after=result.fit_after[unit[0]]["rms"],
        residual_unit=unit[1],
        validation_rms_m=v["calibrated"][vkey]["rms"] if v and unit[1] == "m" else None,
        parameters=list(result.layout.names),
        sigma=[float(s * k) for s, k in zip(result.sigma, result.layout.scales())],
    )


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
        words = ", ".join(f"{k} RMS {_fmt(v)} max {_fmt(v, 'max')}" for k, v in d[side].items())
        out.append(f"{'nominal' if side == 'fit_before' else 'calibrated'} model on the fitted poses: {words}")
    v = d["validation"]
    if v:
        for side in ("nominal", "calibrated"):
            words = ", ".join(f"{k} RMS {_fmt(x)} max {_fmt(x, 'max')}" for k, x in v[side].items())
            out.append(f"validation ({v['poses']} poses), {side}: {words}")
    return "\n".join(out)


def _fmt(s: dict, key: str = "rms") -> str:
    return f"{s[key] * 1e6:.3g} µm" if s["unit"] == "m" else f"{s[key] * 1e6:.3g} µrad"


def run(args) -> int:
    out = output_folder(args)
    result, d = calibrate(args)
    if not result.converged:
        print_json(d) if args.json else print(_summary(d, result))
        raise CalibrationLimitError(CalibrationLimitError.NOT_CONVERGED.format(reason=result.message))
    rec = record(result)
    header = (
        f"{result.calibrated.name}: calibrated by stewart-drake calibrate from {result.source} "
        f"({d['poses']} {d['measurement_type']} poses), nominal {result.nominal.name}."
    )
    with out.writing() as tmp:
        (tmp / "calibrated.yaml").write_text(platform_yaml(result.calibrated, rec, header), encoding="utf-8")
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
            f"wrote {args.out}/calibrated.yaml, calibration.json"
            + ("" if args.no_plots else ", residuals.png, corrections.png")
        )
    return 0
