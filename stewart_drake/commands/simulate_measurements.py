"""``stewart-drake simulate-measurements``: measure a "true" machine drawn around the nominal (the Monte
Carlo ``--vary`` grammar for its joint and sensor-offset errors) with the given noise; the truth is written
apart, for checking a calibration."""

from __future__ import annotations

from stewart_drake.calibration.measurements import TYPES, measurements_csv
from stewart_drake.commands._common import (
    MACHINE_KINEMATIC,
    add_force_arg,
    add_platform_arg,
    output_folder,
    print_json,
)
from stewart_drake.core.platform_file import platform_yaml
from stewart_drake.core.rotations import ANGLE_UNITS, CONVENTIONS, LENGTH_UNITS
from stewart_drake.montecarlo.measurements_api import simulate_measurements
from stewart_drake.system.jsonout import dumps_strict

HELP = "synthetic calibration measurements of a machine drawn around the nominal (truth written apart)"


def register(sub) -> None:
    p = sub.add_parser("simulate-measurements", help=HELP, description=HELP + ". See docs/calibration.md.")
    add_platform_arg(p, machine=MACHINE_KINEMATIC)
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
    sim = simulate_measurements(
        args.platform,
        args.poses,
        errors=args.errors,
        noise=args.noise,
        type=args.type,
        targets=args.targets,
        seed=args.seed,
        length_unit=args.length_unit,
        angle_unit=args.angle_unit,
        convention=args.convention,
    )
    info, noise = sim.to_dict(), sim.info["noise"]
    with out.writing() as tmp:
        (tmp / "measurements.csv").write_text(measurements_csv(sim.measurements), encoding="utf-8")
        (tmp / "truth").mkdir()
        header = f"The true machine drawn by stewart-drake simulate-measurements (seed {args.seed}): for checking only."
        (tmp / "truth" / "platform.yaml").write_text(platform_yaml(sim.truth, None, header), encoding="utf-8")
        (tmp / "truth" / "truth.json").write_text(dumps_strict(info) + "\n", encoding="utf-8")
    if args.json:
        print_json(info)
    else:
        print(
            f"platform {info['platform']}: {len(sim.measurements)} {args.type} measurements of a machine drawn with {' '.join(args.errors)} "
            f"(seed {args.seed}); noise σ: length {noise['length_m']:g} m, position {noise['position_m']:g} m, angle {noise['angle_rad']:g} rad"
        )
        print(f"wrote {args.out}/measurements.csv (m, rad) and, apart, {args.out}/truth/platform.yaml, truth.json")
    return 0
