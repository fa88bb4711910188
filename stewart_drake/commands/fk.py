"""``stewart-drake fk``: forward kinematics — the pose(s) for six leg lengths."""

from __future__ import annotations

import sys

import numpy as np

from stewart_drake.commands._common import add_platform_arg, add_unit_args, platform_from_args, print_json
from stewart_drake.core.assembly_modes import modes_from_solutions
from stewart_drake.core.newton_fk import forward_kinematics
from stewart_drake.core.rotations import angle_scale, length_scale, pose_from_si, pose_to_si
from stewart_drake.core.sanity import check_finite, check_positive, check_work
from stewart_drake.errors import OPTION_MAX_ITER, OptionError, UsageError


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
    p.add_argument(
        "--lengths",
        nargs=6,
        type=float,
        required=True,
        metavar=("L1", "L2", "L3", "L4", "L5", "L6"),
        help="leg lengths in --length-unit",
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


def _entry(mode, args, k: float, **extra) -> dict:
    d = {
        "pose": pose_from_si(mode.pose, args.length_unit, args.angle_unit).tolist(),
        "residual": mode.residual / k,
        "det_sign": mode.det_sign,
        "condition": mode.condition,
        "sigma_min": mode.sigma_min,
        "above_base": mode.above_base,
        "within_stroke": mode.within_stroke,
        "certified": mode.certified,
        "distance_to_home": mode.distance_to_home,
    }
    d.update(extra)
    return d


# Newton converges quadratically from a good start (< 20 iterations); beyond this many it is not
# converging, and each iteration costs a Jacobian solve.
MAX_ITER = 1000


def _homotopy_all(platform, L, args, k: float) -> dict:
    """The ``--all`` answer of the complete homotopy solver: solutions nearest home first, each with
    its certificate; path counts per class; completeness and its guarantee."""
    # Deferred: the homotopy solver pulls in scipy (~0.1 s) and cli.py imports every command module at
    # start-up; only ``--all --method homotopy`` needs it.
    from stewart_drake.homotopy import solve

    r = solve(platform, L, seed=args.seed)
    sols = []
    for hm in r.modes:
        mode = modes_from_solutions(
            platform, hm.position[None], hm.rotation[None], L, np.array([hm.certified]), args.convention
        )[0]
        sols.append(
            _entry(
                mode,
                args,
                k,
                converged=True,
                method="homotopy",
                path=hm.path,
                certified_radius=hm.radius,
                uniqueness_radius=hm.uniqueness,
                position_bound=hm.position_bound / k,
                angle_bound=hm.angle_bound / angle_scale(args.angle_unit),
                singular=hm.singular,
            )
        )
    sols.sort(key=lambda d: d["distance_to_home"])
    return dict(
        solutions=sols,
        method="homotopy",
        modes_found=len(sols),
        max_solutions=r.max_solutions,
        complete=r.complete,
        guarantee=r.guarantee,
        architecture=r.kind,
        architecture_text=r.architecture,
        paths=r.counts(),
        path_classes=list(r.classes),
        failed_paths=r.failed_paths,
        retracked_paths=r.retracked,
        stage=r.stage,
        engine=r.engine,
        certificate="Krawczyk/Kantorovich existence and uniqueness in Study coordinates (e·e = 1): an exact solution "
        "lies within certified_radius of the returned point, no other within uniqueness_radius; position_bound / "
        "angle_bound are the implied pose bounds",
    )


def run(args) -> int:
    for i, v in enumerate(args.lengths, 1):
        if not v > 0:
            raise UsageError(f"--lengths: leg {i} length {v} {args.length_unit} must be a positive number")
    platform = platform_from_args(args)
    k = length_scale(args.length_unit)
    check_finite(args.lengths, "--lengths")
    check_positive(args.tol, "--tol", "metres")
    if args.max_iter < 1:
        raise OptionError(OPTION_MAX_ITER.format(value=args.max_iter))
    check_work(
        "--max-iter",
        str(args.max_iter),
        args.max_iter,
        "Newton iterations",
        max_count=MAX_ITER,
        hint="; Newton converges in a few tens of iterations or not at all (without --max-iter, the multi-start search runs)",
    )
    L = np.asarray(args.lengths, dtype=float) * k
    out = {
        "platform": platform.name,
        "lengths": list(args.lengths),
        "length_unit": args.length_unit,
        "angle_unit": args.angle_unit,
        "convention": args.convention,
    }
    single = None
    if not args.all:
        initial = None if args.initial is None else pose_to_si(args.initial, args.length_unit, args.angle_unit)
        r = forward_kinematics(
            platform, L, initial, args.convention, tol=args.tol, max_iter=args.max_iter, on_singular="warn"
        )
        if r.converged:
            mode = modes_from_solutions(
                platform, r.iterate[None, :3], r.rotation[None], L, np.array([False]), args.convention
            )[0]
            single = _entry(mode, args, k, converged=True, iterations=int(r.iterations), method="newton")
            out.update(solutions=[single], method="newton")
    if single is None and args.all and args.method == "homotopy":
        out.update(_homotopy_all(platform, L, args, k))
    elif single is None:
        # Deferred: the multi-start search is confirmed by Drake's MathematicalProgram; the Newton and
        # homotopy paths of this command run without pydrake.
        from stewart_drake.drake.program_fk import assembly_modes

        am = assembly_modes(platform, L, args.convention, seed=args.seed, tol=min(args.tol, 1e-13))
        sols = [_entry(m, args, k, converged=True, method="multi-start") for m in am.modes]
        out.update(
            solutions=sols if args.all else sols[:1],
            method="multi-start" if args.all else "newton failed from the initial pose; multi-start, nearest home",
            modes_found=len(am),
            max_solutions=am.max_solutions,
            complete=am.complete,
            starts=am.starts,
        )
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
            flags += ["SINGULAR (a multiple root: rank-deficient, not certified)"] if s.get("singular") else []
            print(
                f"{i:3d}",
                " ".join(f"{x:11.5f}" for x in s["pose"]),
                f"  residual {s['residual']:.2e}",
                ", ".join(flags),
            )
    if out.get("method") == "homotopy" and not out["complete"]:
        print(f"fk --all: {out['guarantee']}", file=sys.stderr)
        return 1
    if out.get("method") == "homotopy" and not out["solutions"]:
        print(
            f"fk --all: no real assembly mode: all {out['max_solutions']} paths end complex or at infinity, so the legs "
            f"cannot be assembled on platform {platform.name!r} (complete: {out['guarantee']})",
            file=sys.stderr,
        )
        return 1
    singular = [i for i, s in enumerate(out["solutions"], 1) if s.get("singular")]
    if singular:  # a pose on a singularity is found and shown; it is a physical limit
        print(
            f"fk --all: mode(s) {', '.join(map(str, singular))} lie on a singularity (several homotopy paths meet there; "
            "the platform loses stiffness in some direction at that pose)",
            file=sys.stderr,
        )
        return 1
    above = [s["above_base"] or platform.plate_below_base_allowed for s in out["solutions"]]
    physical = any(above) if args.all else all(above)  # --all lists mirror modes too; one valid mode suffices
    return 0 if all(s["within_stroke"] for s in out["solutions"]) and physical else 1
