"""``stewart-drake ik``: closed-form inverse kinematics for one pose or a CSV of poses."""

from __future__ import annotations

import numpy as np

from ..csvio import read_numeric_csv
from ..kinematics import check_stroke, leg_lengths
from ..rotations import length_scale, pose_to_si
from ._common import add_platform_arg, add_unit_args, platform_from_args, print_json


def register(sub) -> None:
    p = sub.add_parser("ik", help="leg lengths for a pose (closed-form inverse kinematics)")
    add_platform_arg(p)
    g = p.add_mutually_exclusive_group(required=True)
    g.add_argument("--pose", nargs=6, type=float, metavar=("PX", "PY", "PZ", "A", "B", "G"), help="one pose in the chosen units")
    g.add_argument("--poses", metavar="FILE.csv", help="CSV with columns px,py,pz,a,b,g (header optional), one pose per row")
    add_unit_args(p)
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")
    p.set_defaults(func=run)


def read_poses_csv(path: str) -> np.ndarray:
    """``(n, 6)`` poses from a CSV file; a non-numeric first row is a header. Errors name the line."""
    return read_numeric_csv(path, "poses", (6,), "px,py,pz,a,b,g")[0]


def run(args) -> int:
    platform = platform_from_args(args)
    raw = np.array([args.pose]) if args.pose is not None else read_poses_csv(args.poses)
    q = pose_to_si(raw, args.length_unit, args.angle_unit)
    L = leg_lengths(platform, q, args.convention)
    check = check_stroke(platform, L)
    k = length_scale(args.length_unit)
    results = []
    for i in range(len(q)):
        viol = [
            {
                "leg": v["leg"],
                "side": v["side"],
                "length": v["length_m"] / k,
                "limit": v["limit_m"] / k,
                "excess": v["excess_m"] / k,
            }
            for v in check.violations()
            if v["pose"] == [i]
        ]
        results.append(
            {
                "pose": raw[i].tolist(),
                "lengths": (L[i] / k).tolist(),
                "length_unit": args.length_unit,
                "within_stroke": bool(check.within[i]),
                "violations": viol,
            }
        )
    if args.json:
        print_json(results[0] if args.pose is not None else {"platform": platform.name, "results": results})
    else:
        print(f"platform {platform.name}, convention {args.convention}, lengths in {args.length_unit}")
        for r in results:
            flag = "ok" if r["within_stroke"] else "; ".join(
                f"leg {v['leg']} {v['excess']:.3f} {args.length_unit} {'below L_min' if v['side'] == 'min' else 'above L_max'}"
                for v in r["violations"]
            )
            print(" ".join(f"{x:10.3f}" for x in r["lengths"]), " ", flag)
    return 0 if all(r["within_stroke"] for r in results) else 1
