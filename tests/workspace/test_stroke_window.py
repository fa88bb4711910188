"""The sweep's stroke window (``slabs.stroke_window``): classifying only the window of a block where every leg can
be within L_max gives the block's classification of every node, bit for bit, as testing the whole block did."""

import math

import numpy as np
import pytest

import stewart_drake.workspace as ws
from stewart_drake.core.geometry import load_preset
from stewart_drake.workspace import slabs
from stewart_drake.workspace.grid import default_bounds, grid_axes
from tests._own_platform import own_radial


def _whole_block(spec, xs, ys, zs):
    """The window the former kernel used: the whole block."""
    return 0, len(ys), 0, len(zs)


CASES = [
    ("gonzalez-dutra-2009", (0.0, 0.0, 0.0), 0.02, ws.Limits()),
    ("gonzalez-dutra-2009", (0.1, -0.2, 0.3), 0.025, ws.Limits(leg_diameter=0.12, max_condition=4.0)),
    ("utn-kinematic", (0.0, 0.2, 0.0), 0.02, ws.Limits(base_cone=math.radians(85), top_cone=math.radians(85))),
    ("utn-dynamic", (0.0, 0.0, 0.4), 0.015, ws.Limits()),
    ("own", (-0.2, 0.1, 0.0), 0.06, ws.Limits(stroke=False, leg_diameter=0.05)),  # no stroke: no window
]


@pytest.mark.parametrize("name, orientation, h, limits", CASES)
def test_window_classifies_every_node_as_the_whole_block(monkeypatch, tmp_path, name, orientation, h, limits):
    """Blocks of a few x-planes (some wholly out of reach), over a grid wider than the workspace on every side
    (nodes just past every bound of the window), at tilted orientations and with optional limits: the same inside
    nodes and removed counts, and the window is a small part of each block (the saving)."""
    p = own_radial(tmp_path) if name == "own" else load_preset(name)
    b = default_bounds(p, orientation) + [[-0.1, 0.1]] * 3
    spec = slabs.grid_spec(p, np.array(orientation), "utn", limits, grid_axes(b, h))
    x, y, z = spec.axes
    sizes, inside = [], 0
    for i0 in range(0, len(x), 5):
        xs = x[i0 : i0 + 5]
        got = slabs.inside_block(spec, xs, y, z)
        j0, j1, k0, k1 = slabs.stroke_window(spec, xs, y, z)
        sizes.append((j1 - j0) * (k1 - k0) / (len(y) * len(z)))
        with monkeypatch.context() as m:
            m.setattr(slabs, "stroke_window", _whole_block)
            want = slabs.inside_block(spec, xs, y, z)
        np.testing.assert_array_equal(got[0], want[0])
        assert got[1].keys() == want[1].keys()
        for k in want[1]:
            np.testing.assert_array_equal(got[1][k], want[1][k])
        inside += int(want[0].sum())
    assert inside > 0
    if limits.stroke:
        assert min(sizes) == 0.0 and np.mean(sizes) < 0.5  # blocks out of reach, and half the nodes left untested
