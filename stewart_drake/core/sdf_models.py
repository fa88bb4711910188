"""The generated SDF models: a Stewart platform, the RC-servo hexapod and the 3R planar leg.

Each ``*_sdf`` function returns the whole file as a string, deterministic for its input, written with
the one SDF writer ``core/sdf.py``. Drake parses these strings (``drake/platform_model``,
``drake/servo_model``, ``drake/leg_model``); the commands write them where the user asks (nothing has a
default folder). Names of links, joints and frames are part of the API:

- platform: ``base`` welded to the world at the origin (W = B), frames ``base_anchor_i`` at p_BBi;
  ``top`` the plate, a free body whose link frame is T, frames ``top_anchor_i`` at p_TTi; leg i (1..6):
  ``cylinder_i`` on the universal joint ``universal_i`` at the base anchor, its z axis along the leg at
  the home pose (``leg_bodies.home_leg_frames``); ``piston_i`` on the actuated prismatic joint
  ``prismatic_i`` along that axis. The piston link origin is the piston tip, so the prismatic position
  is the leg length (metres); its limits are the stroke and its effort limit the actuator force. A Drake
  ball constraint closes the piston tip onto ``top_anchor_i`` (Drake accepts these only on a discrete
  plant with a SAP contact approximation). Visuals only: the legs have no collision geometry.
- servo hexapod: ``base`` welded to the world; ``platform`` a free body at the home height; frames
  ``pivot_i`` (base) and ``platform_anchor_i``; ``arm_i`` on the actuated revolute joint ``servo_i``
  (``servo_mounting``: the joint angle is the servo's mechanical angle; limits ±travel about home,
  effort the stall torque); frame ``arm_tip_i`` at (a, 0, 0); ``rod_i`` on the ball joint ``rod_joint_i``
  at the arm tip, a ball constraint closing its end (0, 0, s) onto ``platform_anchor_i``.
- 3R leg: ``hip_mount`` welded to the world with the DH base frame 0 mapped as x0 = world x, y0 = world
  z (up), z0 = -world y, at ``HIP_HEIGHT``; frame ``dh_0`` on it. For DH row i the link (``thigh``,
  ``shank``, ``foot``) is posed at frame ``dh_{i-1}`` rotated by the row's theta offset about z, on a
  revolute joint (``hip``, ``knee``: angle = q_i, limits = the joint limits) or a fixed joint
  (``ankle``); frame ``dh_i`` on it at T(0,0,d)·T(a,0,0)·Rotx(alpha_DH). ``dh_3`` is the foot tip.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from stewart_drake.core.geometry import Platform, base_joints
from stewart_drake.core.leg_bodies import home_leg_frames, leg_dimensions, leg_visual_dimensions
from stewart_drake.core.sdf import (
    ball_constraint_xml,
    box_inertia,
    cylinder_inertia,
    document,
    inertial_xml,
    rpy,
    visual_xml,
    xml_vec,
)
from stewart_drake.errors import OutputError
from stewart_drake.mechanisms.leg3r import Leg3R, dh_rows
from stewart_drake.mechanisms.servo import ServoHexapod
from stewart_drake.mechanisms.servo_mounting import pivot_frames, rod_frames, servo_joint_home
from stewart_drake.system.output_folder import safe_file_stem, write_output_file

# ----------------------------------------------------------------------------------------------
# Stewart platform

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


def convex_outline(points) -> np.ndarray:
    """``(m, 2)`` the convex hull of ``(n, 2+)`` points' x, y, counter-clockwise (Andrew's monotone chain).
    x, y are rounded to 1e-12 m (far below display precision) and equal points count once; which anchors
    are one joint is decided by the caller (``geometry.base_joints``)."""
    pts = sorted({(round(float(x), 12), round(float(y), 12)) for x, y in np.asarray(points, dtype=float)[:, :2]})
    if len(pts) < 3:
        return np.array(pts, dtype=float).reshape(-1, 2)

    def half(seq):
        h = []
        for q in seq:
            while (
                len(h) >= 2
                and (h[-1][0] - h[-2][0]) * (q[1] - h[-2][1]) - (h[-1][1] - h[-2][1]) * (q[0] - h[-2][0]) <= 0
            ):
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


def _box(name, centre, size, yaw, rgba) -> str:
    return visual_xml(name, (*centre, 0, 0, yaw), ("box", size), rgba)


def plate_visuals(
    prefix: str, points, z: float, thickness: float, bar: float, rgba: str, strips: int = 32
) -> list[str]:
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
            out.append(
                _box(
                    f"{prefix}_slab_{k}",
                    ((xa + xb) / 2, (edges[k] + edges[k + 1]) / 2, z),
                    (xb - xa, edges[k + 1] - edges[k], thickness),
                    0.0,
                    rgba,
                )
            )
    for k, (a, b) in enumerate(zip(hull, np.roll(hull, -1, axis=0))):
        d = b - a
        out.append(
            _box(
                f"{prefix}_edge_{k}",
                (*((a + b) / 2), z),
                (float(np.hypot(*d)) + bar, bar, thickness * 1.2),
                float(np.arctan2(d[1], d[0])),
                rgba,
            )
        )
    return out


def _body_visuals(platform: Platform) -> tuple[str, str]:
    """The base's and the plate's visual elements: each a plate over its anchor polygon (the base's
    just below its anchors) and a sphere on every joint."""
    vis = leg_visual_dimensions(platform)
    rj = vis["joint_radius"]
    base_z, top_z = float(platform.base_anchors[:, 2].min()), float(platform.top_anchors[:, 2].mean())
    joints = platform.base_anchors[base_joints(platform)[0]]
    base = plate_visuals("base_plate", joints, base_z - rj, rj, rj, BASE_RGBA)
    base += [
        visual_xml(f"base_joint_{i + 1}", (*b, 0, 0, 0), ("sphere", rj), JOINT_RGBA)
        for i, b in enumerate(platform.base_anchors)
    ]
    top = plate_visuals("top_plate", platform.top_anchors, top_z, rj, rj, PLATE_RGBA)
    top += [
        visual_xml(f"top_joint_{j + 1}", (*t, 0, 0, 0), ("sphere", rj), JOINT_RGBA)
        for j, t in enumerate(platform.top_anchors)
    ]
    return "".join(base), "".join(top)


def platform_model_name(platform: Platform) -> str:
    """The Drake model instance name of ``platform``: its name reduced to letters, digits and ``._+-``
    (``output_folder.safe_file_stem``; Drake refuses "::" and blank names), "platform" if nothing is
    left. The presets' names are unchanged by this."""
    return safe_file_stem(platform.name, "platform")


