"""``stewart-drake workspace``: constant-orientation workspace, rotation limits and mobility of a platform."""

from __future__ import annotations

import math
import sys

import numpy as np

from stewart_drake.api.reach import LIMIT_CHOICES, solve_workspace
from stewart_drake.commands._common import (
    add_force_arg,
    add_platform_arg,
    dumps_strict,
    output_folder,
    platform_from_args,
    print_json,
    reject_unused,
)
from stewart_drake.core.rotations import ANGLE_UNITS, CONVENTIONS, to_radians
from stewart_drake.errors import OptionError, SynthesisError
from stewart_drake.synthesis.proof import MAX_CELLS, START_CELLS
from stewart_drake.system.output_folder import atomic_folder
from stewart_drake.workspace import AXES, view_figures

BOX_AXES = ("px", "py", "pz", "a", "b", "g")


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
    p.add_argument(
        "--require-box",
        nargs=12,
        type=float,
        default=None,
        metavar="V",
        help="with --prove: a box of poses relative to home, px py pz (m) a b g (--angle-unit), each as low high",
    )
    p.add_argument(
        "--prove",
        action="store_true",
        help="prove every pose of --require-box within the stroke and above the base (interval cover); "
        "exit 1 if violated (a witness pose) or unresolved",
    )
    p.add_argument(
        "--max-cells",
        type=int,
        default=MAX_CELLS,
        metavar="N",
        help=f"with --prove: the most cells the proof may examine (default {MAX_CELLS}; it starts with "
        f"{START_CELLS} and doubles them while the volume left unproven shrinks)",
    )
    p.set_defaults(func=run)


def run(args) -> int:
    reject_unused(args, "--prove", args.prove, require_box=None, max_cells=MAX_CELLS)
    if args.prove:
        return run_proof(args)
    names = [n.strip() for n in args.limits.split(",")]
    reject_unused(args, "--limits ...,joints", "joints" in names, joint_cone=45.0)
    reject_unused(args, "--limits ...,collision", "collision" in names, leg_diameter=None)
    reject_unused(args, "--limits ...,dexterity", "dexterity" in names, max_condition=100.0)
    reject_unused(args, "--out", args.out is not None, force=False)
    out = output_folder(args)
    platform = platform_from_args(args)
    r = solve_workspace(
        platform,
        to_radians(args.orientation, args.angle_unit),
        args.resolution,
        args.limits,
        args.convention,
        float(to_radians(args.joint_cone, args.angle_unit)),
        args.leg_diameter,
        args.max_condition,
        args.centre,
        args.workers,
        sys.stderr.isatty(),
        orientation_shown=args.orientation,
    )
    w, result, rot = r.grid, r.to_dict(), r.rotation_limits
    if out is not None:
        write_outputs(w, result, out)
    if args.json:
        print_json(result)
    else:
        print(
            f"platform {platform.name}: workspace at orientation {np.round(args.orientation, 6).tolist()} {args.angle_unit}, "
            f"limits {', '.join(w.limits.active)}, grid {args.resolution} m"
        )
        for a in AXES:
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


def run_proof(args) -> int:
    """``--prove``: the proof of ``--require-box`` alone (``synthesis.proof``); exit 1 unless proven."""
    # deferred: the synthesis API imports its search (pymoo, scipy), which only --prove's module needs, and
    # not for the proof itself; the sweep and --help start without it
    from stewart_drake.synthesis.api import prove_workspace
    from stewart_drake.synthesis.synthesize import cells_note

    reject_unused(args, "the workspace sweep (without --prove)", False, out=None, centre=None, workers=1)
    if args.require_box is None:
        raise OptionError(SynthesisError.BOX_OPTION_COUNT.format(n=0))
    names = [n.strip() for n in args.limits.split(",") if n.strip()]
    reject_unused(args, "--limits ...,joints", "joints" in names, joint_cone=45.0)
    reject_unused(args, "--limits ...,collision", "collision" in names, leg_diameter=None)
    box = np.asarray(args.require_box, dtype=float).reshape(6, 2)
    platform = platform_from_args(args)
    r = prove_workspace(
        platform,
        box[:, 0],
        box[:, 1],
        limits=args.limits,
        angle_unit=args.angle_unit,
        joint_cone=args.joint_cone,
        leg_diameter=args.leg_diameter,
        convention=args.convention,
        max_cells=args.max_cells,
    )
    result, cone, diameter = r.proof, r.joint_cone, r.leg_diameter
    if args.json:
        print_json(r.to_dict())
    else:
        print(
            f"platform {platform.name}: proof that every pose of the box (relative to home "
            f"{np.round(platform.home_pose()[:3], 6).tolist()} m) is within the stroke and above the base"
            f"{f' with joint cones of {args.joint_cone} {args.angle_unit}' if cone is not None else ''}"
            f"{f', legs {diameter} m thick apart' if diameter is not None else ''}: {result.status}"
        )
        print(f"  {result.cells_examined} cells examined, {result.cells_proven} proven, {result.seconds:.2f} s")
        if result.status == "proven":
            lo, hi = result.length_bounds
            print(
                f"  leg lengths within [{lo:.6f}, {hi:.6f}] m (stroke [{platform.L_min}, {platform.L_max}] m); "
                f"least margin {result.stroke_margin_m * 1e3:.3f} mm"
            )
        elif result.witness:
            w = result.witness
            print(
                f"  witness pose {np.round(w['pose'], 9).tolist()} (in the base frame, not relative to home; m, rad): leg {w['leg']} {w['what']} "
                f"(length {w['length_m']:.6f} m, checked by the IK)"
            )
        else:
            print(f"  not proven yet {cells_note(result.cells_examined, result.unresolved_count, result.stopped)}")
    return 0 if result.status == "proven" else 1
