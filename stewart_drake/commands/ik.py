"""``stewart-drake ik``: closed-form inverse kinematics for one pose or a CSV of poses."""

from __future__ import annotations

import json
import sys

import numpy as np

from stewart_drake.api.kinematics import solve_ik
from stewart_drake.commands._common import add_platform_arg, add_unit_args, platform_from_args, print_json
from stewart_drake.core.rotations import length_scale, pose_to_si

# Bytes a CSV row costs until the output is written: its text and parsed values, its pose in SI and its
# output line (table ~80 characters, JSON ~400); the results themselves are computed CHUNK_ROWS at a time.
BYTES_PER_ROW = 400
BYTES_PER_JSON_ROW = 200
CHUNK_ROWS = 1 << 13


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
    from stewart_drake.core.csvio import read_numeric_csv  # deferred: see ``run``

    return read_numeric_csv(path, "poses", (6,), "px,py,pz,a,b,g")[0]


def run(args) -> int:
    platform = platform_from_args(args)
    if args.pose is not None:
        raw, lines = np.array(args.pose), None
    else:
        # deferred: the CSV reader (and the csv module) is needed only with --poses; one pose starts without it
        from stewart_drake.core.csvio import read_numeric_csv

        cost = BYTES_PER_ROW + (BYTES_PER_JSON_ROW if args.json else 0)
        raw, lines = read_numeric_csv(args.poses, "poses", (6,), "px,py,pz,a,b,g", option="--poses", bytes_per_row=cost)
    what = "--pose" if lines is None else f"{args.poses}: pose"
    q = pose_to_si(raw, args.length_unit, args.angle_unit)
    k = length_scale(args.length_unit)
    if args.pose is not None:
        r = solve_ik(platform, q, args.convention, what, lines)
        (res,) = _in_cli_units([r.to_dict()], raw, k, args)
        if args.json:
            print_json(res)
        else:
            print(_table_header(r.platform, args))
            sys.stdout.write(table_text(r, [res], args.length_unit))
        ok = r.ok
    else:
        # the results are computed and formatted a chunk at a time (a result's dict is ~2 kB), and written
        # once all are: an error in a later row leaves no partial output
        parts, ok = [], True
        for s in range(0, len(q), CHUNK_ROWS):
            e = min(s + CHUNK_ROWS, len(q))
            r = solve_ik(platform, q[s:e], args.convention, what, lines[s:e])
            ok = ok and r.ok
            results = _in_cli_units(r.to_dict()["results"], raw[s:e], k, args)
            if args.json:  # compact, one result per line: the C encoder (indent= is pure Python, ~50 µs a row)
                parts.append(",\n".join(json.dumps(res, allow_nan=False) for res in results))
            else:
                parts.append(table_text(r, results, args.length_unit))
            del r, results
        if args.json:
            sys.stdout.write('{"platform": ' + json.dumps(platform.name) + ', "results": [\n')
            for i, part in enumerate(parts):  # written part by part: a joined copy would double the output's memory
                sys.stdout.write((",\n" if i else "") + part)
            sys.stdout.write("\n]}\n")
        else:
            sys.stdout.write(_table_header(platform.name, args) + "\n")
            for part in parts:
                sys.stdout.write(part)
    if ok:
        hint = ""
    else:
        from stewart_drake.core.unit_hint import other_unit_hint  # deferred: only a failed pose needs it

        hint = other_unit_hint(platform, q, args.length_unit, args.angle_unit, args.convention)
    if hint:
        print(f"stewart-drake ik: outside the workspace{hint}", file=sys.stderr)
    return 0 if ok else 1


def _in_cli_units(results: list, raw, k: float, args) -> list:
    """``results`` (the API's dicts, SI) in the command's units: lengths as asked, each pose as typed."""
    for res, row in zip(results, raw.reshape(-1, 6).tolist()):
        res.update(
            pose=row, lengths=[v / k for v in res["lengths"]], length_unit=args.length_unit, angle_unit=args.angle_unit
        )
        if "readings" in res:
            res["readings"] = [v / k for v in res["readings"]]
        for v in res["violations"]:
            v.update(length=v["length"] / k, limit=v["limit"] / k, excess=v["excess"] / k)
    return results


def _table_header(platform_name: str, args) -> str:
    return (
        f"platform {platform_name}, convention {args.convention}, poses read in {args.length_unit} and "
        f"{args.angle_unit}, lengths in {args.length_unit}"
    )


def table_text(r, results: list, unit: str) -> str:
    """The lengths, one row per pose, with each failing pose's reason (``r.notes`` indexed as ``results``)."""
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
    return (("%10.3f " * 6 + "  %s\n") * len(results)) % tuple(cells.ravel().tolist())
