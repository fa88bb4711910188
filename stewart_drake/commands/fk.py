"""``stewart-drake fk``: forward kinematics — the pose(s) for six leg lengths."""

from __future__ import annotations

import sys

import numpy as np

from stewart_drake.api.kinematics import solve_fk
from stewart_drake.commands._common import add_platform_arg, add_unit_args, platform_from_args, print_json
from stewart_drake.core.rotations import angle_scale, length_scale, pose_from_si, pose_to_si
from stewart_drake.core.sanity import check_finite


def register(sub) -> None:
    p = sub.add_parser(
        "fk",
        help="pose for six leg lengths (forward kinematics); --all: every assembly mode",
        description="Forward kinematics. Without --all: Newton-Raphson from the home pose (or --initial); if it "
        "does not converge, the multi-start search is run and the mode nearest home is returned. With --all: "
        "every assembly mode, nearest home first: by default the complete parameter homotopy (every path classified, "
        "each real mode certified by a Krawczyk/Kantorovich test), or --method multi-start (Newton multi-start "
        "confirmed by a Drake MathematicalProgram).",
    )
    add_platform_arg(p)
    given = p.add_mutually_exclusive_group(required=True)
    given.add_argument(
        "--lengths",
        nargs=6,
        type=float,
        metavar=("L1", "L2", "L3", "L4", "L5", "L6"),
        help="leg lengths (joint to joint) in --length-unit",
    )
    given.add_argument(
        "--readings",
        nargs=6,
        type=float,
        metavar=("R1", "R2", "R3", "R4", "R5", "R6"),
        help="leg sensor readings in --length-unit: lengths = readings + the platform's legs.length_offset",
    )
    add_unit_args(p)
    p.add_argument("--all", action="store_true", help="every assembly mode, not just one")
    p.add_argument(
        "--initial",
        nargs=6,
        type=float,
        metavar=("PX", "PY", "PZ", "A", "B", "G"),
        help="initial pose for Newton (default: home), in the chosen units",
    )
    p.add_argument(
        "--tol", type=float, default=1e-13, help="Newton tolerance on the leg lengths, metres (default 1e-13)"
    )
    p.add_argument("--max-iter", type=int, default=30, help="Newton iteration limit (default 30)")
    p.add_argument(
        "--seed", type=int, default=0, help="random seed of the multi-start search / the homotopy's gamma (default 0)"
    )
    p.add_argument(
        "--method",
        choices=("homotopy", "multi-start"),
        default="homotopy",
        help="--all: complete homotopy (default) or the multi-start search",
    )
    p.add_argument("--json", action="store_true", help='print JSON: {"solutions": [...], ...}')
    p.set_defaults(func=run)


def cli_units(result, args, k: float) -> dict:
    """The result's dict in the command's units (``--length-unit``, ``--angle-unit``), lengths as typed."""
    out = result.to_dict()
    ka = angle_scale(args.angle_unit)
    out.update(lengths=[float(v) for v in args.lengths], length_unit=args.length_unit, angle_unit=args.angle_unit)
    if args.readings is not None:
        out["readings"] = list(args.readings)
    for s in out["solutions"]:
        s["pose"] = pose_from_si(np.array(s["pose"]), args.length_unit, args.angle_unit).tolist()
        s["residual"] /= k
        if "position_bound" in s:
            s.update(position_bound=s["position_bound"] / k, angle_bound=s["angle_bound"] / ka)
        if "uniqueness_radius_initial" in s:
            s["uniqueness_radius_initial"] /= k
    return out


def run(args) -> int:
    platform = platform_from_args(args)
    k = length_scale(args.length_unit)
    if args.readings is not None:  # the sensors' readings of a calibrated platform: joint-to-joint lengths first
        check_finite(args.readings, "--readings")
        lengths = platform.lengths_from_readings(np.asarray(args.readings, dtype=float) * k) / k
        args.lengths = [float(v) for v in lengths]
    initial = None if args.initial is None else pose_to_si(args.initial, args.length_unit, args.angle_unit)
    result = solve_fk(
        platform,
        np.asarray(args.lengths, dtype=float) * k,
        args.all,
        initial,
        args.convention,
        args.method,
        args.tol,
        args.max_iter,
        args.seed,
        what="--lengths" if args.readings is None else "--readings + legs.length_offset",
        unit=args.length_unit,
        given=args.lengths,
    )
    out = cli_units(result, args, k)
    if args.json:
        print_json(out)
    else:
        print(
            f"platform {platform.name}, convention {args.convention}, pose in {args.length_unit}/{args.angle_unit}, "
            f"method: {out['method']}"
        )
        if "paths" in out:
            counts = ", ".join(f"{v} {c}" for c, v in out["paths"].items() if v)
            engine = {"c": "c (the compiled tracker, track.c)", "numpy": "numpy (no C compiler)"}[out["engine"]]
            print(f"architecture {out['architecture_text']} ({counts}); tracking engine: {engine}")
            print(("complete: " if out["complete"] else "") + out["guarantee"])
        elif "modes_found" in out:
            print(
                f"{out['modes_found']} modes found (at most {out['max_solutions']} exist; complete: {out['complete']})"
            )
        for i, s in enumerate(out["solutions"], 1):
            flags = [
                "above base" if s["above_base"] else "BELOW base",
                "within stroke" if s["within_stroke"] else "OUTSIDE stroke",
                f"det {'+' if s['det_sign'] > 0 else '-'}",
                f"cond {s['condition']:.3g}",
            ] + (
                [f"certified (radius {s['certified_radius']:.1e})" if "certified_radius" in s else "certified"]
                if s["certified"]
                else []
            )
            if "branch_certified" in s:
                flags.append(
                    "on the initial pose's branch (certified)"
                    if s["branch_certified"]
                    else "branch from the initial pose NOT certified (another assembly mode may have been reached)"
                )
            flags += ["SINGULAR (a multiple root: rank-deficient, not certified)"] if s.get("singular") else []
            print(
                f"{i:3d}",
                " ".join(f"{x:11.5f}" for x in s["pose"]),
                f"  residual {s['residual']:.2e}",
                ", ".join(flags),
            )
    if out.get("method") == "homotopy" and not out["complete"]:
        print(f"fk --all: {out['guarantee']}", file=sys.stderr)
    elif out.get("method") == "homotopy" and not out["solutions"]:
        print(
            f"fk --all: no real assembly mode: all {out['max_solutions']} paths end complex or at infinity, so the legs "
            f"cannot be assembled on platform {platform.name!r} (complete: {out['guarantee']})",
            file=sys.stderr,
        )
    singular = [i for i, s in enumerate(out["solutions"], 1) if s.get("singular")]
    if singular:  # a pose on a singularity is found and shown; it is a physical limit (FKResult.ok is False)
        why = (
            "several homotopy paths meet there"
            if args.all
            else "a multiple root: the Jacobian's smallest singular value is what Newton's tolerance leaves at one"
        )
        print(
            f"fk{' --all' if args.all else ''}: mode(s) {', '.join(map(str, singular))} lie on a singularity ({why}; "
            "the platform loses stiffness in some direction at that pose)",
            file=sys.stderr,
        )
    return 0 if result.ok else 1
