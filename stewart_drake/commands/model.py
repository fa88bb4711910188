"""``stewart-drake model``: write or inspect the generated Drake model (SDF) of a platform."""

from __future__ import annotations

from stewart_drake.commands._common import add_platform_arg, platform_from_args, print_json
from stewart_drake.core.sdf_models import platform_model_name, sdf_text, write_sdf
from stewart_drake.errors import UsageError


def register(sub) -> None:
    p = sub.add_parser("model", help="generate (write) or inspect the SDF model of a platform")
    add_platform_arg(p)
    p.add_argument(
        "--write",
        metavar="DIR",
        help="write <DIR>/<name>.sdf (name made file-safe; an existing file is replaced only if stewart-drake wrote it)",
    )
    p.add_argument(
        "--inspect", action="store_true", help="parse into a MultibodyPlant and list bodies, joints, constraints"
    )
    p.add_argument("--json", action="store_true", help="with --inspect: JSON output")
    p.set_defaults(func=run)


def run(args) -> int:
    if args.json and not args.inspect:
        raise UsageError(UsageError.NEEDS.format(option="--json", needs="--inspect"))
    platform = platform_from_args(args)
    if args.write:
        written = write_sdf(platform, args.write, option="--write")
        if not args.inspect:
            print(written)
    if args.inspect:
        # Deferred: only --inspect needs Drake, and cli.py imports every command module at start-up;
        # writing or printing the SDF works without pydrake.
        from stewart_drake.drake.verify_kinematics import anchor_frames, make_plant

        h = make_plant(platform)
        plant = h.plant
        info = {
            "platform": platform.name,
            "bodies": [
                plant.get_body(b).name()
                for b in plant.GetBodyIndices(plant.GetModelInstanceByName(platform_model_name(platform)))
            ],
            "joints": {plant.get_joint(j).name(): plant.get_joint(j).type_name() for j in plant.GetJointIndices()},
            "actuators": [plant.get_joint_actuator(a).name() for a in plant.GetJointActuatorIndices()],
            "num_positions": plant.num_positions(),
            "num_velocities": plant.num_velocities(),
            "constraints": plant.num_constraints(),
            "time_step_s": plant.time_step(),
        }
        base, top = anchor_frames(h)
        if args.write:
            info["sdf_file"] = str(written)
        info["anchor_error_m"] = float(
            max(abs(base - platform.base_anchors).max(), abs(top - platform.top_anchors_per_leg).max())
        )
        if args.json:
            print_json(info)
        else:
            for k, v in info.items():
                print(f"{k}: {v}")
    if not args.write and not args.inspect:
        print(sdf_text(platform), end="")
    return 0
