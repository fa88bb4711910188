"""``ServoPlant.set_servos`` reads every arm tip, anchor and arm frame from one evaluation of the kinematics
before it sets any rod: the rods' angles must be those of setting rod by rod, each read after the previous rod
was set (the positions a rod's frame is built from do not depend on the other rods), bit for bit."""

import numpy as np

from stewart_drake.core.sdf import rpy
from stewart_drake.drake.servo_model import ServoPlant
from stewart_drake.mechanisms.servo_mounting import frame_from_zx, servo_joint_home


def _rod_by_rod(h: ServoPlant, angles) -> np.ndarray:
    """The plant's positions after setting the servos, then each rod from frames read after the previous rod."""
    for i, j in enumerate(h.servos):
        j.set_angle(h.context, float(angles[i]))
    for i, j in enumerate(h.rods):
        tip = h.plant.GetFrameByName(f"arm_tip_{i + 1}").CalcPoseInWorld(h.context).translation()
        d = h.plant.GetFrameByName(f"platform_anchor_{i + 1}").CalcPoseInWorld(h.context).translation() - tip
        R_WA = h.plant.GetBodyByName(f"arm_{i + 1}").EvalPoseInWorld(h.context).rotation().matrix()
        X_AF = j.frame_on_parent().GetFixedPoseInBodyFrame().rotation().matrix()
        X_RM = j.frame_on_child().GetFixedPoseInBodyFrame().rotation().matrix()
        j.set_angles(h.context, rpy((R_WA @ X_AF).T @ frame_from_zx(d, R_WA[:, 0]) @ X_RM))
    return h.plant.GetPositions(h.context).copy()


def test_set_servos_equals_rod_by_rod(hexapod):
    rng = np.random.default_rng(12)
    a, b = ServoPlant(hexapod), ServoPlant(hexapod)
    for _ in range(5):
        pose = hexapod.home_pose() + np.r_[rng.uniform(-0.005, 0.005, 3), rng.uniform(-0.08, 0.08, 3)]
        angles = servo_joint_home(hexapod) + rng.uniform(-0.2, 0.2, 6)
        a.set_platform(pose)
        b.set_platform(pose)
        a.set_servos(angles)
        np.testing.assert_array_equal(a.plant.GetPositions(a.context), _rod_by_rod(b, angles))
