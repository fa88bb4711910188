"""The servo hexapod's plant without SceneGraph (``servo_model.build_plant(visuals=False)``, what the closed loop
and the IK cross-checks build: nothing is shown) steps to the same states, bit for bit, as the plant with its
display geometry: the model has no collision geometry, so SceneGraph never enters the dynamics."""

import numpy as np
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder

from stewart_drake.core.sdf_models import SERVO_HEXAPOD_MODEL
from stewart_drake.drake.servo_model import build_plant
from stewart_drake.mechanisms.servo_loop import servo_gains
from stewart_drake.mechanisms.servo_mounting import servo_joint_home


def _states(hexapod, visuals: bool) -> tuple[np.ndarray, int]:
    """The plant state every 10 ms over 0.15 s from home, the six PD servos told to turn by different angles
    (so the platform moves), and the number of geometries SceneGraph holds (−1: no SceneGraph)."""
    builder = DiagramBuilder()
    plant, scene_graph = build_plant(hexapod, 1e-3, builder, pd_gains=servo_gains(hexapod), visuals=visuals)
    builder.ExportInput(plant.get_desired_state_input_port(plant.GetModelInstanceByName(SERVO_HEXAPOD_MODEL)), "xd")
    diagram = builder.Build()
    sim = Simulator(diagram)
    root = sim.get_mutable_context()
    turn = np.radians([4.0, -3.0, 2.0, -5.0, 3.0, -2.0])
    diagram.GetInputPort("xd").FixValue(root, np.r_[servo_joint_home(hexapod) + turn, np.zeros(6)])
    pc = plant.GetMyContextFromRoot(root)
    out = []
    for k in range(1, 16):
        sim.AdvanceTo(k * 1e-2)
        out.append(plant.GetPositionsAndVelocities(pc).copy())
    n_geometries = -1 if scene_graph is None else scene_graph.model_inspector().num_geometries()
    return np.array(out), n_geometries


def test_servo_plant_steps_bit_for_bit_without_scene_graph(hexapod):
    shown, n_shown = _states(hexapod, visuals=True)
    alone, n_alone = _states(hexapod, visuals=False)
    assert n_shown > 0 and n_alone == -1
    assert np.ptp(shown[:, :7], axis=0).max() > 1e-4  # the platform moved (quaternion or position, > 1e-4)
    np.testing.assert_array_equal(alone, shown)
