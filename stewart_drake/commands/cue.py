"""``stewart-drake cue``: a vehicle's motion (a drive file or a shipped drive) turned into platform poses by a
motion-cueing law, kept in the workspace, scored by perceived motion, optionally run in the loop with the
machine's controller and the Drake plant; writes the poses, the scores and plots."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

from stewart_drake.api.cueing import ALGORITHMS, cue, resolve_drive
from stewart_drake.commands._common import (
    add_force_arg,
    add_machine_args,
    add_platform_arg,
    dumps_strict,
    machine_from_args,
    output_folder,
    print_json,
    reject_unused,
)
from stewart_drake.control.cueing.generators import DRIVES
from stewart_drake.control.cueing.tuning import load_params
from stewart_drake.errors import OptionError
from stewart_drake.system.output_folder import atomic_folder

HELP = "motion cueing: a vehicle's motion (drive file or shipped drive) to platform poses, scored by perceived motion"
# the files cue writes into --out (perception.png: vehicle vs perceived per channel; legs.png: leg usage)
FILES = ("poses.csv", "scores.json", "perception.png", "legs.png")
ANIMATION = "animation.html"  # with --animate


def register(sub) -> None:
    p = sub.add_parser("cue", help=HELP)
    add_platform_arg(p, default=None)
    add_machine_args(p)
    p.add_argument(
        "--drive",
        required=True,
        metavar="FILE|NAME",
        help=f"the vehicle's motion: a CSV or Parquet file (t,fx,fy,fz,wx,wy,wz[,roll,pitch,yaw], SI, head frame) or a "
        f"shipped drive ({', '.join(DRIVES)})",
    )
    p.add_argument(
        "--algorithm",
        choices=ALGORITHMS,
        default="classical",
        help="classical washout with hand-set (FlyPT-like) parameters, classical washout tuned for the drive (or "
        "--params), or MPC cueing (default classical)",
    )
    p.add_argument(
        "--params", default=None, metavar="FILE", help="classical washout parameters (YAML, as tuning writes them)"
    )
    p.add_argument(
        "--simulate",
        action="store_true",
        help="run the poses through the machine's controller and the Drake plant and score the plant's motion",
    )
    p.add_argument("--out", required=True, metavar="DIR", help="write poses.csv, scores.json, perception.png, legs.png")
    p.add_argument(
        "--joint-cone",
        type=float,
        default=None,
        metavar="DEG",
        help="keep every leg within this angle of its joint's axis (base and plate normals), degrees (default: no "
        "joint limit; platform files give none)",
    )
    p.add_argument(
        "--animate",
        action="store_true",
        help="also write animation.html: the plant's motion (with --simulate) or the commanded poses, in Meshcat",
    )
    p.add_argument("--json", action="store_true", help="print the whole result as JSON (default: a summary)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar (with --simulate)")
    add_force_arg(p)
    p.set_defaults(func=run)


def run(args) -> int:
    reject_unused(args, "--algorithm classical or tuned", args.algorithm != "mpc", params=None)
    reject_unused(args, "--simulate", args.simulate, no_progress=False)
    out_folder = output_folder(args, names=FILES + (ANIMATION,) * args.animate)
    machine = machine_from_args(args)
    drive = resolve_drive(args.drive, "--drive")
    if args.joint_cone is not None and not 0 < args.joint_cone <= 180:
        raise OptionError(
            OptionError.BETWEEN.format(
                option="--joint-cone", lo="0 (excluded)", hi="180 degrees", value=args.joint_cone
            )
        )
    result = cue(
        machine,
        drive,
        algorithm=args.algorithm,
        params=load_params(args.params) if args.params is not None else None,
        simulate=args.simulate,
        joint_cone=None if args.joint_cone is None else math.radians(args.joint_cone),
        progress=not args.no_progress,
    )
    d = result.to_dict()
    # deferred: matplotlib is loaded only when the figures are written
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with atomic_folder(out_folder) as tmp:
        write_poses(tmp / "poses.csv", result.drive.t, result.poses)
        (tmp / "scores.json").write_text(dumps_strict(d))
        for name, fig in (("perception.png", result.plot()), ("legs.png", result.plot_legs())):
            fig.savefig(tmp / name, dpi=100, bbox_inches="tight")
            plt.close(fig)
        if args.animate:
            (tmp / ANIMATION).write_text(result.animate().html, encoding="utf-8")
    print_json(d if args.json else summary(d))
    for f in result.failures:
        print(f"stewart-drake cue: {f}", file=sys.stderr)
    return 0 if result.ok else 1


def summary(d: dict) -> dict:
    """The result without the parameters, the loop's settings and the per-channel scores (all in scores.json):
    what a person reads first."""
    out = {k: v for k, v in d.items() if k not in ("params", "simulation")}
    for key in ("scores", "plant_scores"):
        if out.get(key) is not None:
            out[key] = {k: v for k, v in out[key].items() if k != "channels"}
    return out


def write_poses(path: Path, t, poses) -> None:
    """``t,px,py,pz,ax,ay,az`` rows in SI: what ``simulate --trajectory`` reads back."""
    np.savetxt(path, np.column_stack([t, poses]), delimiter=",", header="t,px,py,pz,ax,ay,az", comments="", fmt="%.9g")
