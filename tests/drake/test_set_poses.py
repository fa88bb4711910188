"""``platform_model.set_poses`` (the per-sample loops' batch of ``set_pose``) leaves the context in exactly the
state ``set_pose`` gives, pose by pose: its rotations and joint positions are computed for all poses at once,
and numpy's elementwise arithmetic must give the same bits as one pose at a time."""

import numpy as np

from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.sampling import random_poses
from stewart_drake.drake.platform_model import build_plant, prismatic_joints, prismatic_positions, set_pose, set_poses


def test_set_poses_equals_set_pose_bit_for_bit(preset):
    plant, _ = build_plant(preset, visuals=False)
    a, b = plant.CreateDefaultContext(), plant.CreateDefaultContext()
    poses = random_poses(preset, 25, seed=4)
    seen = []
    for k in set_poses(plant, a, preset, poses, "zyx"):
        set_pose(plant, b, preset, poses[k], "zyx")
        assert np.array_equal(plant.GetPositions(a), plant.GetPositions(b)), k
        seen.append(k)
    assert seen == list(range(len(poses)))


def test_prismatic_positions_with_held_joints():
    """The joints looked up once read the same lengths as a fresh lookup, in leg order."""
    p = load_preset("utn-dynamic")
    plant, _ = build_plant(p, visuals=False)
    ctx = plant.CreateDefaultContext()
    pose = random_poses(p, 1, seed=2)[0]
    set_pose(plant, ctx, p, pose)
    joints = prismatic_joints(plant)
    assert [j.name() for j in joints] == [f"prismatic_{i + 1}" for i in range(6)]
    assert np.array_equal(prismatic_positions(plant, ctx, joints), prismatic_positions(plant, ctx))
    # the pose's closed-form lengths (a few float operations on metre-scale numbers: ~1e-15 m), not home's
    np.testing.assert_allclose(prismatic_positions(plant, ctx, joints), leg_lengths(p, pose), rtol=0, atol=1e-12)
