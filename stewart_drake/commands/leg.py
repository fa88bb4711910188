"""``stewart-drake leg``: forward and inverse kinematics of the 3R planar leg (seed 003)."""

from __future__ import annotations

import numpy as np

from stewart_drake.api.leg import leg_ik, make_leg, solve_leg_fk
from stewart_drake.commands._common import print_json
from stewart_drake.core.rotations import angle_scale, length_scale
from stewart_drake.core.sdf_models import sdf_text, write_sdf
from stewart_drake.errors import OPTION_TARGET, LegError


def register(sub) -> None:
    p = sub.add_parser("leg", help="3R planar leg (seed 003): DH forward kinematics, geometric inverse kinematics")
    ops = p.add_subparsers(dest="op", required=True, metavar="fk|ik|sdf")
    fk = ops.add_parser("fk", help="foot position and orientation for joint angles q1 q2")
    fk.add_argument("q1", type=float, metavar="Q1", help="hip angle (angle unit)")
    fk.add_argument("q2", type=float, metavar="Q2", help="knee angle (angle unit)")
    ik = ops.add_parser("ik", help="joint angles (both elbow branches) for a foot position")
    ik.add_argument("px", type=float, metavar="PX", help="foot x (length unit)")
    ik.add_argument("py", type=float, metavar="PY", help="foot y (length unit)")
    ik.add_argument(
        "--gamma", type=float, help="also the foot orientation gamma: the seed's 3R method (corrected), returns q3"
    )
    ik.add_argument(
        "--branch", choices=["a", "b", "both"], default="both", help="a: knee angle >= 0, b: <= 0 (default both)"
    )
    sdf = ops.add_parser("sdf", help="print (or --write DIR) the leg's SDF generated from the DH table")
    sdf.add_argument("--write", metavar="DIR")
    for q in (fk, ik, sdf):
        q.add_argument("--l1", type=float, help="thigh length (length unit; default 80 mm)")
        q.add_argument("--l2", type=float, help="shank length (default 80 mm)")
        q.add_argument("--l3", type=float, help="foot length (default 30 mm)")
        q.add_argument("--length-unit", choices=["m", "mm"], default="mm", help="default mm")
    for q in (fk, ik):
        q.add_argument("--angle-unit", choices=["rad", "deg", "pi"], default="deg", help="default deg")
        q.add_argument("--json", action="store_true", help="JSON output")
    p.set_defaults(func=run)


def _leg(args):
    k = length_scale(args.length_unit)
    return {n: getattr(args, n) * k for n in ("l1", "l2", "l3") if getattr(args, n) is not None}


def run(args) -> int:
    dims = _leg(args)
    if args.op == "sdf":
        leg = make_leg(**dims)
        if args.write:
            print(write_sdf(leg, args.write, option="--write"))
        else:
            print(sdf_text(leg), end="")
        return 0
    k, ka = length_scale(args.length_unit), angle_scale(args.angle_unit)
    units = {"length": args.length_unit, "angle": args.angle_unit}
    if args.op == "fk":
        args.q = [args.q1, args.q2]
        res = solve_leg_fk(np.array(args.q) * ka, make_leg(**dims), args.q, args.angle_unit, ka)
        out = {
            "q": list(args.q),
            "foot": [res.foot[0] / k, res.foot[1] / k],
            "gamma": res.gamma / ka,
            "units": units,
            "T03": res.T03.tolist(),
            "within_limits": res.within_limits,
            "limit_violations": res.limit_violations,
        }
        if args.json:
            print_json(out)
        else:
            print(
                f"foot Px = {out['foot'][0]:.6g} {args.length_unit}, Py = {out['foot'][1]:.6g} {args.length_unit}, "
                f"gamma = {out['gamma']:.6g} {args.angle_unit}"
                + ("" if out["within_limits"] else "  (outside joint limits)")
            )
        return 0 if out["within_limits"] else 1
    args.target = [args.px, args.py]
    t = np.array(args.target) * k
    if not np.all(np.isfinite(t)):
        raise LegError(OPTION_TARGET.format(value=args.target))
    res = leg_ik(*t, gamma=None if args.gamma is None else args.gamma * ka, branch=args.branch, **dims)
    sols = {b: {"q": (v["q"] / ka).tolist(), "within_limits": v["within_limits"]} for b, v in res.solutions.items()}
    out = {"target": list(args.target), "gamma": args.gamma, "units": units, "solutions": sols}
    if args.json:
        print_json(out)
    else:
        for b, s in sols.items():
            names = ["q1", "q2", "q3"][: len(s["q"])]
            print(
                f"branch {b}: "
                + ", ".join(f"{n} = {v:.6g} {args.angle_unit}" for n, v in zip(names, s["q"]))
                + ("" if s["within_limits"] else "  (outside joint limits)")
            )
    return 0 if any(s["within_limits"] for s in sols.values()) else 1
