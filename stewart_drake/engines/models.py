"""The platform's model for Pinocchio and MuJoCo, as text (numpy only: no engine is imported here).

Names follow the SDF model (``core.sdf_models``): ``base`` fixed at the world origin (W = B); ``top`` the
plate, a free body whose link frame is T (at the home pose, p_BT = home − rotation centre); leg i (1..6):
``cylinder_i`` on a universal joint at the base anchor whose zero-angle frame is ``leg_bodies.home_leg_frames``
(two revolute joints ``universal_i_1`` about x then ``universal_i_2`` about the new y: R = Rx(q0) Ry(q1), the
angles of ``leg_bodies.leg_joint_positions``), ``piston_i`` on the prismatic joint ``prismatic_i`` along z
whose position is the leg length (metres) and whose link origin is the piston tip. The six loop closures
put the piston tip on ``top_anchor_i`` (a ball joint: three constraint rows each).

- URDF (``urdf_text``): the open tree (a massless link ``universal_link_i`` between the two revolute joints,
  the plate on a ``floating`` joint from ``base`` at the home pose), fixed frames ``base_anchor_i`` and
  ``top_anchor_i``; the closures are in the YAML of ``closures_yaml`` (URDF cannot hold loops).
- MJCF (``mjcf_text``): the same bodies (the two universal angles are two hinges of ``cylinder_i``), the plate
  on a free joint, sites ``base_anchor_i``, ``piston_tip_i``, ``top_anchor_i``, the closures as ``connect``
  equalities between the tip and anchor sites, a motor per leg. The reference configuration (qpos0) is the home
  pose: slide joints carry ``ref`` = the home leg length, so qpos of ``prismatic_i`` is the leg length.

Numbers are written with 15 significant digits (``core.sdf.xml_vec``): a position of size ≤ 10 m is off by
at most 5e-15 × 10 m from the platform's.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import yaml

from stewart_drake.core.dynamics import G_EARTH
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.leg_bodies import home_leg_frames, leg_dimensions
from stewart_drake.core.sdf import cylinder_inertia, rpy, xml_attr, xml_comment, xml_vec
from stewart_drake.core.sdf_models import platform_model_name, platform_sdf
from stewart_drake.errors import OutputError
from stewart_drake.system.output_folder import check_output_file, safe_file_stem, write_output_file

FORMATS = ("sdf", "urdf", "mjcf")
# MuJoCo's connect constraints are soft: solref = (time constant s, damping ratio). Its default (0.02, 1) is
# stiff enough to hold a platform, and the cross-check measures what it costs (``mujoco_engine``).
MJCF_SOLREF = (0.02, 1.0)
MJCF_TIMESTEP = 1e-3  # s
MASSLESS = 1e-9  # kg (and kg·m²): the plate of a massless platform, as in the SDF


MASSLESS_PLATE = 1e-6  # kg: a massless platform's plate in the models (the SDF's placeholder)


def plate_inertial(platform: Platform) -> tuple[float, np.ndarray]:
    """The plate's mass (kg) and ``(3, 3)`` inertia about its centre of mass (kg·m²) as the models carry them
    (a massless platform gets the SDF's placeholder: 1e-6 kg, 1e-9 kg·m²)."""
    if platform.mass > 0:
        return float(platform.mass), np.asarray(platform.inertia, dtype=float)
    return MASSLESS_PLATE, np.eye(3) * MASSLESS


def modelled_platform(platform: Platform) -> Platform:
    """``platform`` with the plate the models carry (``plate_inertial``): what the engines' numbers are compared
    with."""
    if platform.mass > 0:
        return platform
    mass, inertia = plate_inertial(platform)
    return platform.replace(mass=mass, inertia=inertia)


def home_plate_origin(platform: Platform) -> np.ndarray:
    """``(3,)`` p_BT, the plate link's origin at the home pose (m)."""
    return platform.home_pose()[:3] - platform.rotation_centre


def _urdf_inertial(mass, com, I) -> str:
    return (
        f'<inertial><origin xyz="{xml_vec(*com)}" rpy="0 0 0"/><mass value="{xml_vec(mass)}"/>'
        f'<inertia ixx="{xml_vec(I[0, 0])}" ixy="{xml_vec(I[0, 1])}" ixz="{xml_vec(I[0, 2])}" '
        f'iyy="{xml_vec(I[1, 1])}" iyz="{xml_vec(I[1, 2])}" izz="{xml_vec(I[2, 2])}"/></inertial>'
    )


def _urdf_joint(name, kind, parent, child, xyz=(0, 0, 0), rpy_=(0, 0, 0), axis=None, limit=None) -> str:
    out = (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xml_vec(*xyz)}" rpy="{xml_vec(*rpy_)}"/>'
    )
    if axis is not None:
        out += f'<axis xyz="{xml_vec(*axis)}"/>'
    if limit is not None:
        lo, hi, effort = limit
        out += f'<limit lower="{xml_vec(lo)}" upper="{xml_vec(hi)}" effort="{xml_vec(effort)}" velocity="0"/>'
    return out + "</joint>"


