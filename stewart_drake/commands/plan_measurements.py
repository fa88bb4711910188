"""``stewart-drake plan-measurements``: calibration poses that maximise the identification's D-index, against
random poses of the same count; written as a CSV and as a motion program (.stw) that visits them."""

from __future__ import annotations

from stewart_drake.api.calibration import plan_measurements, poses_csv
from stewart_drake.calibration.measurements import TYPES
from stewart_drake.commands._common import (
    MACHINE_KINEMATIC,
    add_force_arg,
    add_platform_arg,
    output_folder,
    print_json,
)
from stewart_drake.core.rotations import ANGLE_UNITS, CONVENTIONS, LENGTH_UNITS
from stewart_drake.system.jsonout import dumps_strict

HELP = "plan calibration poses (D-optimal) inside a workspace box; CSV and a .stw program that visits them"


def register(sub) -> None:
    p = sub.add_parser("plan-measurements", help=HELP, description=HELP + ". See docs/calibration.md.")
    add_platform_arg(p, machine=MACHINE_KINEMATIC)
    p.add_argument("--poses", type=int, required=True, metavar="N", help="number of poses to plan")
    p.add_argument("--type", choices=TYPES, default="pose", help="the measurement to plan for (default pose)")
    p.add_argument(
        "--workspace",
        nargs=4,
        type=float,
        metavar=("X", "Y", "Z", "ROT"),
        help="box about home: ±X ±Y ±Z (--length-unit) and ±ROT per angle (--angle-unit); default ±30 %% of the "
        "stroke range in x, y, ±20 %% in z, ±20°",
    )
    p.add_argument("--length-unit", choices=list(LENGTH_UNITS), default="mm", help="--workspace lengths (default mm)")
    p.add_argument("--angle-unit", choices=list(ANGLE_UNITS), default="deg", help="--workspace angle (default deg)")
    p.add_argument("--convention", choices=list(CONVENTIONS), default="utn", help="Euler convention of the poses")
    p.add_argument("--noise", nargs="+", default=[], metavar="KEY=VALUE", help="σ as for calibrate (weights the rows)")
    p.add_argument("--targets", type=int, default=3, help="--type points: targets on the plate (default 3)")
    p.add_argument("--gains", action="store_true", help="plan for identifying the sensor gains too")
    p.add_argument("--candidates", type=int, default=1000, help="candidate poses drawn (default 1000)")
    p.add_argument("--seed", type=int, default=0, help="seed of the candidates and of the random baseline")
    p.add_argument("--out", required=True, metavar="DIR", help="output folder (created; only its own files replaced)")
    add_force_arg(p)
    p.add_argument("--json", action="store_true", help="print plan.json to stdout")
    p.set_defaults(func=run)


def run(args) -> int:
    out = output_folder(args)
    plan = plan_measurements(
        args.platform,
        args.poses,
        type=args.type,
        workspace=args.workspace,
        noise=args.noise,
        targets=args.targets,
        gains=args.gains,
        candidates=args.candidates,
        seed=args.seed,
        length_unit=args.length_unit,
        angle_unit=args.angle_unit,
        convention=args.convention,
    )
    d = plan.to_dict()
    with out.writing() as tmp:
        (tmp / "poses.csv").write_text(poses_csv(plan.poses), encoding="utf-8")
        (tmp / "random.csv").write_text(poses_csv(plan.random), encoding="utf-8")
        (tmp / "plan.stw").write_text(plan.program(), encoding="utf-8")
        (tmp / "plan.json").write_text(dumps_strict(d) + "\n", encoding="utf-8")
    if args.json:
        print_json(d)
        return 0
    print(
        f"platform {d['platform']}: {args.poses} {args.type} poses from {d['candidates']} candidates; criterion {d['criterion']}"
    )
    for side in ("planned", "random"):
        s = d[side]
        print(
            f"{side:8s} D-index {s['d_index']:.4g}  noise amplification {s['noise_amplification_index']:.4g}  "
            f"condition {s['condition_number']:.4g}  identifiable {s['identifiable']}"
        )
    if d["frame_freedoms"]:
        print("this measurement cannot fix: " + ", ".join(d["frame_freedoms"]))
    if d["fixed_by_convention"]:
        print("held at nominal (convention): " + ", ".join(d["fixed_by_convention"]))
    print(f"wrote {args.out}/poses.csv (m, rad), random.csv, plan.stw, plan.json")
    return 0
