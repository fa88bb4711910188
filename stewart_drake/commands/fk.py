"""``stewart-drake fk``: forward kinematics — the pose(s) for six leg lengths."""

from __future__ import annotations

import numpy as np

from ..errors import UsageError
from ..rotations import length_scale, pose_from_si, pose_to_si
from ..sanity import check_finite, check_positive, check_work
from ._common import add_platform_arg, add_unit_args, platform_from_args, print_json


def register(sub) -> None:
    p = sub.add_parser(
        "fk",
        help="pose for six leg lengths (forward kinematics); --all: every assembly mode",
        description="Forward kinematics. Without --all: Newton-Raphson from the home pose (or --initial); if it "
        "does not converge, the multi-start search is run and the mode nearest home is returned. With --all: "
        "every assembly mode found (Newton multi-start, confirmed by a Drake MathematicalProgram), nearest home first.",
    )
    add_platform_arg(p)
    p.add_argument("--lengths", nargs=6, type=float, required=True, metavar=("L1", "L2", "L3", "L4", "L5", "L6"), help="leg lengths in --length-unit")
    add_unit_args(p)
    p.add_argument("--all", action="store_true", help="every assembly mode, not just one")
    p.add_argument("--initial", nargs=6, type=float, metavar=("PX", "PY", "PZ", "A", "B", "G"), help="initial pose for Newton (default: home), in the chosen units")
    p.add_argument("--tol", type=float, default=1e-13, help="Newton tolerance on the leg lengths, metres (default 1e-13)")
    p.add_argument("--max-iter", type=int, default=30, help="Newton iteration limit (default 30)")
    p.add_argument("--seed", type=int, default=0, help="random seed of the multi-start search (default 0)")
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


def run(args) -> int:
    from ..fk import forward_kinematics

    for i, v in enumerate(args.lengths, 1):
        if not v > 0:
            raise UsageError(f"--lengths: leg {i} length {v} {args.length_unit} must be a positive number")
    platform = platform_from_args(args)
    k = length_scale(args.length_unit)
    check_finite(args.lengths, "--lengths")
    check_positive(args.tol, "--tol", "metres")
    if args.max_iter < 1:
        raise ValueError(f"--max-iter must be >= 1, got {args.max_iter}")
    check_work("--max-iter", str(args.max_iter), args.max_iter, "Newton iterations", max_count=MAX_ITER,
               hint="; Newton converges in a few tens of iterations or not at all (without --max-iter, the multi-start search runs)")
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
        r = forward_kinematics(platform, L, initial, args.convention, tol=args.tol, max_iter=args.max_iter, on_singular="warn")
        if r.converged:
            from ..forward import modes_from_solutions

            mode = modes_from_solutions(platform, r.iterate[None, :3], r.rotation[None], L, np.array([False]), args.convention)[0]
            single = _entry(mode, args, k, converged=True, iterations=int(r.iterations), method="newton")
            out.update(solutions=[single], method="newton")
    if single is None:
        from ..forward import assembly_modes

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
        if "modes_found" in out:
            print(f"{out['modes_found']} modes found (at most {out['max_solutions']} exist; complete: {out['complete']})")
        for i, s in enumerate(out["solutions"], 1):
            flags = [
                "above base" if s["above_base"] else "BELOW base",
                "within stroke" if s["within_stroke"] else "OUTSIDE stroke",
                f"det {'+' if s['det_sign'] > 0 else '-'}",
                f"cond {s['condition']:.3g}",
            ] + (["certified"] if s["certified"] else [])
            print(f"{i:3d}", " ".join(f"{x:11.5f}" for x in s["pose"]), f"  residual {s['residual']:.2e}", ", ".join(flags))
    above = [s["above_base"] or platform.plate_below_base_allowed for s in out["solutions"]]
    physical = any(above) if args.all else all(above)  # --all lists mirror modes too; one valid mode suffices
    return 0 if all(s["within_stroke"] for s in out["solutions"]) and physical else 1
