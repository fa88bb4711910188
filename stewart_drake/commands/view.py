"""``stewart-drake view``: the platform in Meshcat with pose sliders and live readouts, or a log replayed."""

from __future__ import annotations

import sys

import numpy as np

from stewart_drake.commands._common import add_platform_arg, add_unit_args, platform_from_args, print_json
from stewart_drake.core.rotations import pose_to_si
from stewart_drake.errors import OPTION_PORT, OPTION_SPEED, OPTION_VIEW_DURATION, OptionError


def register(sub) -> None:
    p = sub.add_parser(
        "view",
        help="interactive 3-D viewer (Meshcat on localhost): pose sliders, leg lengths, "
        "stroke margins, singularity distance, assembly modes; or replay a simulate/run log",
    )
    add_platform_arg(p, default="utn-dynamic")
    add_unit_args(p)
    p.add_argument(
        "--port",
        type=int,
        default=None,
        metavar="P",
        help="Meshcat port on localhost (default: the first free from 7000)",
    )
    p.add_argument(
        "--pose",
        type=float,
        nargs=6,
        metavar=("PX", "PY", "PZ", "A", "B", "G"),
        help="initial pose in --length-unit/--angle-unit/--convention (default: home)",
    )
    p.add_argument(
        "--replay",
        metavar="LOG",
        help="replay a simulate log (log.npz, log.csv), a run output (trajectory.csv) or their folder",
    )
    p.add_argument("--speed", type=float, default=1.0, help="replay speed factor (default 1)")
    p.add_argument("--loop", action="store_true", help="replay in a loop")
    p.add_argument(
        "--duration",
        type=float,
        default=None,
        metavar="S",
        help="exit after S wall seconds (non-interactive use, tests); 0: draw once and exit",
    )
    p.add_argument("--no-modes", action="store_true", help="do not count assembly modes (faster updates)")
    p.add_argument("--json", action="store_true", help="print the last readout as JSON on exit")
    p.set_defaults(func=run)


def run(args) -> int:
    # Deferred: this command needs Drake (Meshcat), and cli.py imports every command module at start-up,
    # so a top-level import would make the numpy commands need pydrake too.
    from stewart_drake.api.viewer import ViewerReadout
    from stewart_drake.drake.viewer import Viewer, load_replay, open_meshcat

    platform = platform_from_args(args)
    if args.duration is not None and not (np.isfinite(args.duration) and 0 <= args.duration <= 86400):
        raise OptionError(OPTION_VIEW_DURATION.format(value=args.duration))
    if not (np.isfinite(args.speed) and args.speed > 0):
        raise OptionError(OPTION_SPEED.format(value=args.speed))
    if args.port is not None and not 1024 <= args.port <= 65535:  # Drake aborts (SystemExit) below 1024
        raise OptionError(OPTION_PORT.format(value=args.port))
    replay = load_replay(args.replay) if args.replay else None
    if replay is not None and replay[3] and replay[3] != platform.name:
        print(
            f"stewart-drake view: note: the log was recorded on platform {replay[3]!r}, shown on {platform.name!r}",
            file=sys.stderr,
        )
    pose = (
        platform.home_pose()
        if args.pose is None
        else pose_to_si(np.array(args.pose), args.length_unit, args.angle_unit)
    )
    meshcat = open_meshcat(args.port)
    viewer = Viewer(platform, meshcat, args.length_unit, args.angle_unit, args.convention, modes=not args.no_modes)
    print(
        f"stewart-drake view: {platform.name} at {meshcat.web_url()}"
        + ("" if args.duration is not None else " (Ctrl-C to quit)"),
        file=sys.stderr if args.json else sys.stdout,  # --json: stdout is the JSON alone
        flush=True,
    )
    try:
        if replay is not None:
            t, poses, sat, _ = replay
            r = viewer.replay(t, poses, sat, args.speed, args.loop, args.duration)
        else:
            viewer.add_sliders(pose)
            r = viewer.show(pose) if args.duration == 0 else viewer.interact(args.duration)
    except KeyboardInterrupt:
        r = viewer.readout
    if args.json and r is not None:
        print_json(ViewerReadout.from_readout(r).to_dict())
    if r is not None and not r.reachable and args.duration is not None:
        print(f"stewart-drake view: the last pose is unreachable: {'; '.join(l for l in _why(r))}", file=sys.stderr)
        return 1
    return 0


def _why(r):
    bad = [i + 1 for i in np.flatnonzero(r.margin < 0)]
    if bad:
        yield "legs " + ", ".join(map(str, bad)) + " beyond the stroke"
    if r.condition >= 1e8:
        yield f"singular (condition number {r.condition:.3g})"
