"""The Drake plant of a Stewart platform: its SDF (``core/sdf_models.platform_sdf``) parsed into a
closed-loop ``MultibodyPlant``, and the helpers that pose it.

Names in the model: ``base``, ``top`` (link frame T), ``cylinder_i`` on ``universal_i``, ``piston_i`` on
the actuated ``prismatic_i`` (position = leg length, metres), ball constraints closing each piston tip
onto ``top_anchor_i``. Drake accepts ball constraints only on a discrete plant with a SAP contact
approximation, or on a continuous plant under the CENIC integrator.
"""

from __future__ import annotations

import numpy as np
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph, DiscreteContactApproximation, MultibodyPlant
from pydrake.systems.framework import DiagramBuilder

from stewart_drake.core.geometry import Platform
from stewart_drake.core.leg_bodies import leg_joint_positions
from stewart_drake.core.rotations import rotation_matrix
from stewart_drake.core.sdf_models import platform_sdf
from stewart_drake.errors import SimulationError


def add_platform(plant, platform: Platform, visuals: bool = True):
    """Parse the platform's SDF into ``plant`` (not finalized); return the model instance. The prismatic
    joints' default positions are the home leg lengths. ``visuals=False``: no visual geometry (nothing to
    show; the same dynamics, parsed ~7× faster: ``sdf_models.platform_sdf``)."""
    (instance,) = Parser(plant).AddModelsFromString(platform_sdf(platform, visuals), "sdf")
    _, L_home = leg_joint_positions(platform, platform.home_pose())
    for i in range(6):
        plant.GetJointByName(f"prismatic_{i + 1}", instance).set_default_translation(L_home[i])
    return instance


def build_plant(
    platform: Platform,
    time_step: float = 1e-3,
    builder=None,
    gravity: bool = True,
    continuous: bool = False,
    visuals: bool = True,
):
    """A finalized closed-loop ``MultibodyPlant`` of ``platform`` and its ``SceneGraph``, added to
    ``builder`` (a new ``DiagramBuilder`` if None). Discrete (SAP) with ``time_step`` > 0 by default: Drake's
    ball constraints need a discrete plant, except under the CENIC integrator (``continuous=True``: a
    continuous plant, time_step 0, for a Simulator configured with ``integration_scheme="cenic"``).
    ``visuals=False``: the plant alone, without visual geometry (``add_platform``) and without a SceneGraph
    (returned as None): the same dynamics (the model has no collision geometry), built and stepped faster."""
    if not (continuous or time_step > 0):
        raise SimulationError(SimulationError.DISCRETE_STEP.format(value=time_step))
    builder = builder or DiagramBuilder()
    step = 0.0 if continuous else time_step
    if visuals:
        plant, scene_graph = AddMultibodyPlantSceneGraph(builder, step)
    else:  # nothing to show, no collision geometry: no SceneGraph to keep posed at every step
        plant, scene_graph = builder.AddSystem(MultibodyPlant(step)), None
    if not continuous:
        plant.set_discrete_contact_approximation(DiscreteContactApproximation.kLagged)
    add_platform(plant, platform, visuals)
    if not gravity:
        plant.mutable_gravity_field().set_gravity_vector([0.0, 0.0, 0.0])
    plant.Finalize()
    return plant, scene_graph


def set_pose(plant, context, platform: Platform, pose, convention: str = "utn") -> None:
    """Set the plate to ``pose`` (6,) and every leg joint to the closed-form solution, in ``context``."""
    for _ in set_poses(plant, context, platform, np.asarray(pose, dtype=float).reshape(1, 6), convention):
        pass


def set_poses(plant, context, platform: Platform, poses, convention: str = "utn"):
    """For a loop over ``(n, 6)`` poses: set ``context`` to pose k as ``set_pose`` does, then yield k. The
    rotations and closed-form joint positions are computed for all poses at once (elementwise numpy: the same
    bits as pose by pose) and the joints looked up once."""
    poses = np.asarray(poses, dtype=float).reshape(-1, 6)
    R = rotation_matrix(poses[:, 3:], convention)
    angles, L = leg_joint_positions(platform, poses, convention)
    top = plant.GetBodyByName("top")
    universals = [plant.GetJointByName(f"universal_{i + 1}") for i in range(6)]
    prismatics = prismatic_joints(plant)
    for k in range(len(poses)):
        plant.SetFreeBodyPose(
            context, top, RigidTransform(RotationMatrix(R[k]), poses[k, :3] - R[k] @ platform.rotation_centre)
        )
        for i in range(6):
            universals[i].set_angles(context, angles[k, i])
            prismatics[i].set_translation(context, L[k, i])
        yield k


def prismatic_joints(plant) -> list:
    """The six ``prismatic_i`` joints of the plant, leg order (looked up once for a loop over samples)."""
    return [plant.GetJointByName(f"prismatic_{i + 1}") for i in range(6)]


def prismatic_positions(plant, context, joints=None) -> np.ndarray:
    """``(6,)`` the prismatic joint positions (leg lengths, metres) in ``context``; ``joints``: the plant's
    ``prismatic_joints`` when the caller already holds them."""
    return np.array([j.get_translation(context) for j in joints or prismatic_joints(plant)])
