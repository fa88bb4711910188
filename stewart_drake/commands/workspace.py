"""``stewart-drake workspace``: constant-orientation workspace, rotation limits and mobility of a platform."""

from __future__ import annotations

import math
import sys

import numpy as np

import stewart_drake.workspace as ws
from stewart_drake.commands._common import (
    add_force_arg,
    add_platform_arg,
    dumps_strict,
    output_folder,
    platform_from_args,
    print_json,
    reject_unused,
)
from stewart_drake.core.leg_bodies import leg_dimensions
from stewart_drake.core.output_folder import atomic_folder
from stewart_drake.core.processes import check_workers
from stewart_drake.core.rotations import ANGLE_UNITS, CONVENTIONS, to_radians
from stewart_drake.core.sanity import check_centre, check_finite
from stewart_drake.errors import OptionError
from stewart_drake.workspace import Limits, view_figures

LIMIT_CHOICES = ("stroke", "joints", "collision", "dexterity")


def register(sub) -> None:
    p = sub.add_parser("workspace", help="reachable positions (extents, volume, views) and rotation limits")
    add_platform_arg(p, default="gonzalez-dutra-2009")
    p.add_argument(
        "--orientation",
        nargs=3,
        type=float,
        default=[0.0, 0.0, 0.0],
        metavar=("A", "B", "G"),
        help="plate orientation about X, Y, Z for the workspace (default 0 0 0, in --angle-unit)",
    )
    p.add_argument(
        "--angle-unit",
        choices=list(ANGLE_UNITS),
        default="deg",
        help="unit of --orientation and --joint-cone (default deg)",
    )
    p.add_argument(
        "--convention",
        choices=list(CONVENTIONS),
        default="utn",
        help="Euler convention of --orientation (default utn: Ry·Rx·Rz)",
    )
    p.add_argument("--resolution", type=float, default=0.01, metavar="M", help="grid step in metres (default 0.01)")
    p.add_argument(
        "--limits",
        default="stroke",
        metavar="LIST",
        help=f"comma-separated limits among {','.join(LIMIT_CHOICES)} (default stroke; the stroke always applies)",
    )
    p.add_argument(
        "--joint-cone",
        type=float,
        default=45.0,
        metavar="ANGLE",
        help="with 'joints': max angle between a leg and its joint's axis (plate/base normal), base and top (default 45 deg)",
    )
    p.add_argument(
        "--leg-diameter",
        type=float,
        default=None,
        metavar="M",
        help="with 'collision': leg cylinder diameter in metres (default: the Drake model's cylinder diameter)",
    )
    p.add_argument(
        "--max-condition",
        type=float,
        default=100.0,
        metavar="K",
        help="with 'dexterity': largest acceptable Jacobian condition number (default 100)",
    )
    p.add_argument(
        "--centre",
        nargs=3,
        type=float,
        default=None,
        metavar=("X", "Y", "Z"),
        help="rotation centre for the rotation limits, metres in the plate frame (default: the platform's rotation centre)",
    )
    p.add_argument("--workers", type=int, default=1, metavar="N", help="worker processes for the sweep (default 1)")
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
    p.add_argument(
        "--out",
        metavar="DIR",
        help="write workspace.json, boundary.csv and the views (top, front, side, 3d PNG) into DIR",
    )
    add_force_arg(p)
    p.set_defaults(func=run)


def parse_limits(text: str, platform, joint_cone: float, leg_diameter: float | None, max_condition: float):
    """A ``workspace.Limits`` from the ``--limits`` list (angles already in radians)."""
    names = [n.strip() for n in text.split(",") if n.strip()]
    unknown = [n for n in names if n not in LIMIT_CHOICES]
    if unknown:
        raise OptionError(
            OptionError.UNKNOWN_LIMIT.format(option="--limits", value=unknown[0], valid=", ".join(LIMIT_CHOICES))
        )
    kw = {}
    if "joints" in names:
        kw["base_cone"] = kw["top_cone"] = joint_cone
    if "collision" in names:
        if leg_diameter is None:
            leg_diameter = 2 * leg_dimensions(platform)["cylinder_radius"]
        kw["leg_diameter"] = leg_diameter
    if "dexterity" in names:
        kw["max_condition"] = max_condition
    return Limits(**kw)