def urdf_text(platform: Platform) -> str:
    """The URDF of the platform's open tree as a string (see the module docstring for its names); the loop
    closures that complete it are ``closures_yaml(platform)``."""
    dims = leg_dimensions(platform)
    legs = platform.legs
    R_BC = home_leg_frames(platform)
    cl, cr, pl, pr = dims["cylinder_length"], dims["cylinder_radius"], dims["piston_length"], dims["piston_radius"]
    mass, I = plate_inertial(platform)
    out = [
        '<?xml version="1.0"?>',
        f"<!-- Generated by stewart_drake.engines.models from platform {xml_comment(platform.name)}; do not edit."
        " The loop closures are in the companion YAML. -->",
        f'<robot name="{xml_attr(platform_model_name(platform))}">',
        f'<link name="base">{_urdf_inertial(1.0, (0, 0, 0), np.eye(3) * 0.01)}</link>',
        f'<link name="top">{_urdf_inertial(mass, platform.com, I)}</link>',
        _urdf_joint("top", "floating", "base", "top", home_plate_origin(platform)),
    ]
    for i in range(6):
        n = i + 1
        b, t = platform.base_anchors[i], platform.top_anchors_per_leg[i]
        out += [
            f'<link name="base_anchor_{n}"/>',
            _urdf_joint(f"base_anchor_{n}", "fixed", "base", f"base_anchor_{n}", b),
            f'<link name="top_anchor_{n}"/>',
            _urdf_joint(f"top_anchor_{n}", "fixed", "top", f"top_anchor_{n}", t),
            f'<link name="universal_link_{n}"/>',
            _urdf_joint(
                f"universal_{n}_1",
                "revolute",
                "base",
                f"universal_link_{n}",
                b,
                rpy(R_BC[i]),
                (1, 0, 0),
                (-np.pi, np.pi, 0),
            ),
            f'<link name="cylinder_{n}">'
            f"{_urdf_inertial(legs.cylinder_mass, (0, 0, cl / 2), cylinder_inertia(legs.cylinder_mass, cr, cl))}</link>",
            _urdf_joint(
                f"universal_{n}_2",
                "revolute",
                f"universal_link_{n}",
                f"cylinder_{n}",
                axis=(0, 1, 0),
                limit=(-np.pi, np.pi, 0),
            ),
            f'<link name="piston_{n}">'
            f"{_urdf_inertial(legs.piston_mass, (0, 0, -pl / 2), cylinder_inertia(legs.piston_mass, pr, pl))}</link>",
            _urdf_joint(
                f"prismatic_{n}",
                "prismatic",
                f"cylinder_{n}",
                f"piston_{n}",
                axis=(0, 0, 1),
                limit=(platform.L_min, platform.L_max, legs.max_force),
            ),
        ]
    out.append("</robot>")
    return "\n".join(out) + "\n"


def closures(platform: Platform) -> list[dict]:
    """The six loop closures: frame ``frame_a``'s point ``p_a`` coincides with frame ``frame_b``'s point ``p_b``
    (m, in those frames), a ball joint (three rows)."""
    return [
        {
            "name": f"leg_{i + 1}",
            "type": "ball",
            "frame_a": f"piston_{i + 1}",
            "p_a": [0.0, 0.0, 0.0],
            "frame_b": "top",
            "p_b": [float(x) for x in platform.top_anchors_per_leg[i]],
        }
        for i in range(6)
    ]


def closures_yaml(platform: Platform, urdf_name: str | None = None) -> str:
    """The loop closures of ``urdf_text(platform)`` as YAML text (``closures``; ``urdf_name`` recorded as ``urdf``)."""
    doc = {
        "model": platform_model_name(platform),
        "urdf": urdf_name or f"{platform_model_name(platform)}.urdf",
        "closures": closures(platform),
    }
    head = (
        "# Loop closures of the URDF's open tree (generated by stewart_drake.engines.models; do not edit):\n"
        "# each puts point p_a of link frame_a on point p_b of link frame_b (metres): a ball joint, 3 rows\n"
        "# (Pinocchio: RigidConstraintModel CONTACT_3D; MuJoCo: equality connect).\n"
    )
    return head + yaml.safe_dump(doc, sort_keys=False)


def _mj_inertial(mass, com, I) -> str:
    return (
        f'<inertial pos="{xml_vec(*com)}" mass="{xml_vec(mass)}" '
        f'fullinertia="{xml_vec(I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2])}"/>'
    )


