"""The Drake model of a platform: SDF generated from a ``Platform``, and a closed-loop ``MultibodyPlant``.

The model (names are part of the API):
- ``base``: welded to the world at the origin (W = B). Frames ``base_anchor_i`` at p_BBi.
- ``top``: the plate, a free body whose link frame is T; frames ``top_anchor_i`` at p_TTi.
- leg i (1..6): ``cylinder_i`` on the universal joint ``universal_i`` at the base anchor, its z axis along
  the leg at the home pose; ``piston_i`` on the actuated prismatic joint ``prismatic_i`` along that z axis.
  The piston link origin is the piston tip, so **the prismatic position is the leg length** (metres);
  its limits are the stroke and its effort limit the actuator force.
- the loop closes with a Drake ball constraint between the piston tip and ``top_anchor_i``. Drake accepts
  these only on a discrete plant with a SAP contact approximation (see DESIGN.md).
Visuals only: the legs have no collision geometry.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from stewart_drake.core.output_folder import safe_file_stem, write_text_atomic
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_vectors
from stewart_drake.core.rotations import angles_from_matrix, rotation_matrix
from stewart_drake.drake.servo_model import xml_attr, xml_comment

SDF_DIR = Path(__file__).resolve().parents[2] / "sdf"
_F = "{:.15g}"


def _v(*xs) -> str:
    return " ".join(_F.format(float(x) + 0.0) for x in xs)


def _inertial(mass, com, I) -> str:
    return (
        f"<inertial><pose>{_v(*com, 0, 0, 0)}</pose><mass>{_v(mass)}</mass><inertia>"
        f"<ixx>{_v(I[0][0])}</ixx><ixy>{_v(I[0][1])}</ixy><ixz>{_v(I[0][2])}</ixz>"
        f"<iyy>{_v(I[1][1])}</iyy><iyz>{_v(I[1][2])}</iyz><izz>{_v(I[2][2])}</izz></inertia></inertial>"
    )


def _rod_inertia(mass, radius, length) -> np.ndarray:
    t = mass * (3 * radius**2 + length**2) / 12
    return np.diag([t, t, mass * radius**2 / 2])


def _visual(name, radius, length, z_centre, rgba) -> str:
    return (
        f'<visual name="{name}"><pose>{_v(0, 0, z_centre, 0, 0, 0)}</pose><geometry><cylinder>'
        f"<radius>{_v(radius)}</radius><length>{_v(length)}</length></cylinder></geometry>"
        f"<material><diffuse>{rgba}</diffuse></material></visual>"
    )


# Display colours (RGBA): a dark base, orange cylinders with steel pistons, black joints, a blue plate.
BASE_RGBA = "0.3 0.3 0.33 1"
CYLINDER_RGBA = "0.9 0.5 0.1 1"
PISTON_RGBA = "0.78 0.8 0.85 1"
JOINT_RGBA = "0.1 0.1 0.1 1"
PLATE_RGBA = "0.15 0.35 0.8 1"
VISUAL_NOTE = (
    "<!-- Visual geometry is for display only: the cylinder and piston visuals are sized to overlap over the"
    " whole stroke, joints are spheres and plates their anchor polygons. The <inertial> elements are what the"
    " dynamics uses (uniform rods of the configured cylinder length; the plate's given mass properties). -->"
)


def _sphere_visual(name, centre, radius, rgba) -> str:
    return (
        f'<visual name="{name}"><pose>{_v(*centre, 0, 0, 0)}</pose><geometry><sphere>'
        f"<radius>{_v(radius)}</radius></sphere></geometry><material><diffuse>{rgba}</diffuse></material></visual>"
    )


def _box_visual(name, centre, size, yaw, rgba) -> str:
    return (
        f'<visual name="{name}"><pose>{_v(*centre, 0, 0, yaw)}</pose><geometry><box>'
        f"<size>{_v(*size)}</size></box></geometry><material><diffuse>{rgba}</diffuse></material></visual>"
    )


def convex_outline(points) -> np.ndarray:
    """``(m, 2)`` the convex hull of ``(n, 2+)`` points' x, y, counter-clockwise (Andrew's monotone chain);
    coincident points (legs sharing a joint) count once."""
    pts = sorted({(round(float(x), 12), round(float(y), 12)) for x, y in np.asarray(points, dtype=float)[:, :2]})
    if len(pts) < 3:
        return np.array(pts, dtype=float).reshape(-1, 2)

    def half(seq):
        h = []
        for q in seq:
            while len(h) >= 2 and (h[-1][0] - h[-2][0]) * (q[1] - h[-2][1]) - (h[-1][1] - h[-2][1]) * (q[0] - h[-2][0]) <= 0:
                h.pop()
            h.append(q)
        return h[:-1]

    return np.array(half(pts) + half(pts[::-1]), dtype=float)


def _chord(hull: np.ndarray, y: float) -> tuple[float, float]:
    """The x interval of the convex polygon ``hull`` (m, 2) on the line at height ``y`` (inside it)."""
    a, b = hull, np.roll(hull, -1, axis=0)
    dy = b[:, 1] - a[:, 1]
    ok = (np.minimum(a[:, 1], b[:, 1]) <= y) & (y <= np.maximum(a[:, 1], b[:, 1])) & (np.abs(dy) > 1e-15)
    x = a[ok, 0] + (y - a[ok, 1]) / dy[ok] * (b[ok, 0] - a[ok, 0])
    return float(x.min()), float(x.max())


def plate_visuals(prefix: str, points, z: float, thickness: float, bar: float, rgba: str, strips: int = 32) -> list[str]:
    """Boxes drawing the convex polygon of ``points`` (n, 2+) as a plate ``thickness`` thick centred at
    height ``z``: ``strips`` slabs across it, each as wide as the polygon along its whole height (so it
    stays inside), and a bar ``bar`` wide along every edge covering the slabs' stepped ends.
    Fewer than three distinct points: no boxes."""
    hull = convex_outline(points)
    if len(hull) < 3:
        return []
    out = []
    y0, y1 = hull[:, 1].min(), hull[:, 1].max()
    edges = np.linspace(y0, y1, strips + 1)
    eps = 1e-9 * (y1 - y0)
    for k in range(strips):
        lo, hi = _chord(hull, edges[k] + eps), _chord(hull, edges[k + 1] - eps)
        xa, xb = max(lo[0], hi[0]), min(lo[1], hi[1])
        if xb - xa > bar:  # narrower slabs lie under the edge bars
            out.append(_box_visual(f"{prefix}_slab_{k}", ((xa + xb) / 2, (edges[k] + edges[k + 1]) / 2, z),
                                   (xb - xa, edges[k + 1] - edges[k], thickness), 0.0, rgba))
    for k, (a, b) in enumerate(zip(hull, np.roll(hull, -1, axis=0))):
        d = b - a
        out.append(_box_visual(f"{prefix}_edge_{k}", (*((a + b) / 2), z), (float(np.hypot(*d)) + bar, bar, thickness * 1.2),
                               float(np.arctan2(d[1], d[0])), rgba))
    return out


def leg_visual_dimensions(platform: Platform) -> dict:
    """Display lengths (metres) of each leg's cylinder and piston, and the joint sphere radius.

    The cylinder runs from the base joint up ``cylinder_length``; the piston from the top joint down
    ``piston_length``. They overlap at every leg length L in [L_min, L_max] when their sum exceeds
    L_max, and neither passes the far joint at L_min when each is at most L_min. Both are
    L_min/2 + L_max/4: the sum L_min + L_max/2 lies halfway between L_max and 2 L_min, leaving an
    overlap of (2 L_min − L_max)/2 at full extension. A stroke with L_max >= 2 L_min cannot satisfy
    both; there each is 0.55 L_max, keeping the overlap (the piston then shows below the base joint)."""
    lo, hi = platform.L_min, platform.L_max
    length = lo / 2 + hi / 4 if hi < 2 * lo else 0.55 * hi
    dims = leg_dimensions(platform)
    return {"cylinder_length": length, "piston_length": length, "cylinder_radius": dims["cylinder_radius"],
            "piston_radius": dims["piston_radius"], "joint_radius": 1.6 * dims["cylinder_radius"]}


def leg_dimensions(platform: Platform) -> dict:
    """Cylinder/piston radii and lengths (metres), the YAML values or their defaults."""
    legs = platform.legs
    cl = legs.cylinder_length or platform.L_min / 2
    cr = legs.cylinder_radius or platform.L_min / 40
    pr = legs.piston_radius or 0.6 * cr
    return {"cylinder_length": cl, "cylinder_radius": cr, "piston_length": cl, "piston_radius": pr}


def home_leg_frames(platform: Platform) -> np.ndarray:
    """``(6, 3, 3)`` R_BCi: each cylinder's zero-angle frame; z along the leg at the home pose, x horizontal."""
    u = leg_vectors(platform, platform.home_pose())
    z = u / np.linalg.norm(u, axis=-1, keepdims=True)
    x = np.cross([0.0, 0.0, 1.0], z)
    n = np.linalg.norm(x, axis=-1, keepdims=True)
    x = np.where(n > 1e-9, x / np.where(n > 1e-9, n, 1.0), [1.0, 0.0, 0.0])
    y = np.cross(z, x)
    return np.stack([x, y, z], axis=-1)


