"""``stewart-drake ik``: closed-form inverse kinematics for one pose or a CSV of poses."""

from __future__ import annotations

import json
import sys

import numpy as np

from stewart_drake.api.kinematics import solve_ik
from stewart_drake.commands._common import add_platform_arg, add_unit_args, platform_from_args, print_json
from stewart_drake.core.csvio import read_numeric_csv
from stewart_drake.core.rotations import length_scale, pose_to_si
from stewart_drake.core.unit_hint import other_unit_hint

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
        "--poses",
        metavar="FILE.csv",
        help="CSV with columns px,py,pz,a,b,g, one pose per row (header optional: its names, in any order, say "
        "which column is which)",
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
        raw, lines = np.array(args.pose), None
    else:
        cost = BYTES_PER_ROW + (BYTES_PER_JSON_ROW if args.json else 0)
        raw, lines = read_numeric_csv(args.poses, "poses", (6,), "px,py,pz,a,b,g", option="--poses", bytes_per_row=cost)
    what = "--pose" if lines is None else f"{args.poses}: pose"
    q = pose_to_si(raw, args.length_unit, args.angle_unit)
    r = solve_ik(platform, q, args.convention, what, lines)
    k = length_scale(args.length_unit)
    results = [r.to_dict()] if args.pose is not None else r.to_dict()["results"]
    for res, row in zip(results, raw.reshape(-1, 6).tolist()):  # the CLI's units: lengths as asked, pose as typed
        res.update(
            pose=row, lengths=[v / k for v in res["lengths"]], length_unit=args.length_unit, angle_unit=args.angle_unit
        )
        if "readings" in res:
            res["readings"] = [v / k for v in res["readings"]]
        for v in res["violations"]:
            v.update(length=v["length"] / k, limit=v["limit"] / k, excess=v["excess"] / k)
    if args.json:
        if args.pose is not None:
            print_json(results[0])
        else:  # compact, one result per line: the C encoder (indent= is pure Python, ~50 µs a row)
            sys.stdout.write(
                '{"platform": '
                + json.dumps(platform.name)
                + ', "results": [\n'
                + ",\n".join(json.dumps(res, allow_nan=False) for res in results)
                + "\n]}\n"
            )
    else:
        print_table(r, results, args.length_unit, args.angle_unit, args.convention)
    hint = "" if r.ok else other_unit_hint(platform, q, args.length_unit, args.angle_unit, args.convention)
    if hint:
        print(f"stewart-drake ik: outside the workspace{hint}", file=sys.stderr)
    return 0 if r.ok else 1


def print_table(r, results: list, unit: str, angle_unit: str, convention: str) -> None:
    """The lengths, one row per pose, with each failing pose's reason; the header names the units read."""
    print(f"platform {r.platform}, convention {convention}, poses read in {unit} and {angle_unit}, lengths in {unit}")
    flags = np.full(len(results), "ok", dtype=object)
    for i, res in enumerate(results):
        if res["violations"] or i in r.notes:
            flags[i] = "; ".join(
                ([r.notes[i]] if i in r.notes else [])
                + [
                    f"leg {v['leg']} {v['excess']:.3f} {unit} {'below L_min' if v['side'] == 'min' else 'above L_max'}"
                    for v in res["violations"]
                ]
            )
    cells = np.empty((len(results), 7), dtype=object)
    cells[:, :6], cells[:, 6] = np.array([res["lengths"] for res in results]).reshape(-1, 6), flags
    # one formatting pass over all rows (a Python loop per row costs ~10 µs a row)
    sys.stdout.write((("%10.3f " * 6 + "  %s\n") * len(results)) % tuple(cells.ravel().tolist()))
