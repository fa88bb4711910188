"""``stewart-drake model``: write or inspect the generated model of a platform (SDF for Drake; URDF + loop-closure YAML
for Pinocchio and ROS 2; MJCF for MuJoCo)."""

from __future__ import annotations

import io

from stewart_drake.commands._common import add_platform_arg, platform_from_args, print_json
from stewart_drake.core.sdf_models import sdf_text, write_sdf
from stewart_drake.engines.models import FORMATS, model_files, write_models
from stewart_drake.errors import UsageError
from stewart_drake.system.output_folder import write_output_file


def register(sub) -> None:
    p = sub.add_parser(
        "model", help="generate (write) or inspect the model of a platform: SDF (Drake), URDF + closures, MJCF"
    )
    add_platform_arg(p)
    p.add_argument(
        "--write",
        metavar="DIR",
        help="write <DIR>/<name>.sdf (name made file-safe; an existing file is replaced only if stewart-drake wrote it)",
    )
    p.add_argument(
        "--format",
        choices=FORMATS,
        default="sdf",
        help="sdf (Drake), urdf (the open tree for Pinocchio/ROS 2; --write adds <name>.closures.yaml, the six loop"
        " closures) or mjcf (MuJoCo, <name>.xml); default sdf",
    )
    p.add_argument(
        "--inspect", action="store_true", help="parse into a MultibodyPlant and list bodies, joints, constraints"
    )
    p.add_argument("--json", action="store_true", help="with --inspect: JSON output")
    p.add_argument(
        "--figure",
        metavar="FILE.png",
        help="draw the platform at home: joints numbered by leg, legs coloured, base axes (a new PNG file)",
    )
    p.set_defaults(func=run)


def run(args) -> int:
    if args.json and not args.inspect:
        raise UsageError(UsageError.NEEDS.format(option="--json", needs="--inspect"))
    if args.inspect and args.format != "sdf":
        raise UsageError(UsageError.NEEDS.format(option="--inspect", needs="--format sdf"))
    platform = platform_from_args(args)
    if args.figure:
        print(write_output_file(args.figure, _figure_png(platform), option="--figure"))
    if args.inspect:
        # Deferred: only --inspect needs Drake, and cli.py imports every command module at start-up;
        # writing or printing the SDF works without pydrake.
        from stewart_drake.api.model import inspect_model

        info = inspect_model(platform, write=args.write).to_dict()
        if args.json:
            print_json(info)
        else:
            for k, v in info.items():
                print(f"{k}: {v}")
    elif args.write and args.format == "sdf":
        print(write_sdf(platform, args.write, option="--write"))
    elif args.write:
        for path in write_models(platform, args.write, args.format, option="--write"):
            print(path)
    elif not args.figure:
        print(
            sdf_text(platform) if args.format == "sdf" else next(iter(model_files(platform, args.format).values())),
            end="",
        )
    return 0


def _figure_png(platform) -> bytes:
    """The PNG of ``design.drawings.platform_figure`` of ``platform``."""
    import matplotlib  # deferred: only --figure draws; cli.py imports every command module at start-up

    matplotlib.use("Agg")
    from stewart_drake.design.drawings import platform_figure

    fig = platform_figure(platform)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100)
    return buf.getvalue()