def platform_sdf(platform: Platform, visuals: bool = True) -> str:
    """The SDF model of ``platform`` as a string (see the module docstring for its names). ``visuals=False``:
    without the visual elements (display only: the same bodies, joints, inertias and constraints), for a plant
    nobody looks at — Drake parses it ~7× faster (a Monte Carlo run's perturbed plant)."""
    dims = leg_dimensions(platform)
    vis = leg_visual_dimensions(platform)
    legs = platform.legs
    R_BC = home_leg_frames(platform)
    p_BT = platform.home_pose()[:3] - platform.rotation_centre
    base_visuals, top_visuals = _body_visuals(platform) if visuals else ("", "")
    top_inertia = platform.inertia if platform.mass > 0 else np.eye(3) * 1e-9
    out = [
        f'<link name="base">{inertial_xml(1.0, (0, 0, 0), np.eye(3) * 0.01)}{base_visuals}</link>',
        '<joint name="base_weld" type="fixed"><parent>world</parent><child>base</child></joint>',
        f'<link name="top"><pose relative_to="base">{xml_vec(*p_BT, 0, 0, 0)}</pose>'
        f"{inertial_xml(max(platform.mass, 1e-6), platform.com, top_inertia)}{top_visuals}</link>",
    ]
    cl, cr = dims["cylinder_length"], dims["cylinder_radius"]
    pl, pr = dims["piston_length"], dims["piston_radius"]
    for i in range(6):
        n = i + 1
        b = platform.base_anchors[i]
        t = platform.top_anchors_per_leg[i]
        out.append(
            f'<frame name="base_anchor_{n}" attached_to="base"><pose relative_to="base">{xml_vec(*b, 0, 0, 0)}</pose></frame>'
        )
        out.append(
            f'<frame name="top_anchor_{n}" attached_to="top"><pose relative_to="top">{xml_vec(*t, 0, 0, 0)}</pose></frame>'
        )
        out.append(
            f'<link name="cylinder_{n}"><pose relative_to="base">{xml_vec(*b, *rpy(R_BC[i]))}</pose>'
            f"{inertial_xml(legs.cylinder_mass, (0, 0, cl / 2), cylinder_inertia(legs.cylinder_mass, cr, cl))}"
            f"{visual_xml('body', (0, 0, vis['cylinder_length'] / 2, 0, 0, 0), ('cylinder', (cr, vis['cylinder_length'])), CYLINDER_RGBA) if visuals else ''}"
            "</link>"
        )
        out.append(
            f'<joint name="universal_{n}" type="universal"><parent>base</parent><child>cylinder_{n}</child>'
            "<axis><xyz>1 0 0</xyz><limit><effort>0</effort></limit></axis>"
            "<axis2><xyz>0 1 0</xyz><limit><effort>0</effort></limit></axis2></joint>"
        )
        # The piston's link origin is its tip; at prismatic position q it lies q along the cylinder axis
        # (the model's zero configuration has the tip on the base anchor; the plant sets the defaults).
        out.append(
            f'<link name="piston_{n}"><pose relative_to="cylinder_{n}">0 0 0 0 0 0</pose>'
            f"{inertial_xml(legs.piston_mass, (0, 0, -pl / 2), cylinder_inertia(legs.piston_mass, pr, pl))}"
            f"{visual_xml('rod', (0, 0, -vis['piston_length'] / 2, 0, 0, 0), ('cylinder', (pr, vis['piston_length'])), PISTON_RGBA) if visuals else ''}"
            "</link>"
        )
        out.append(
            f'<joint name="prismatic_{n}" type="prismatic"><parent>cylinder_{n}</parent><child>piston_{n}</child>'
            f'<pose relative_to="cylinder_{n}">0 0 0 0 0 0</pose>'
            f"<axis><xyz>0 0 1</xyz><limit><lower>{xml_vec(platform.L_min)}</lower><upper>{xml_vec(platform.L_max)}</upper>"
            f"<effort>{xml_vec(legs.max_force)}</effort></limit></axis></joint>"
        )
        out.append(ball_constraint_xml(f"piston_{n}", (0, 0, 0), "top", t))
    if visuals:
        out.append(VISUAL_NOTE)
    return document(f"platform {platform.name!r}", platform_model_name(platform), out)