def _rpy(R) -> tuple:
    """Roll-pitch-yaw (SDF pose order) of a 3x3 rotation matrix, via our ``zyx`` convention."""
    return tuple(angles_from_matrix(R, "zyx"))


def _body_visuals(platform: Platform) -> tuple[str, str]:
    """The base's and the plate's visual elements: each a plate over its anchor polygon (the base's
    just below its anchors) and a sphere on every joint."""
    vis = leg_visual_dimensions(platform)
    rj = vis["joint_radius"]
    base_z, top_z = float(platform.base_anchors[:, 2].min()), float(platform.top_anchors[:, 2].mean())
    base = plate_visuals("base_plate", platform.base_anchors, base_z - rj, rj, rj, BASE_RGBA)
    base += [_sphere_visual(f"base_joint_{i + 1}", b, rj, JOINT_RGBA) for i, b in enumerate(platform.base_anchors)]
    top = plate_visuals("top_plate", platform.top_anchors, top_z, rj, rj, PLATE_RGBA)
    top += [_sphere_visual(f"top_joint_{j + 1}", t, rj, JOINT_RGBA) for j, t in enumerate(platform.top_anchors)]
    return "".join(base), "".join(top)


def sdf_text(platform: Platform) -> str:
    """The SDF (1.9) model of ``platform`` as a string, deterministic for a given platform."""
    dims = leg_dimensions(platform)
    legs = platform.legs
    R_BC = home_leg_frames(platform)
    home = platform.home_pose()
    p_BT = home[:3] - platform.rotation_centre
    base_visuals, top_visuals = _body_visuals(platform)
    out = [
        '<?xml version="1.0"?>',
        f"<!-- Generated by stewart_drake.drake.platform_model from platform {xml_comment(repr(platform.name))}; do not edit. -->",
        '<sdf version="1.9">',
        f'<model name="{xml_attr(model_name(platform))}">',
        f'<link name="base">{_inertial(1.0, (0, 0, 0), np.eye(3) * 0.01)}'
        f"{base_visuals}</link>",
        '<joint name="base_weld" type="fixed"><parent>world</parent><child>base</child></joint>',
        f'<link name="top"><pose relative_to="base">{_v(*p_BT, 0, 0, 0)}</pose>'
        f"{_inertial(max(platform.mass, 1e-6), platform.com, platform.inertia if platform.mass > 0 else np.eye(3) * 1e-9)}"
        f"{top_visuals}</link>",
    ]
    for i in range(6):
        n = i + 1
        b = platform.base_anchors[i]
        t = platform.top_anchors_per_leg[i]
        rpy = _rpy(R_BC[i])
        out.append(f'<frame name="base_anchor_{n}" attached_to="base"><pose relative_to="base">{_v(*b, 0, 0, 0)}</pose></frame>')
        out.append(f'<frame name="top_anchor_{n}" attached_to="top"><pose relative_to="top">{_v(*t, 0, 0, 0)}</pose></frame>')
        cl, cr = dims["cylinder_length"], dims["cylinder_radius"]
        pl, pr = dims["piston_length"], dims["piston_radius"]
        vis = leg_visual_dimensions(platform)
        out.append(
            f'<link name="cylinder_{n}"><pose relative_to="base">{_v(*b, *rpy)}</pose>'
            f"{_inertial(legs.cylinder_mass, (0, 0, cl / 2), _rod_inertia(legs.cylinder_mass, cr, cl))}"
            f"{_visual('body', cr, vis['cylinder_length'], vis['cylinder_length'] / 2, CYLINDER_RGBA)}</link>"
        )
        out.append(
            f'<joint name="universal_{n}" type="universal"><parent>base</parent><child>cylinder_{n}</child>'
            "<axis><xyz>1 0 0</xyz><limit><effort>0</effort></limit></axis>"
            "<axis2><xyz>0 1 0</xyz><limit><effort>0</effort></limit></axis2></joint>"
        )
        # The piston's link origin is its tip; at prismatic position q it lies q along the cylinder axis
        # (the model's zero configuration has the tip on the base anchor; add_platform sets the defaults).
        out.append(
            f'<link name="piston_{n}"><pose relative_to="cylinder_{n}">0 0 0 0 0 0</pose>'
            f"{_inertial(legs.piston_mass, (0, 0, -pl / 2), _rod_inertia(legs.piston_mass, pr, pl))}"
            f"{_visual('rod', pr, vis['piston_length'], -vis['piston_length'] / 2, PISTON_RGBA)}</link>"
        )
        out.append(
            f'<joint name="prismatic_{n}" type="prismatic"><parent>cylinder_{n}</parent><child>piston_{n}</child>'
            f'<pose relative_to="cylinder_{n}">0 0 0 0 0 0</pose>'
            f"<axis><xyz>0 0 1</xyz><limit><lower>{_v(platform.L_min)}</lower><upper>{_v(platform.L_max)}</upper>"
            f"<effort>{_v(legs.max_force)}</effort></limit></axis></joint>"
        )
        out.append(
            "<drake:ball_constraint>"
            f"<drake:ball_constraint_body_A>piston_{n}</drake:ball_constraint_body_A>"
            "<drake:ball_constraint_body_B>top</drake:ball_constraint_body_B>"
            "<drake:ball_constraint_p_AP>0 0 0</drake:ball_constraint_p_AP>"
            f"<drake:ball_constraint_p_BQ>{_v(*t)}</drake:ball_constraint_p_BQ>"
            "</drake:ball_constraint>"
        )
    out += [VISUAL_NOTE, "</model>", "</sdf>", ""]
    return "\n".join(out)


