"""The generated Drake model of a platform, inspected: ``inspect_model`` parses the platform's SDF into a
MultibodyPlant and lists its bodies, joints and actuators, with the anchors' distance from the geometry's.

Imports pydrake (through ``drake.verify_kinematics``): ``import stewart_drake`` loads this module on first use
of ``inspect_model``."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from stewart_drake.api.platform import load_platform
from stewart_drake.api.result import Result
from stewart_drake.core.argcheck import check_path, param
from stewart_drake.core.geometry import Platform
from stewart_drake.core.sdf_models import platform_model_name
from stewart_drake.core.sdf_models import write_sdf as write_sdf_file
from stewart_drake.drake.verify_kinematics import anchor_frames, make_plant

__all__ = ["inspect_model", "ModelInspection"]


@dataclass(repr=False)
class ModelInspection(Result):
    """The platform's Drake model as parsed (``inspect_model``). ``to_dict()`` is ``stewart-drake model
    --inspect --json`` (already SI: ``time_step_s``, ``anchor_error_m``).

    Attributes:
        platform: the platform's name.
        bodies: the bodies of the platform's model instance.
        joints: joint name -> Drake joint type, over the whole plant.
        actuators: the joint actuators (one per leg's prismatic joint).
        num_positions: the plant's generalized positions.
        num_velocities: the plant's generalized velocities.
        constraints: the plant's constraints (the closed kinematic loops).
        time_step: the plant's discrete time step, s (0: continuous).
        anchor_error: the largest distance between a joint anchor of the parsed model and the platform's, m.
        sdf_file: the SDF written (``write``), else None.
    """

    platform: str
    bodies: list
    joints: dict
    actuators: list
    num_positions: int
    num_velocities: int
    constraints: int
    time_step: float
    anchor_error: float
    sdf_file: Path | None = None

    @property
    def ok(self) -> bool:
        """The parsed anchors agree with the platform's to 1 µm (the SDF writes them to the nanometre)."""
        return self.anchor_error <= 1e-6

    def _fields(self) -> dict:
        out = {
            "platform": self.platform,
            "bodies": self.bodies,
            "joints": self.joints,
            "actuators": self.actuators,
            "num_positions": self.num_positions,
            "num_velocities": self.num_velocities,
            "constraints": self.constraints,
            "time_step_s": self.time_step,
        }
        if self.sdf_file is not None:
            out["sdf_file"] = str(self.sdf_file)
        out["anchor_error_m"] = self.anchor_error
        return out


def inspect_model(platform: Platform | str | Path, *, write: str | Path | None = None) -> ModelInspection:
    """Parse the platform's generated SDF into a Drake MultibodyPlant and list what it holds.

    Args:
        platform: a ``Platform``, a preset name or a platform YAML file.
        write: also write ``<write>/<name>.sdf`` (a file stewart-drake did not write is never replaced).

    Returns:
        The model's bodies, joints, actuators, sizes and the anchors' error against the platform.

    Raises:
        StewartError: an unknown platform, a folder that cannot be written.
    """
    platform = load_platform(platform)
    sdf_file = (
        None if write is None else write_sdf_file(platform, check_path(write, param("write")), option=param("write"))
    )
    h = make_plant(platform)
    plant = h.plant
    instance = plant.GetModelInstanceByName(platform_model_name(platform))
    base, top = anchor_frames(h)
    return ModelInspection(
        platform.name,
        [plant.get_body(b).name() for b in plant.GetBodyIndices(instance)],
        {plant.get_joint(j).name(): plant.get_joint(j).type_name() for j in plant.GetJointIndices()},
        [plant.get_joint_actuator(a).name() for a in plant.GetJointActuatorIndices()],
        plant.num_positions(),
        plant.num_velocities(),
        plant.num_constraints(),
        plant.time_step(),
        float(max(abs(base - platform.base_anchors).max(), abs(top - platform.top_anchors_per_leg).max())),
        sdf_file,
    )
