"""Closed-form inverse kinematics checked against Drake's own kinematics on the closed-loop plant."""

from __future__ import annotations

from stewart_drake.core.geometry import PRESETS, load_preset
from stewart_drake.core.sampling import random_poses
from stewart_drake.drake.verify_kinematics import compare_ik_with_drake
from stewart_drake.report import run_standalone

TITLE = "Inverse kinematics vs Drake"
ORDER = 5
COST = 1  # CPU seconds (full report, measured): the report's workers start the costliest first
NEEDS = ()  # a user's platform: its own plant against its closed form
# SNOPT closes the ball constraints to its feasibility tolerance (1e-10); lengths agree far below 1 µm.
IK_TOL_M = 1e-8
# Anchor frames and forward kinematics are pure float arithmetic on the same numbers.
FRAME_TOL_M = 1e-12


def build(section) -> None:
    n = 20 if section.quick else 200
    rows = []
    platforms = [load_preset(name) for name in PRESETS] if section.subject is None else [section.subject.platform]
    for p in platforms:
        name = p.name
        err = compare_ik_with_drake(p, random_poses(p, n, seed=1))
        rows.append([name, n, err["anchors"], err["ik"], err["fk"]])
        section.check(f"{name}: anchor frames read back from the parsed plant", err["anchors"], FRAME_TOL_M, "m")
        section.check(
            f"{name}: Drake InverseKinematics prismatic positions vs closed-form lengths ({n} poses)",
            err["ik"],
            IK_TOL_M,
            "m",
        )
        section.check(
            f"{name}: Drake FK piston tip vs plate anchor at the closed-form joints ({n} poses)",
            err["fk"],
            FRAME_TOL_M,
            "m",
        )
    section.text(
        "For each platform the SDF is generated from the Platform and parsed into a discrete MultibodyPlant with six "
        "ball constraints. (a) the anchor frames read back from the plant; (b) Drake's InverseKinematics with the "
        "plate's floating joint locked at a random in-stroke pose, legs starting from the home configuration; "
        "(c) Drake's forward kinematics with the joints set to the closed-form solution."
    )
    section.table(
        ["platform", "poses", "anchor frames (m)", "IK lengths (m)", "FK tip gap (m)"],
        rows,
        caption="Worst absolute errors",
        fmt="{:.3g}",
    )


def main(argv=None):
    return run_standalone(__file__, argv)


if __name__ == "__main__":
    raise SystemExit(main())
