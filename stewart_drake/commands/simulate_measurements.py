"""``stewart-drake simulate-measurements``: measure a "true" machine drawn around the nominal (the Monte
Carlo ``--vary`` grammar for its joint and sensor-offset errors) with the given noise; the truth is written
apart, for checking a calibration."""

from __future__ import annotations

import numpy as np

from stewart_drake.calibration.measurements import TYPES, measurements_csv
from stewart_drake.calibration.noise import parse_noise
from stewart_drake.calibration.simulate import simulate_measurements
from stewart_drake.commands._common import (
    add_force_arg,
    add_platform_arg,
    output_folder,
    platform_from_args,
    print_json,
)
from stewart_drake.core.csvio import read_numeric_csv
from stewart_drake.core.jsonout import dumps_strict
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.platform_file import platform_yaml
from stewart_drake.core.rotations import ANGLE_UNITS, CONVENTIONS, LENGTH_UNITS, pose_to_si
from stewart_drake.core.sanity import check_poses
from stewart_drake.errors import CalibrationError
from stewart_drake.montecarlo.spec import parse_spec

HELP = "synthetic calibration measurements of a machine drawn around the nominal (truth written apart)"
GEOMETRIC_KEYS = ("anchor", "leg_offset")
MAX_POSES = 10_000


def register(sub) -> None:
    p = sub.add_parser("simulate-measurements", help=HELP, description=HELP + ". See docs/calibration.md.")
    add_platform_arg(p)
    p.add_argument(
        "--errors",
        nargs="+",
        default=["anchor=±1mm", "leg_offset=±0.5mm"],
        metavar="KEY=VALUE",
        help="the machine's errors in the montecarlo --vary grammar, keys anchor and leg_offset "
        "(default anchor=±1mm leg_offset=±0.5mm)",
    )
    p.add_argument(
        "--noise", nargs="+", default=[], metavar="KEY=VALUE", help="length=1um position=10um angle=20urad (default)"
    )
    p.add_argument(
        "--poses", required=True, metavar="PLAN.csv", help="poses px,py,pz,a,b,g (a plan-measurements poses.csv)"
    )
    p.add_argument("--length-unit", choices=list(LENGTH_UNITS), default="m", help="lengths of --poses (default m)")
    p.add_argument("--angle-unit", choices=list(ANGLE_UNITS), default="rad", help="angles of --poses (default rad)")
    p.add_argument("--convention", choices=list(CONVENTIONS), default="utn", help="Euler convention of the poses")
    p.add_argument("--type", choices=TYPES, default="pose", help="what is measured (default pose)")
    p.add_argument("--targets", type=int, default=3, help="--type points: targets on the plate (default 3)")
    p.add_argument("--seed", type=int, default=0, help="seed of the machine and of the noise (default 0)")
    p.add_argument("--out", required=True, metavar="DIR", help="output folder (created; only its own files replaced)")
    add_force_arg(p)
    p.add_argument("--json", action="store_true", help="print the truth as JSON")
    p.set_defaults(func=run)


def run(args) -> int:
    out = output_folder(args)
    platform = platform_from_args(args)
    spec = parse_spec(args.errors)
    bad = [k for k in spec.laws if k not in GEOMETRIC_KEYS]
    if bad:
        raise CalibrationError(CalibrationError.ERRORS_KEY.format(key=bad[0]))
    noise = parse_noise(args.noise)
    if not 1 <= args.targets <= 8:
        raise CalibrationError(CalibrationError.TARGET_COUNT.format(value=args.targets))
    raw, lines = read_numeric_csv(args.poses, "poses", (6,), "px,py,pz,a,b,g")
    if len(raw) > MAX_POSES:
        raise CalibrationError(CalibrationError.POSE_COUNT.format(path=args.poses, limit=MAX_POSES))
    q = pose_to_si(raw, args.length_unit, args.angle_unit)
    check_poses(platform, q, args.convention, what=f"{args.poses}: pose", lines=lines)
    L = leg_lengths(platform, q, args.convention)
    bad = np.argwhere((L < platform.L_min) | (L > platform.L_max))
    if bad.size:
        r, leg = bad[0]
        raise CalibrationError(
            CalibrationError.POSE_STROKE.format(
                path=args.poses, line=lines[r], leg=leg + 1, length=L[r, leg], lmin=platform.L_min, lmax=platform.L_max
            )
        )
    data, truth = simulate_measurements(
        platform, spec.laws, q, args.type, noise, args.seed, args.convention, args.targets
    )
    info = {
        "platform": platform.name,
        "errors": spec.to_dict(),
        "noise": noise.to_dict(),
        "seed": args.seed,
        "measurement_type": args.type,
        "convention": args.convention,
        "note": "leg_offset is what each sensor reads beyond the joint-to-joint length (as in montecarlo); "
        "the true legs.length_offset is the nominal's minus it",
        **truth.to_dict(),
    }
    with out.writing() as tmp:
        (tmp / "measurements.csv").write_text(measurements_csv(data), encoding="utf-8")
        (tmp / "truth").mkdir()
        header = f"The true machine drawn by stewart-drake simulate-measurements (seed {args.seed}): for checking only."
        (tmp / "truth" / "platform.yaml").write_text(platform_yaml(truth.platform, None, header), encoding="utf-8")
        (tmp / "truth" / "truth.json").write_text(dumps_strict(info) + "\n", encoding="utf-8")
    if args.json:
        print_json(info)
    else:
        print(
            f"platform {platform.name}: {len(q)} {args.type} measurements of a machine drawn with {' '.join(args.errors)} "
            f"(seed {args.seed}); noise σ: length {noise.length:g} m, position {noise.position:g} m, angle {noise.angle:g} rad"
        )
        print(f"wrote {args.out}/measurements.csv (m, rad) and, apart, {args.out}/truth/platform.yaml, truth.json")
    return 0
