"""``stewart-drake ik``: closed-form inverse kinematics for one pose or a CSV of poses."""

from __future__ import annotations

import json
import sys

import numpy as np

from stewart_drake.commands._common import add_platform_arg, add_unit_args, platform_from_args, print_json
from stewart_drake.core.csvio import read_numeric_csv
from stewart_drake.core.kinematics import check_stroke, leg_lengths
from stewart_drake.core.rotations import length_scale, pose_to_si
from stewart_drake.core.sanity import below_base_message, check_poses, plate_anchor_heights

# Bytes per CSV row while reading (Python lists of floats) and per result printed as JSON (estimates).
BYTES_PER_ROW = 600
BYTES_PER_JSON_ROW = 1500


def register(sub) -> None:
    p = sub.add_parser("ik", help="leg lengths for a pose (closed-form inverse kinematics)")
    add_platform_arg(p)
    g = p.add_mutually_exclusive_group(required=True)
    g.add_argument(
        "--pose", nargs=6, type=float, metavar=("PX", "PY", "PZ", "A", "B", "G"), help="one pose in the chosen units"
    )
    g.add_argument(
        "--poses", metavar="FILE.csv", help="CSV with columns px,py,pz,a,b,g (header optional), one pose per row"
    )
    add_unit_args(p)
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")
    p.set_defaults(func=run)


def read_poses_csv(path: str) -> np.ndarray:
    """``(n, 6)`` poses from a CSV file; a non-numeric first row is a header. Errors name the line."""
    return read_numeric_csv(path, "poses", (6,), "px,py,pz,a,b,g")[0]


def run(args) -> int:
    platform = platform_from_args(args)
    if args.pose is not None:
        raw, lines = np.array([args.pose]), None
    else:
        cost = BYTES_PER_ROW + (BYTES_PER_JSON_ROW if args.json else 0)
        raw, lines = read_numeric_csv(args.poses, "poses", (6,), "px,py,pz,a,b,g", option="--poses", bytes_per_row=cost)
    q = pose_to_si(raw, args.length_unit, args.angle_unit)
    check_poses(
        platform, q, args.convention, what="--pose" if lines is None else f"{args.poses}: pose", lines=lines, base=False
    )
    L = leg_lengths(platform, q, args.convention)
    check = check_stroke(platform, L)
    within = check.within
    z = plate_anchor_heights(platform, q, args.convention)  # (n, 6) m
    above = np.all(z > 0, axis=1) | platform.plate_below_base_allowed
    ok = within & above
    k = length_scale(args.length_unit)
    Lu = L / k
    # per-pose details only for the poses that fail (linear in the number of poses)
    bad = np.flatnonzero(~ok)
    viol = {int(i): [] for i in bad}
    for side, arr, lim in (("min", check.below, platform.L_min), ("max", check.above, platform.L_max)):
        for i, leg in np.argwhere(arr[bad] > 0):
            n = int(bad[i])
            viol[n].append(
                {
                    "leg": int(leg) + 1,
                    "side": side,
                    "length": float(Lu[n, leg]),
                    "limit": lim / k,
                    "excess": float(arr[n, leg]) / k,
                }
            )
    for v in viol.values():
        v.sort(key=lambda d: d["leg"])
    notes = {int(i): below_base_message("pose", z[i]) for i in np.flatnonzero(~above)}
    if args.json:
        rows = raw.tolist()
        lengths = Lu.tolist()
        results = [
            {
                "pose": rows[i],
                "lengths": lengths[i],
                "length_unit": args.length_unit,
                "within_stroke": bool(within[i]),
                "above_base": bool(above[i]),
                "violations": viol.get(i, []),
            }
            for i in range(len(q))
        ]
        if args.pose is not None:
            print_json(results[0])
        else:  # compact, one result per line: the C encoder (indent= is pure Python, ~50 µs a row)
            sys.stdout.write(
                '{"platform": '
                + json.dumps(platform.name)
                + ', "results": [\n'
                + ",\n".join(json.dumps(r, allow_nan=False) for r in results)
                + "\n]}\n"
            )
    else:
        print(f"platform {platform.name}, convention {args.convention}, lengths in {args.length_unit}")
        flags = np.full(len(q), "ok", dtype=object)
        for i, vs in viol.items():
            flags[i] = "; ".join(
                ([notes[i]] if i in notes else [])
                + [
                    f"leg {v['leg']} {v['excess']:.3f} {args.length_unit} {'below L_min' if v['side'] == 'min' else 'above L_max'}"
                    for v in vs
                ]
            )
        cells = np.empty((len(q), 7), dtype=object)
        cells[:, :6], cells[:, 6] = Lu, flags
        # one formatting pass over all rows (a Python loop per row costs ~10 µs a row)
        sys.stdout.write((("%10.3f " * 6 + "  %s\n") * len(q)) % tuple(cells.ravel().tolist()))
    return 0 if bool(np.all(ok)) else 1
