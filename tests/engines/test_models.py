"""The engines' model files: URDF + closure YAML and MJCF written from a Platform and loaded back by Pinocchio and
MuJoCo give the platform's anchors, masses and closures."""

import xml.etree.ElementTree as ET

import numpy as np
import pytest
import yaml

from stewart_drake.core.geometry import PRESETS, load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.sampling import random_poses
from stewart_drake.engines.cross_check import engine_model, kinematics_check
from stewart_drake.engines.models import closures_yaml, mjcf_text, urdf_text, write_models

from .own_platform import own_platform

# The texts carry 15 significant digits: a number x comes back within 5e-15 |x|; positions are ≤ 1 m and masses
# ≤ 20 kg here, so 1e-13 m / 1e-12 kg bound the round trip with a decade to spare.
POS_TOL = 1e-13
MASS_TOL = 1e-12


@pytest.fixture(params=[*PRESETS, "own"])
def platform(request, tmp_path):
    return own_platform(tmp_path) if request.param == "own" else load_preset(request.param)


def test_urdf_is_a_tree_and_the_yaml_closes_every_leg(platform):
    """Without either engine: the URDF has one parent per link, and each leg's piston is closed onto its plate
    anchor by the YAML."""
    root = ET.fromstring(urdf_text(platform))
    children = [j.find("child").get("link") for j in root.iter("joint")]
    assert len(children) == len(set(children))  # a tree: no link has two parents
    assert {link.get("name") for link in root.iter("link")} - set(children) == {"base"}
    doc = yaml.safe_load(closures_yaml(platform))
    assert [(c["frame_a"], c["frame_b"]) for c in doc["closures"]] == [(f"piston_{i}", "top") for i in range(1, 7)]
    np.testing.assert_allclose([c["p_b"] for c in doc["closures"]], platform.top_anchors_per_leg, rtol=0, atol=0)


def test_pinocchio_loads_back_anchors_and_masses(platform):
    pin = pytest.importorskip("pinocchio", reason="pinocchio not installed (pip install 'stewart-drake[engines]')")
    model = pin.buildModelFromXML(urdf_text(platform))
    data = model.createData()
    pin.framesForwardKinematics(model, data, pin.neutral(model))
    body = pin.FrameType.BODY
    base = np.array([data.oMf[model.getFrameId(f"base_anchor_{i}", body)].translation for i in range(1, 7)])
    np.testing.assert_allclose(base, platform.base_anchors, rtol=0, atol=POS_TOL)
    top = model.frames[model.getFrameId("top_anchor_1", body)]
    assert model.names[top.parentJoint] == "top"
    anchors = np.array(
        [model.frames[model.getFrameId(f"top_anchor_{i}", body)].placement.translation for i in range(1, 7)]
    )
    np.testing.assert_allclose(anchors, platform.top_anchors_per_leg, rtol=0, atol=POS_TOL)
    mass = {model.names[j]: model.inertias[j].mass for j in range(1, model.njoints)}
    assert abs(mass["top"] - platform.mass) <= MASS_TOL
    assert abs(mass["universal_1_2"] - platform.legs.cylinder_mass) <= MASS_TOL  # the cylinder
    assert abs(mass["prismatic_1"] - platform.legs.piston_mass) <= MASS_TOL
    np.testing.assert_allclose(model.inertias[model.getJointId("top")].lever, platform.com, rtol=0, atol=POS_TOL)


def test_mujoco_loads_back_anchors_masses_and_a_closed_home(platform):
    mujoco = pytest.importorskip("mujoco", reason="mujoco not installed (pip install 'stewart-drake[engines]')")
    m = mujoco.MjModel.from_xml_string(mjcf_text(platform))
    d = mujoco.MjData(m)
    mujoco.mj_kinematics(m, d)

    def site(name):
        return d.site_xpos[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, name)]

    def body(name):
        return mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, name)

    np.testing.assert_allclose([site(f"base_anchor_{i}") for i in range(1, 7)], platform.base_anchors, atol=POS_TOL)
    np.testing.assert_allclose(
        [m.site_pos[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, f"top_anchor_{i}")] for i in range(1, 7)],
        platform.top_anchors_per_leg,
        atol=POS_TOL,
    )
    assert abs(m.body_mass[body("top")] - platform.mass) <= MASS_TOL
    assert abs(m.body_mass[body("cylinder_1")] - platform.legs.cylinder_mass) <= MASS_TOL
    assert abs(m.body_mass[body("piston_1")] - platform.legs.piston_mass) <= MASS_TOL
    # The reference configuration is the home pose: every closure closed, slide positions the home leg lengths.
    tips = np.array([site(f"piston_tip_{i}") for i in range(1, 7)])
    anchors = np.array([site(f"top_anchor_{i}") for i in range(1, 7)])
    assert np.abs(tips - anchors).max() <= POS_TOL
    slides = [m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, f"prismatic_{i}")] for i in range(1, 7)]
    np.testing.assert_allclose(d.qpos[slides], leg_lengths(platform, platform.home_pose()), rtol=0, atol=POS_TOL)


def test_the_written_urdf_and_closures_load_back_closed(tmp_path):
    """What ``model --format urdf`` writes (a ROS 2 user's two files) rebuilds the closed loop: Pinocchio loads the
    URDF and the YAML's closures from disk, and they close at our joint positions to rounding."""
    pytest.importorskip("pinocchio", reason="pinocchio not installed (pip install 'stewart-drake[engines]')")
    platform = own_platform(tmp_path)
    urdf, closures_file = write_models(platform, tmp_path / "out", "urdf")
    doc = yaml.safe_load(closures_file.read_text())
    assert doc["urdf"] == urdf.name
    eng = engine_model("pinocchio", platform, urdf=urdf.read_text(), closure_list=doc["closures"])
    r = kinematics_check(eng, platform, random_poses(platform, 50, seed=7))
    assert r["ok"], r
