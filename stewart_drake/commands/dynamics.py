"""``stewart-drake dynamics``: leg forces along a trajectory (inverse dynamics, seed 004 part 2)."""

from __future__ import annotations

import csv
import sys

from stewart_drake.api.dynamics import inverse_dynamics
from stewart_drake.commands._common import (
    add_platform_arg,
    flag_error,
    platform_from_args,
    print_json,
    reject_unused,
)
from stewart_drake.errors import StewartError

CSV_HELP = (
    "CSV, one sample per row: either 7 columns t,px,py,pz,a,b,g (velocities and accelerations from a cubic "
    "spline through the samples) or 19 columns t, q(6), qd(6), qdd(6) (px_dot..., px_ddot...); header optional: "
    "its names, in any order, say which column is which"
)


def register(sub) -> None:
    p = sub.add_parser("dynamics", help="leg forces along a trajectory (inverse dynamics, with or without Coriolis)")
    add_platform_arg(p, default="utn-dynamic")
    p.add_argument(
        "--trajectory",
        default="seed",
        metavar="seed|FILE.csv",
        help="'seed' (px = -0.1 m, py = 0.1 sin(2t) m, pz = 0.7 m) or a CSV file: " + CSV_HELP,
    )
    p.add_argument("--t-end", type=float, default=4.0, help="seed trajectory: last time in s (default 4)")
    p.add_argument("--dt", type=float, default=0.1, help="seed trajectory: time step in s (default 0.1, as the seed)")
    p.add_argument(
        "--coriolis", choices=["on", "off"], default="on", help="include C(q, q̇) q̇ (default on; off = the seed's model)"
    )
    p.add_argument(
        "--legs",
        choices=["on", "off"],
        default="off",
        help="include the legs' masses (cylinder + piston, from the platform) (default off, as the seed)",
    )
    p.add_argument("--gravity", type=float, default=9.81, help="m/s² (default 9.81)")
    p.add_argument(
        "--convention", choices=["utn", "zyx"], default="utn", help="Euler convention of the CSV's angles (default utn)"
    )
    p.add_argument("--length-unit", choices=["m", "mm"], default="m", help="CSV positions (default m)")
    p.add_argument("--angle-unit", choices=["rad", "deg", "pi"], default="rad", help="CSV angles (default rad)")
    p.add_argument(
        "--smooth",
        type=float,
        default=None,
        metavar="TOL",
        help="differentiate a CSV through a smoothing spline within TOL (RMS, in the file's units) of its samples: "
        "for files rounded so coarsely that their second differences are noise (refused without it)",
    )
    p.add_argument(
        "--allow-out-of-stroke",
        action="store_true",
        help="compute forces even where a leg leaves the stroke (a warning, also in the JSON 'warnings'); default: exit 1",
    )
    out = p.add_mutually_exclusive_group()
    out.add_argument("--json", action="store_true", help="print JSON")
    out.add_argument("--csv", action="store_true", help="print CSV: t,F1..F6 (N)")
    p.set_defaults(func=run)


# the options the API's messages name by keyword (``allow_out_of_stroke=True``)
DYNAMICS_FLAGS = {"allow_out_of_stroke": ("--allow-out-of-stroke", None)}


def run(args) -> int:
    seed = args.trajectory == "seed"
    reject_unused(args, "--trajectory seed", seed, t_end=4.0, dt=0.1)
    reject_unused(
        args, "--trajectory FILE.csv", not seed, length_unit="m", angle_unit="rad", convention="utn", smooth=None
    )
    try:  # the API names its keywords (allow_out_of_stroke=True); the user gave flags
        r = inverse_dynamics(
            platform_from_args(args),
            args.trajectory,
            legs=args.legs == "on",
            coriolis=args.coriolis == "on",
            gravity=args.gravity,
            t_end=args.t_end,
            dt=args.dt,
            convention=args.convention,
            length_unit=args.length_unit,
            angle_unit=args.angle_unit,
            allow_out_of_stroke=args.allow_out_of_stroke,
            smooth=args.smooth,
            on_warning=lambda w: print(f"stewart-drake dynamics: warning: {w}", file=sys.stderr),
        )
    except StewartError as e:
        raise flag_error(e, DYNAMICS_FLAGS) from None
    if args.json:
        print_json(r.to_dict())
    elif args.csv:
        w = csv.writer(sys.stdout, lineterminator="\n")
        w.writerow(["t"] + [f"F{i}" for i in range(1, 7)])
        for tk, Fk in zip(r.t, r.forces):
            w.writerow([f"{tk:.9g}"] + [f"{x:.12g}" for x in Fk])
    else:
        print(
            f"platform {r.platform}, trajectory {args.trajectory}"
            + ("" if seed else f" (read in {args.length_unit} and {args.angle_unit})")
            + f", Coriolis {args.coriolis}, legs {args.legs}; forces in N"
        )
        print(f"{'t (s)':>8} " + " ".join(f"{'F' + str(i):>10}" for i in range(1, 7)))
        for tk, Fk in zip(r.t, r.forces):
            print(f"{tk:8.3f} " + " ".join(f"{x:10.4f}" for x in Fk))
    return 0
