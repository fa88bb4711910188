"""The generated Drake model agrees with the Platform and with the closed-form inverse kinematics."""

import numpy as np
import pytest

from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.leg_bodies import leg_joint_positions
from stewart_drake.core.sampling import random_poses
from stewart_drake.drake.platform_model import build_plant, set_pose
from stewart_drake.drake.verify_kinematics import anchor_frames, drake_fk_tip_errors, drake_ik_lengths, make_plant

# SNOPT closes the ball constraints to its feasibility tolerance (1e-10 m scale); the recovered leg
# lengths then agree to ~1e-10 m. 1e-8 m leaves margin and is still 100x tighter than the 1e-6 m asked.
IK_TOL = 1e-8
# Frames and forward kinematics are a few float operations on metre-scale numbers: ~1e-15 m.
FK_TOL = 1e-12


def test_plant_structure(preset):
    h = make_plant(preset)
    plant = h.plant
    assert plant.num_actuators() == 6
    assert plant.num_constraints() == 6
    # 7 (quaternion plate) + 6 x (2 universal + 1 prismatic).
    assert plant.num_positions() == 25 and plant.num_velocities() == 24
    assert plant.GetJointByName("top").type_name() == "quaternion_floating"
    lo, hi = plant.GetPositionLowerLimits(), plant.GetPositionUpperLimits()
    j = plant.GetJointByName("prismatic_3").position_start()
    # The SDF stores 15 significant digits.
    assert (lo[j], hi[j]) == pytest.approx((preset.L_min, preset.L_max), rel=1e-14)


def test_anchor_frames_read_back(preset):
    base, top = anchor_frames(make_plant(preset))
    np.testing.assert_allclose(base, preset.base_anchors, atol=FK_TOL)
    np.testing.assert_allclose(top, preset.top_anchors_per_leg, atol=FK_TOL)


def test_default_context_is_assembled_at_home(preset):
    h = make_plant(preset)
    gaps = drake_fk_tip_errors(h, preset.home_pose())
    assert gaps.max() < FK_TOL


def test_drake_fk_puts_piston_tips_on_anchors(preset):
    h = make_plant(preset)
    poses = random_poses(preset, 200, seed=21)
    assert drake_fk_tip_errors(h, poses).max() < FK_TOL


def test_drake_inverse_kinematics_matches_closed_form(preset):
    h = make_plant(preset)
    poses = random_poses(preset, 200, seed=22)
    L_drake = drake_ik_lengths(h, poses)
    np.testing.assert_allclose(L_drake, leg_lengths(preset, poses), atol=IK_TOL, rtol=0)


def test_universal_angles_follow_drake_convention():
    p = load_preset("utn-dynamic")
    plant, _ = build_plant(p)
    ctx = plant.CreateDefaultContext()
    q = p.home_pose() + [0.03, -0.02, 0.05, 0.2, 0.1, -0.3]
    set_pose(plant, ctx, p, q)
    angles, L = leg_joint_positions(p, q)
    for i in range(6):
        X = plant.GetFrameByName(f"piston_{i + 1}").CalcPoseInWorld(ctx)
        u = (X.translation() - p.base_anchors[i]) / L[i]
        np.testing.assert_allclose(X.rotation().matrix()[:, 2], u, atol=1e-13)
    assert np.abs(angles).max() < 1.0


def test_time_step_must_be_positive():
    with pytest.raises(ValueError, match="time_step must be > 0 .* got 0.0"):
        build_plant(load_preset("utn-dynamic"), time_step=0.0)