# ----------------------------------------------------------------------------------------------
# RC-servo hexapod (seed 002)

SERVO_HEXAPOD_MODEL = "servo-hexapod"


def servo_hexapod_sdf(hexapod: ServoHexapod) -> str:
    """The SDF model of the servo hexapod as a string (see the module docstring for its names)."""
    a, s, h0 = hexapod.arm_length, hexapod.rod_length, hexapod.home_height
    R_piv, R_rod = pivot_frames(hexapod), rod_frames(hexapod)
    r_plate = float(np.max(np.linalg.norm(hexapod.platform_anchors[:, :2], axis=1))) * 1.15
    r_base = float(np.max(np.linalg.norm(hexapod.base_pivots[:, :2], axis=1))) * 1.2
    mp = hexapod.platform_mass
    plate_t = 0.005
    I_plate = np.diag([mp * (3 * r_plate**2 + plate_t**2) / 12] * 2 + [mp * r_plate**2 / 2])
    arm_w, rod_r = 0.006, 0.0015
    home = servo_joint_home(hexapod)
    out = [
        f'<link name="base">{inertial_xml(1.0, (0, 0, 0), np.eye(3) * 0.01)}'
        f"{visual_xml('base_plate', (0, 0, -0.003, 0, 0, 0), ('cylinder', (r_base, 0.006)), '0.6 0.6 0.6 1')}</link>",
        '<joint name="base_weld" type="fixed"><parent>world</parent><child>base</child></joint>',
        f'<link name="platform"><pose relative_to="base">{xml_vec(0, 0, h0, 0, 0, 0)}</pose>'
        f"{inertial_xml(mp, (0, 0, 0), I_plate)}"
        f"{visual_xml('plate', (0, 0, plate_t / 2, 0, 0, 0), ('cylinder', (r_plate, plate_t)), '0.2 0.4 0.8 1')}</link>",
    ]
    lo, hi = home - hexapod.travel_rad, home + hexapod.travel_rad
    for i in range(6):
        n = i + 1
        b, p = hexapod.base_pivots[i], hexapod.platform_anchors[i]
        tip = b + a * R_piv[i][:, 0]  # arm tip at zero joint angle
        out.append(
            f'<frame name="pivot_{n}" attached_to="base"><pose relative_to="base">{xml_vec(*b, *rpy(R_piv[i]))}</pose></frame>'
        )
        out.append(
            f'<frame name="platform_anchor_{n}" attached_to="platform"><pose relative_to="platform">{xml_vec(*p, 0, 0, 0)}</pose></frame>'
        )
        out.append(
            f'<link name="arm_{n}"><pose relative_to="pivot_{n}">0 0 0 0 0 0</pose>'
            f"{inertial_xml(hexapod.arm_mass, (a / 2, 0, 0), box_inertia(hexapod.arm_mass, (a, arm_w, 0.003)))}"
            f"{visual_xml('horn', (a / 2, 0, 0, 0, 0, 0), ('box', (a + arm_w, arm_w, 0.003)), '0.9 0.9 0.9 1')}</link>"
        )
        out.append(
            f'<joint name="servo_{n}" type="revolute"><parent>base</parent><child>arm_{n}</child>'
            f"<axis><xyz>0 0 1</xyz><limit><lower>{xml_vec(lo[i])}</lower><upper>{xml_vec(hi[i])}</upper>"
            f"<effort>{xml_vec(hexapod.servo_torque)}</effort></limit></axis></joint>"
        )
        out.append(
            f'<frame name="arm_tip_{n}" attached_to="arm_{n}"><pose relative_to="arm_{n}">{xml_vec(a, 0, 0, 0, 0, 0)}</pose></frame>'
        )
        out.append(
            f'<link name="rod_{n}"><pose relative_to="base">{xml_vec(*tip, *rpy(R_rod[i]))}</pose>'
            f"{inertial_xml(hexapod.rod_mass, (0, 0, s / 2), cylinder_inertia(hexapod.rod_mass, rod_r, s))}"
            f"{visual_xml('rod', (0, 0, s / 2, 0, 0, 0), ('cylinder', (rod_r, s)), '0.8 0.5 0.2 1')}</link>"
        )
        out.append(f'<joint name="rod_joint_{n}" type="ball"><parent>arm_{n}</parent><child>rod_{n}</child></joint>')
        out.append(ball_constraint_xml(f"rod_{n}", (0, 0, s), "platform", p))
    return document(f"servo hexapod {hexapod.name!r}", SERVO_HEXAPOD_MODEL, out)