def mjcf_text(
    platform: Platform, solref=MJCF_SOLREF, timestep: float = MJCF_TIMESTEP, integrator: str = "Euler"
) -> str:
    """The MJCF of the platform as a string (see the module docstring); ``solref`` = (time constant s, damping
    ratio) of the ``connect`` equalities, ``timestep`` (s) and ``integrator`` (MuJoCo's name: Euler, RK4,
    implicitfast) of its simulation."""
    dims = leg_dimensions(platform)
    legs = platform.legs
    R_BC = home_leg_frames(platform)
    L_home = leg_lengths(platform, platform.home_pose())
    cl, cr, pl, pr = dims["cylinder_length"], dims["cylinder_radius"], dims["piston_length"], dims["piston_radius"]
    mass, I = plate_inertial(platform)
    bodies, equalities, motors = [], [], []
    sites = "".join(
        f'<site name="base_anchor_{i + 1}" pos="{xml_vec(*b)}"/>' for i, b in enumerate(platform.base_anchors)
    )
    for i in range(6):
        n = i + 1
        bodies.append(
            f'<body name="cylinder_{n}" pos="{xml_vec(*platform.base_anchors[i])}" xyaxes="{xml_vec(*R_BC[i][:, 0], *R_BC[i][:, 1])}">'
            f'<joint name="universal_{n}_1" type="hinge" axis="1 0 0"/>'
            f'<joint name="universal_{n}_2" type="hinge" axis="0 1 0"/>'
            f"{_mj_inertial(legs.cylinder_mass, (0, 0, cl / 2), cylinder_inertia(legs.cylinder_mass, cr, cl))}"
            f'<geom type="capsule" fromto="0 0 0 0 0 {xml_vec(cl)}" size="{xml_vec(cr)}" contype="0" conaffinity="0"'
            ' mass="0" rgba="0.9 0.5 0.1 1"/>'
            f'<body name="piston_{n}" pos="0 0 {xml_vec(L_home[i])}">'
            f'<joint name="prismatic_{n}" type="slide" axis="0 0 1" ref="{xml_vec(L_home[i])}"/>'
            f"{_mj_inertial(legs.piston_mass, (0, 0, -pl / 2), cylinder_inertia(legs.piston_mass, pr, pl))}"
            f'<geom type="capsule" fromto="0 0 0 0 0 {xml_vec(-pl)}" size="{xml_vec(pr)}" contype="0"'
            ' conaffinity="0" mass="0" rgba="0.78 0.8 0.85 1"/>'
            f'<site name="piston_tip_{n}"/></body></body>'
        )
        equalities.append(
            f'<connect name="leg_{n}" site1="piston_tip_{n}" site2="top_anchor_{n}" solref="{xml_vec(*solref)}"/>'
        )
        motors.append(
            f'<motor name="leg_{n}" joint="prismatic_{n}" gear="1" forcerange="{xml_vec(-legs.max_force, legs.max_force)}"/>'
        )
    top_sites = "".join(
        f'<site name="top_anchor_{i + 1}" pos="{xml_vec(*t)}"/>' for i, t in enumerate(platform.top_anchors_per_leg)
    )
    return (
        "\n".join(
            [
                f"<!-- Generated by stewart_drake.engines.models from platform {xml_comment(platform.name)}; do not edit. -->",
                f'<mujoco model="{xml_attr(platform_model_name(platform))}">',
                '<compiler angle="radian" autolimits="true"/>',
                f'<option timestep="{xml_vec(timestep)}" integrator="{xml_attr(integrator)}" gravity="0 0 {xml_vec(-G_EARTH)}"/>',
                "<worldbody>",
                f'<body name="base">{_mj_inertial(1.0, (0, 0, 0), np.eye(3) * 0.01)}{sites}',
                *bodies,
                "</body>",
                f'<body name="top" pos="{xml_vec(*home_plate_origin(platform))}"><freejoint name="top"/>'
                f"{_mj_inertial(mass, platform.com, I)}{top_sites}</body>",
                "</worldbody>",
                "<equality>",
                *equalities,
                "</equality>",
                "<actuator>",
                *motors,
                "</actuator>",
                "</mujoco>",
            ]
        )
        + "\n"
    )


def model_files(platform: Platform, fmt: str) -> dict:
    """file name -> text of the platform's model in format ``fmt`` (``FORMATS``): ``<name>.sdf``; ``<name>.urdf``
    with ``<name>.closures.yaml``; ``<name>.xml`` (MJCF). ``<name>`` is the file-safe platform name."""
    stem = safe_file_stem(platform.name)
    if fmt == "sdf":
        return {f"{stem}.sdf": platform_sdf(platform)}
    if fmt == "urdf":
        return {f"{stem}.urdf": urdf_text(platform), f"{stem}.closures.yaml": closures_yaml(platform, f"{stem}.urdf")}
    if fmt == "mjcf":
        return {f"{stem}.xml": mjcf_text(platform)}
    raise ValueError(f"unknown model format {fmt!r}")  # internal: the CLI's choices are FORMATS


def write_models(platform: Platform, folder, fmt: str, *, option: str = "--write") -> list[Path]:
    """Write ``model_files(platform, fmt)`` into ``folder`` under the output-file policy of
    ``output_folder.write_output_file`` (a file the tool did not write is never replaced); every file is checked
    before the first is written. Returns the paths."""
    if os.path.exists(folder) and not os.path.isdir(folder):
        raise OutputError(OutputError.NOT_A_FOLDER.format(option=option, typed=folder, part=folder))
    files = model_files(platform, fmt)
    for name in files:
        check_output_file(os.path.join(folder, name), option=option)
    return [write_output_file(os.path.join(folder, name), text, option=option) for name, text in files.items()]