def run(args) -> int:
    names = [n.strip() for n in args.limits.split(",")]
    reject_unused(args, "--limits ...,joints", "joints" in names, joint_cone=45.0)
    reject_unused(args, "--limits ...,collision", "collision" in names, leg_diameter=None)
    reject_unused(args, "--limits ...,dexterity", "dexterity" in names, max_condition=100.0)
    reject_unused(args, "--out", args.out is not None, force=False)
    out = output_folder(args)
    platform = platform_from_args(args)
    if not (args.resolution > 0 and math.isfinite(args.resolution)):
        raise OptionError(OptionError.POSITIVE.format(option="--resolution", unit="metres", value=args.resolution))
    if args.centre is not None:
        check_centre(platform, args.centre)
    check_finite(args.orientation, "--orientation")
    check_workers("--workers", args.workers)  # the one rule for worker counts (core.processes)
    orientation = to_radians(args.orientation, args.angle_unit)
    cone = float(to_radians(args.joint_cone, args.angle_unit))
    limits = parse_limits(args.limits, platform, cone, args.leg_diameter, args.max_condition)
    w = ws.constant_orientation_workspace(
        platform,
        orientation,
        args.resolution,
        limits,
        args.convention,
        workers=args.workers,
        progress=sys.stderr.isatty(),
    )
    rot = ws.orientation_limits(platform, centre=args.centre, limits=limits)
    result = {
        "platform": platform.name,
        "orientation_deg": np.degrees(orientation).tolist(),
        "convention": args.convention,
    }
    result.update(w.summary())
    result["rotation_limits_deg"] = {
        a: {("+" if r.sign > 0 else "-"): math.degrees(r.angle) for r in rot if r.axis == a} for a in ws.AXES
    }
    result["rotation_limits"] = [r.as_dict() for r in rot]
    result["rotation_centre_m"] = list(platform.rotation_centre if args.centre is None else args.centre)
    result["mobility"] = ws.stewart_mobility("SPS")["m"]
    if out is not None:
        write_outputs(w, result, out)
    if args.json:
        print_json(result)
    else:
        print(
            f"platform {platform.name}: workspace at orientation {np.round(args.orientation, 6).tolist()} {args.angle_unit}, "
            f"limits {', '.join(limits.active)}, grid {args.resolution} m"
        )
        for a in ws.AXES:
            lo, hi = result[f"{a}_range"]
            print(f"  {a}: [{lo:+.4f}, {hi:+.4f}] m")
        print(
            f"  volume {w.volume:.6f} m³ (true value in [{w.volume_bounds[0]:.6f}, {w.volume_bounds[1]:.6f}]; "
            f"change from half resolution {w.volume_change_2h:.2e})"
        )
        for n, v in w.removed_m3.items():
            print(f"  {n} limit {'binds' if v > 0 else 'does not bind'}: removes {v:.6f} m³")
        print("  rotation limits from the home pose:")
        for r in rot:
            what = (
                (f"plate anchor of leg {r.leg} at the base plane" if r.limit == "base" else f"{r.limit} leg {r.leg}")
                if r.leg
                else (f"{r.limit} legs {r.pair}" if r.pair else (r.limit or "none reached"))
            )
            print(
                f"    about {r.axis} {'+' if r.sign > 0 else '-'}: {math.degrees(r.angle):+8.3f} deg  ({what}"
                f"{', ' + r.side if r.side else ''}); lengths {np.round(r.lengths, 4).tolist()} m"
            )
        if args.out:
            print(f"  wrote {args.out}")
    return 0


def write_outputs(w, result: dict, out) -> None:
    """workspace.json, boundary.csv (metres) and the four views as PNG into ``out``."""
    # deferred: pyplot is imported only when views are written, after selecting the Agg backend
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    with atomic_folder(out) as tmp:
        (tmp / "workspace.json").write_text(dumps_strict(result))
        np.savetxt(tmp / "boundary.csv", w.boundary, delimiter=",", header="x_m,y_m,z_m", comments="", fmt="%.6f")
        for name, fig in view_figures(w, title=result["platform"].replace("$", r"\$")).items():
            fig.savefig(tmp / f"{name}.png", dpi=110, bbox_inches="tight")
            plt.close(fig)