# ----------------------------------------------------------------------------------------------
# 3R planar leg (seed 003)

LEG_MODEL = "leg-3r"
HIP_HEIGHT = 0.25  # m, above the world origin
LINK_MASS = 0.05  # kg per link (Drake model only)
LINK_RADIUS = 0.006  # m, visual and inertia
JOINT_TORQUE = 1.0  # N·m, servo stall torque


def leg_sdf(leg: Leg3R) -> str:
    """The SDF model of ``leg`` generated row by row from its DH table (see the module docstring)."""
    limits = [leg.q1_limits, leg.q2_limits]
    out = [
        f'<link name="hip_mount"><pose>{xml_vec(0, 0, HIP_HEIGHT, np.pi / 2, 0, 0)}</pose>'
        f"{inertial_xml(0.5, (0, 0, 0), np.eye(3) * 1e-3)}"
        f"{visual_xml('mount', (0, 0, 0, 0, 0, 0), ('cylinder', (2 * LINK_RADIUS, 4 * LINK_RADIUS)), '0.6 0.6 0.6 1')}</link>",
        '<joint name="mount_weld" type="fixed"><parent>world</parent><child>hip_mount</child></joint>',
        '<frame name="dh_0" attached_to="hip_mount"><pose relative_to="hip_mount">0 0 0 0 0 0</pose></frame>',
    ]
    parent, k = "hip_mount", 0
    for i, row in enumerate(dh_rows(leg), start=1):
        a = row["a"]
        com = (a / 2, 0, row["d"])
        I = cylinder_inertia(LINK_MASS, LINK_RADIUS, a)[[2, 0, 1]][:, [2, 0, 1]]  # the rod lies along x
        out.append(
            f'<link name="{row["link"]}"><pose relative_to="dh_{i - 1}">{xml_vec(0, 0, 0, 0, 0, row["theta"])}</pose>'
            f"{inertial_xml(LINK_MASS, com, I)}"
            f"{visual_xml('rod', (a / 2, 0, row['d'], 0, np.pi / 2, 0), ('cylinder', (LINK_RADIUS, a)), '0.8 0.5 0.2 1')}</link>"
        )
        if row["kind"] == "revolute":
            lo, hi = limits[k]
            k += 1
            out.append(
                f'<joint name="{row["joint"]}" type="revolute"><parent>{parent}</parent><child>{row["link"]}</child>'
                f"<axis><xyz>0 0 1</xyz><limit><lower>{xml_vec(lo)}</lower><upper>{xml_vec(hi)}</upper>"
                f"<effort>{xml_vec(JOINT_TORQUE)}</effort></limit></axis></joint>"
            )
        else:
            out.append(
                f'<joint name="{row["joint"]}" type="fixed"><parent>{parent}</parent><child>{row["link"]}</child></joint>'
            )
        out.append(
            f'<frame name="dh_{i}" attached_to="{row["link"]}"><pose relative_to="{row["link"]}">'
            f"{xml_vec(a, 0, row['d'], row['alpha'], 0, 0)}</pose></frame>"
        )
        parent = row["link"]
    return document(f"leg {leg.name!r} (DH table of seed 003)", LEG_MODEL, out)


