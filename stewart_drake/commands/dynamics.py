"""``stewart-drake dynamics``: leg forces along a trajectory (inverse dynamics, seed 004 part 2)."""

from __future__ import annotations

import csv
import math
import sys

import numpy as np
from scipy.interpolate import CubicSpline

from stewart_drake.commands._common import add_platform_arg, platform_from_args, print_json, reject_unused
from stewart_drake.core.csvio import read_numeric_csv
from stewart_drake.core.dynamics import leg_forces, leg_forces_with_legs, seed_trajectory
from stewart_drake.core.rotations import angle_scale, length_scale
from stewart_drake.core.sanity import (
    check_finite,
    check_gravity,
    check_trajectory,
    check_work,
    fmt_value,
    require_plate,
)
from stewart_drake.errors import CsvError, OptionError, UsageError

CSV_HELP = (
    "CSV, header optional, one sample per row: either 7 columns t,px,py,pz,a,b,g (velocities and "
    "accelerations from a cubic spline through the samples) or 19 columns t, q(6), qd(6), qdd(6)"
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
        "--allow-out-of-stroke",
        action="store_true",
        help="compute forces even where a leg leaves the stroke (a warning, also in the JSON 'warnings'); default: exit 1",
    )
    out = p.add_mutually_exclusive_group()
    out.add_argument("--json", action="store_true", help="print JSON")
    out.add_argument("--csv", action="store_true", help="print CSV: t,F1..F6 (N)")
    p.set_defaults(func=run)


def read_trajectory_csv(path: str, length_unit: str = "m", angle_unit: str = "rad"):
    """``(t, q, qd, qdd)`` in SI units from a trajectory CSV (see ``CSV_HELP``). Errors name the line."""
    a, _ = read_numeric_csv(
        path, "trajectory", (7, 19), "see --help", option="--trajectory", bytes_per_row=BYTES_PER_SAMPLE + 600
    )
    width = a.shape[1]
    if len(a) < (2 if width == 19 else 4):
        raise CsvError(CsvError.TOO_FEW.format(path=path, need=2 if width == 19 else 4, got=len(a)))
    t = a[:, 0]
    if np.any(np.diff(t) <= 0):
        k = int(np.argmax(np.diff(t) <= 0))
        raise CsvError(CsvError.TIMES.format(path=path, k=k + 1, t=t[k + 1], t_prev=t[k]))
    scale = np.r_[np.full(3, length_scale(length_unit)), np.full(3, angle_scale(angle_unit))]
    if width == 19:
        return t, a[:, 1:7] * scale, a[:, 7:13] * scale, a[:, 13:19] * scale
    spline = CubicSpline(t, a[:, 1:7] * scale, axis=0)
    return t, spline(t), spline(t, 1), spline(t, 2)


# Memory per trajectory sample while computing forces ((6, 6) Jacobians, mass matrices and their
# temporaries) and the most samples one run takes (~10 s of vectorised inverse dynamics).
BYTES_PER_SAMPLE = 4000
MAX_SAMPLES = 10_000_000


def seed_times(t_end: float, dt: float) -> np.ndarray:
    """``(n,)`` the seed trajectory's sample times 0, dt, ... t_end (s), after checking that both are
    finite and the sample count fits the memory and sample budget (before allocating)."""
    check_finite(t_end, "--t-end (s)")
    check_finite(dt, "--dt (s)")
    if not (dt > 0 and t_end >= 0):
        raise OptionError(OptionError.DT.format(dt=fmt_value(dt), t_end=fmt_value(t_end)))
    n = math.floor(t_end / dt + 0.5) + 1
    check_work(
        "--t-end/--dt",
        f"{fmt_value(t_end)}/{fmt_value(dt)} s",
        n,
        "samples",
        BYTES_PER_SAMPLE,
        MAX_SAMPLES,
        hint="; use a larger --dt or a shorter --t-end",
    )
    return np.arange(0.0, t_end + dt / 2, dt)


def run(args) -> int:
    seed = args.trajectory == "seed"
    reject_unused(args, "--trajectory seed", seed, t_end=4.0, dt=0.1)
    reject_unused(args, "--trajectory FILE.csv", not seed, length_unit="m", angle_unit="rad", convention="utn")
    platform = platform_from_args(args)
    require_plate(platform, "dynamics")
    gravity = check_gravity(args.gravity)
    if args.trajectory == "seed":
        t = seed_times(args.t_end, args.dt)
        q, qd, qdd = seed_trajectory(t)
        convention = "utn"
    else:
        t, q, qd, qdd = read_trajectory_csv(args.trajectory, args.length_unit, args.angle_unit)
        convention = args.convention
    what = "the seed trajectory" if args.trajectory == "seed" else f"trajectory {args.trajectory}"
    warnings = check_trajectory(platform, t, q, convention, what, args.allow_out_of_stroke)
    for w in warnings:
        print(f"stewart-drake dynamics: warning: {w}", file=sys.stderr)
    if args.legs == "on":
        if args.coriolis == "off":
            raise UsageError(UsageError.LEGS_CORIOLIS)
        F = leg_forces_with_legs(platform, q, qd, qdd, convention, gravity=gravity)
    else:
        F = leg_forces(platform, q, qd, qdd, convention, coriolis=args.coriolis == "on", gravity=gravity)
    if args.json:
        print_json(
            {
                "platform": platform.name,
                "trajectory": args.trajectory,
                "coriolis": args.coriolis == "on",
                "legs": args.legs == "on",
                "gravity": gravity,
                "unit": "N",
                "t": t,
                "forces": F,
                "max_abs_force": np.abs(F).max(axis=0),
                "warnings": warnings,
            }
        )
    elif args.csv:
        w = csv.writer(sys.stdout, lineterminator="\n")
        w.writerow(["t"] + [f"F{i}" for i in range(1, 7)])
        for tk, Fk in zip(t, F):
            w.writerow([f"{tk:.9g}"] + [f"{x:.12g}" for x in Fk])
    else:
        print(
            f"platform {platform.name}, trajectory {args.trajectory}, Coriolis {args.coriolis}, legs {args.legs}; forces in N"
        )
        print(f"{'t (s)':>8} " + " ".join(f"{'F' + str(i):>10}" for i in range(1, 7)))
        for tk, Fk in zip(t, F):
            print(f"{tk:8.3f} " + " ".join(f"{x:10.4f}" for x in Fk))
    return 0
