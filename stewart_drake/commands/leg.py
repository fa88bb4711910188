"""``stewart-drake leg``: forward and inverse kinematics of the 3R planar leg (seed 003)."""

from __future__ import annotations

import numpy as np

from stewart_drake.commands._common import print_json
from stewart_drake.core.leg3r import (
    Leg3R,
    foot,
    forward_kinematics,
    inverse_kinematics,
    inverse_kinematics_3r,
    limit_violations,
    within_limits,
)
from stewart_drake.core.rotations import angle_scale, length_scale
from stewart_drake.core.sdf_models import sdf_text, write_sdf
from stewart_drake.errors import OPTION_JOINT_ANGLES, OPTION_JOINT_OVERFLOW, OPTION_TARGET, LegError


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
    dims = {n: getattr(args, n) * k for n in ("l1", "l2", "l3") if getattr(args, n) is not None}
    return Leg3R(**dims)


def run(args) -> int:
    leg = _leg(args)
    if args.op == "sdf":
        if args.write:
            print(write_sdf(leg, args.write, option="--write"))
        else:
            print(sdf_text(leg), end="")
        return 0
    k, ka = length_scale(args.length_unit), angle_scale(args.angle_unit)
    units = {"length": args.length_unit, "angle": args.angle_unit}
    if args.op == "fk":
        args.q = [args.q1, args.q2]
        q = np.array(args.q) * ka
        if not np.all(np.isfinite(q)):
            raise LegError(OPTION_JOINT_ANGLES.format(value=args.q))
        f = foot(leg, q)
        if not np.isfinite(f[2] / ka):  # angles near the float range: their sum in the user's unit is no number
            raise LegError(OPTION_JOINT_OVERFLOW.format(value=args.q, unit=args.angle_unit))
        out = {
            "q": list(args.q),
            "foot": [f[0] / k, f[1] / k],
            "gamma": f[2] / ka,
            "units": units,
            "T03": forward_kinematics(leg, q).tolist(),
            "within_limits": bool(within_limits(leg, q)),
            "limit_violations": limit_violations(leg, q),
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
    sols = {}
    for b in ("a", "b") if args.branch == "both" else (args.branch,):
        if args.gamma is None:
            q = inverse_kinematics(leg, t, b)
        else:
            q = inverse_kinematics_3r(leg, np.r_[t, args.gamma * ka], b)
        sols[b] = {"q": (q / ka).tolist(), "within_limits": bool(within_limits(leg, q[:2]))}
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