# ----------------------------------------------------------------------------------------------
# Any of the three


def sdf_text(model: Platform | ServoHexapod | Leg3R) -> str:
    """The SDF text of a platform, a servo hexapod or a 3R leg."""
    if isinstance(model, Platform):
        return platform_sdf(model)
    if isinstance(model, ServoHexapod):
        return servo_hexapod_sdf(model)
    if isinstance(model, Leg3R):
        return leg_sdf(model)
    raise TypeError(f"no SDF model for a {type(model).__name__}; expected a Platform, ServoHexapod or Leg3R")


def sdf_file_name(model: Platform | ServoHexapod | Leg3R) -> str:
    """The file name of ``model``'s SDF: ``<safe platform name>.sdf`` (``output_folder.safe_file_stem``:
    always a plain name, never a path), ``servo-hexapod.sdf`` or ``leg-3r.sdf``."""
    if isinstance(model, Platform):
        return f"{safe_file_stem(model.name)}.sdf"
    if isinstance(model, ServoHexapod):
        return f"{SERVO_HEXAPOD_MODEL}.sdf"
    if isinstance(model, Leg3R):
        return f"{LEG_MODEL}.sdf"
    raise TypeError(f"no SDF model for a {type(model).__name__}; expected a Platform, ServoHexapod or Leg3R")


def sdf_path(model: Platform | ServoHexapod | Leg3R, directory) -> Path:
    """Where ``model``'s SDF goes in ``directory`` (required: there is no default folder)."""
    return Path(directory) / sdf_file_name(model)


def write_sdf(model: Platform | ServoHexapod | Leg3R, folder, *, option: str = "directory") -> Path:
    """Write ``model``'s SDF as ``sdf_file_name(model)`` into ``folder`` (created if missing) under the
    output-file policy of ``output_folder.write_output_file``: atomic, recorded in the folder's manifest,
    and a file the tool did not write is never replaced. ``option`` names the folder in error messages
    (the CLI passes "--write"); a ``folder`` that exists as a file is refused. Returns the path."""
    if os.path.exists(folder) and not os.path.isdir(folder):
        raise OutputError(OutputError.NOT_A_FOLDER.format(option=option, typed=folder, part=folder))
    return write_output_file(os.path.join(folder, sdf_file_name(model)), sdf_text(model), option=option)