def model_name(platform: Platform) -> str:
    """The Drake model instance name of ``platform``: its name reduced to letters, digits and ``._+-``
    (``atomic.safe_file_stem``; Drake refuses "::" and blank names), "platform" if nothing is left.
    The presets' names are unchanged by this."""
    return safe_file_stem(platform.name, "platform")


def sdf_path(name: str, directory=SDF_DIR) -> Path:
    """Where the SDF of a platform called ``name`` goes in ``directory``: a file name derived safely
    from the name (``atomic.safe_file_stem``), always directly inside ``directory``."""
    return Path(directory) / f"{safe_file_stem(name)}.sdf"


def write_sdf(platform: Platform, directory=SDF_DIR) -> Path:
    """Write ``<directory>/<safe name>.sdf`` (atomically) and return its path."""
    path = sdf_path(platform.name, directory)
    return write_text_atomic(path, sdf_text(platform))


def add_platform(plant, platform: Platform):
    """Parse the platform's SDF into ``plant`` (not finalized); return the model instance."""
    from pydrake.multibody.parsing import Parser

    (instance,) = Parser(plant).AddModelsFromString(sdf_text(platform), "sdf")
    _, L_home = leg_joint_positions(platform, platform.home_pose())
    for i in range(6):
        plant.GetJointByName(f"prismatic_{i + 1}", instance).set_default_translation(L_home[i])
    return instance


