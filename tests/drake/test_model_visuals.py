"""The SDF's display geometry: legs that look whole over the stroke, joints and plates drawn, and the
dynamics untouched by it. Measured on the geometry Drake's SceneGraph reports, not on our formulas."""

import numpy as np
import pytest

from stewart_drake.core.geometry import load_preset
from stewart_drake.core.leg_bodies import leg_dimensions, leg_visual_dimensions
from stewart_drake.core.sdf_models import convex_outline
from stewart_drake.drake.platform_model import build_plant

# Poses and shape sizes come straight from the SDF's 15 significant digits: ~1e-15 m of rounding.
GEOM_TOL = 1e-12


def _leg_extents(platform, L):
    """For every leg at prismatic position ``L`` (m): the [start, end] of its cylinder and piston
    visuals along the leg axis, measured from the base joint, read from Drake's SceneGraph."""
    from pydrake.geometry import Role
    from pydrake.systems.framework import DiagramBuilder

    builder = DiagramBuilder()
    plant, scene_graph = build_plant(platform, builder=builder)
    diagram = builder.Build()
    ctx = diagram.CreateDefaultContext()
    pctx = plant.GetMyMutableContextFromRoot(ctx)
    for i in range(6):
        plant.GetJointByName(f"prismatic_{i + 1}").set_translation(pctx, L)
    query = scene_graph.get_query_output_port().Eval(scene_graph.GetMyContextFromRoot(ctx))
    inspector = query.inspector()
    out = np.zeros((6, 2, 2))
    for i in range(6):
        X_WC = plant.EvalBodyPoseInWorld(pctx, plant.GetBodyByName(f"cylinder_{i + 1}"))
        origin, axis = X_WC.translation(), X_WC.rotation().matrix()[:, 2]
        for k, body in enumerate((f"cylinder_{i + 1}", f"piston_{i + 1}")):
            frame = plant.GetBodyFrameIdOrThrow(plant.GetBodyByName(body).index())
            (gid,) = inspector.GetGeometries(frame, Role.kIllustration)
            X_WG = query.GetPoseInWorld(gid)
            # The visual cylinder lies along its own z axis, which must be the leg axis.
            assert abs(X_WG.rotation().matrix()[:, 2] @ axis) == pytest.approx(1.0, abs=GEOM_TOL)
            centre = (X_WG.translation() - origin) @ axis
            half = inspector.GetShape(gid).length() / 2
            out[i, k] = centre - half, centre + half
    return out


@pytest.mark.parametrize("name", ["utn-dynamic", "gonzalez-dutra-2009"])
def test_cylinder_and_piston_overlap_over_the_whole_stroke(name):
    platform = load_preset(name)
    for L in (platform.L_min, 0.5 * (platform.L_min + platform.L_max), platform.L_max):
        ext = _leg_extents(platform, L)
        cyl, pist = ext[:, 0], ext[:, 1]
        overlap = np.minimum(cyl[:, 1], pist[:, 1]) - np.maximum(cyl[:, 0], pist[:, 0])
        assert (overlap > 0.01 * platform.L_min).all(), f"{name}: a gap between cylinder and piston at L = {L} m"
        # The cylinder starts at the base joint, the piston ends at the plate joint, and neither passes
        # the other joint (a piston sliding inside its cylinder).
        np.testing.assert_allclose(cyl[:, 0], 0.0, atol=GEOM_TOL)
        np.testing.assert_allclose(pist[:, 1], L, atol=GEOM_TOL)
        assert (cyl[:, 1] <= L + GEOM_TOL).all() and (pist[:, 0] >= -GEOM_TOL).all()


def test_visual_lengths_are_not_the_inertial_ones():
    # The dynamics keeps its rods (half of L_min by default); only the display lengthens them.
    platform = load_preset("utn-dynamic")
    assert leg_dimensions(platform)["cylinder_length"] == pytest.approx(platform.L_min / 2)
    vis = leg_visual_dimensions(platform)
    assert vis["cylinder_length"] + vis["piston_length"] > platform.L_max


def test_plate_outline_is_the_anchor_polygon():
    utn = load_preset("utn-dynamic")
    tri = convex_outline(utn.top_anchors)
    assert len(tri) == 3  # the UTN plate is a triangle
    # Shoelace area against the equilateral triangle of side a, from the anchor distances.
    side = np.linalg.norm(utn.top_anchors[0, :2] - utn.top_anchors[1, :2])
    x, y = tri[:, 0], tri[:, 1]
    area = 0.5 * (x @ np.roll(y, -1) - y @ np.roll(x, -1))
    assert area == pytest.approx(np.sqrt(3) / 4 * side**2, rel=1e-12)
    assert len(convex_outline(utn.base_anchors)) == 6  # the base hexagon


def test_joints_and_plates_are_drawn():
    from pydrake.geometry import Role

    platform = load_preset("utn-dynamic")
    plant, scene_graph = build_plant(platform)
    inspector = scene_graph.model_inspector()

    def names(body):
        frame = plant.GetBodyFrameIdOrThrow(plant.GetBodyByName(body).index())
        return [inspector.GetName(g).split("::")[-1] for g in inspector.GetGeometries(frame, Role.kIllustration)]

    base, top = names("base"), names("top")
    assert sum(n.startswith("base_joint_") for n in base) == 6
    assert sum(n.startswith("top_joint_") for n in top) == len(platform.top_anchors)
    assert any(n.startswith("top_plate_slab") for n in top) and any(n.startswith("base_plate_slab") for n in base)
