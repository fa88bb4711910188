"""``extents.point_margins`` (the extents' optimiser calls it thousands of times) hoists the orientation's part
out of the call: it must give, bit for bit, ``raw_margins`` of ``leg_vectors`` at the pose and the half-space
above the base, as the refinement computed them before, for every kind of limit and orientation."""

import math

import numpy as np
import pytest

import stewart_drake.workspace as ws
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_vectors
from stewart_drake.workspace.extents import plate_offsets, point_margins
from stewart_drake.workspace.grid import default_bounds, grid_axes
from stewart_drake.workspace.slabs import grid_spec

LIMITS = [
    ws.Limits(),
    ws.Limits(base_cone=math.radians(60), top_cone=math.radians(60), base_axes=np.tile([0.1, 0.2, 1.0], (6, 1))),
    ws.Limits(leg_diameter=0.12),
    ws.Limits(max_condition=4.0),
]


@pytest.mark.parametrize("orientation", [(0.0, 0.0, 0.0), (0.1, -0.2, 0.3)])
@pytest.mark.parametrize("limits", LIMITS)
def test_point_margins_are_raw_margins_of_leg_vectors(orientation, limits):
    p = load_preset("gonzalez-dutra-2009")
    spec = grid_spec(p, orientation, "utn", limits, grid_axes(default_bounds(p, orientation), 0.05))
    offsets = plate_offsets(spec)
    rng = np.random.default_rng(5)
    for pos in np.r_[[[0.0, 0.0, p.home_height]], rng.uniform([-0.3, -0.3, 0.45], [0.3, 0.3, 0.85], (20, 3))]:
        q = np.r_[pos, spec.orientation]
        l = leg_vectors(p, q, "utn")
        ref = [m.ravel() for m in ws.raw_margins(p, l, spec.R, limits, q, "utn").values()]
        ref = np.concatenate(ref + [np.array([pos[2] - spec.z_floor])])
        got = point_margins(spec, pos, offsets)
        assert got.shape == ref.shape and np.array_equal(got.view(np.int64), ref.view(np.int64))