def build_plant(platform: Platform, time_step: float = 1e-3, builder=None, gravity: bool = True, continuous: bool = False):
    """A finalized closed-loop ``MultibodyPlant`` of ``platform`` and its ``SceneGraph``, added to
    ``builder`` (a new ``DiagramBuilder`` if None). Discrete (SAP) with ``time_step`` > 0 by default: Drake's
    ball constraints need a discrete plant, except under the CENIC integrator (``continuous=True``: a
    continuous plant, time_step 0, for a Simulator configured with ``integration_scheme="cenic"``)."""
    from pydrake.multibody.plant import AddMultibodyPlantSceneGraph, DiscreteContactApproximation
    from pydrake.systems.framework import DiagramBuilder

    if not (continuous or time_step > 0):
        raise ValueError(f"time_step must be > 0 (ball constraints need a discrete plant), got {time_step}")
    builder = builder or DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, 0.0 if continuous else time_step)
    if not continuous:
        plant.set_discrete_contact_approximation(DiscreteContactApproximation.kLagged)
    add_platform(plant, platform)
    if not gravity:
        plant.mutable_gravity_field().set_gravity_vector([0.0, 0.0, 0.0])
    plant.Finalize()
    return plant, scene_graph


def leg_joint_positions(platform: Platform, poses, convention: str = "utn") -> tuple[np.ndarray, np.ndarray]:
    """Closed-form joint positions for ``(..., 6)`` poses: universal angles ``(..., 6, 2)`` (radians)
    and prismatic positions ``(..., 6)`` (= leg lengths, metres)."""
    l = leg_vectors(platform, poses, convention)
    L = np.linalg.norm(l, axis=-1)
    d = np.einsum("ikj,...ik->...ij", home_leg_frames(platform), l / L[..., None])  # direction in C_i
    # Drake's UniversalJoint: R_FM = Rx(q0) Ry(q1), so z_M = [sin q1, -sin q0 cos q1, cos q0 cos q1].
    q1 = np.arcsin(np.clip(d[..., 0], -1.0, 1.0))
    q0 = np.arctan2(-d[..., 1], d[..., 2])
    return np.stack([q0, q1], axis=-1), L


def set_pose(plant, context, platform: Platform, pose, convention: str = "utn") -> None:
    """Set the plate to ``pose`` (6,) and every leg joint to the closed-form solution, in ``context``."""
    from pydrake.math import RigidTransform, RotationMatrix

    pose = np.asarray(pose, dtype=float).reshape(6)
    R = rotation_matrix(pose[3:], convention)
    p_WT = pose[:3] - R @ platform.rotation_centre
    top = plant.GetBodyByName("top")
    plant.SetFreeBodyPose(context, top, RigidTransform(RotationMatrix(R), p_WT))
    angles, L = leg_joint_positions(platform, pose, convention)
    for i in range(6):
        plant.GetJointByName(f"universal_{i + 1}").set_angles(context, angles[i])
        plant.GetJointByName(f"prismatic_{i + 1}").set_translation(context, L[i])


def prismatic_positions(plant, context) -> np.ndarray:
    """``(6,)`` the prismatic joint positions (leg lengths, metres) in ``context``."""
    return np.array([plant.GetJointByName(f"prismatic_{i + 1}").get_translation(context) for i in range(6)])
