"""The sweep's block kernel (``slabs.inside_block``) classifies every node and counts every limit's removals, bit
for bit, as the former kernel did: the whole block tested for the stroke, every optional limit's margin from
``margins_from_legs``. What changed: only the stroke window (``slabs.stroke_window``) is tested, the dexterity limit
is decided by ``condition_above``, and the closest leg axes are remembered across leg diameters."""

import dataclasses
import math

import numpy as np
import pytest

import stewart_drake.workspace as ws
from stewart_drake.core.geometry import load_preset
from stewart_drake.workspace import slabs
from stewart_drake.workspace.grid import default_bounds, grid_axes
from stewart_drake.workspace.limits import margins_from_legs
from tests._own_platform import own_radial


def _former_inside_block(spec, xs, ys, zs):
    """The kernel as it was."""
    p = spec.platform
    shape = (len(xs), len(ys), len(zs))
    ok = np.ones(shape, bool)
    ok &= (np.asarray(zs) > spec.z_floor)[None, None, :]
    lo2, hi2 = p.L_min**2, p.L_max**2
    if spec.limits.stroke:
        for i in range(6):
            c = spec.offsets[i]
            d2 = (
                ((xs + c[0]) ** 2)[:, None, None]
                + ((ys + c[1]) ** 2)[None, :, None]
                + ((zs + c[2]) ** 2)[None, None, :]
            )
            ok &= (d2 >= lo2) & (d2 <= hi2)
    removed = {}
    others = [n for n in spec.limits.active if n != "stroke"]
    if others:
        idx = np.nonzero(ok)
        pos = np.stack([xs[idx[0]], ys[idx[1]], zs[idx[2]]], -1)
        l = pos[:, None, :] + spec.offsets
        poses = np.concatenate([pos, np.broadcast_to(spec.orientation, pos.shape)], -1)
        margins = margins_from_legs(
            p, l, spec.R, dataclasses.replace(spec.limits, stroke=False), poses, spec.convention
        )
        keep = np.ones(len(pos), bool)
        for name in others:
            bad = margins[name][0] < 0
            removed[name] = np.bincount(idx[0][bad], minlength=shape[0])
            keep &= ~bad
        ok[idx] = keep
    return ok, removed


CASES = [
    ("gonzalez-dutra-2009", (0.0, 0.0, 0.0), 0.02, [ws.Limits()]),
    # two diameters: the second sweep's distances come from the memo
    ("gonzalez-dutra-2009", (0.0, 0.0, 0.0), 0.02, [ws.Limits(leg_diameter=0.10), ws.Limits(leg_diameter=0.145)]),
    ("gonzalez-dutra-2009", (0.1, -0.2, 0.3), 0.025, [ws.Limits(leg_diameter=0.12, max_condition=4.0)]),
    ("gonzalez-dutra-2009", (0.0, 0.0, 0.0), 0.02, [ws.Limits(max_condition=3.0)]),
    ("utn-kinematic", (0.0, 0.2, 0.0), 0.02, [ws.Limits(base_cone=math.radians(85), top_cone=math.radians(85))]),
    ("utn-dynamic", (0.0, 0.0, 0.4), 0.03, [ws.Limits(max_condition=20.0, leg_diameter=0.03)]),
    ("own", (-0.2, 0.1, 0.0), 0.06, [ws.Limits(stroke=False, leg_diameter=0.05)]),  # no stroke: no window
]


@pytest.mark.parametrize("name, orientation, h, limits_list", CASES)
def test_block_kernel_as_the_former_one(tmp_path, name, orientation, h, limits_list):
    """Blocks of a few x-planes (some wholly out of reach), over a grid wider than the workspace on every side
    (nodes just past every bound of the window), at tilted orientations, with each optional limit binding: the
    same inside nodes and removed counts; the window is a small part of each block (the saving)."""
    p = own_radial(tmp_path) if name == "own" else load_preset(name)
    b = default_bounds(p, orientation) + [[-0.1, 0.1]] * 3
    slabs.AXIS_DISTANCES.clear()
    for limits in limits_list:
        spec = slabs.grid_spec(p, np.array(orientation), "utn", limits, grid_axes(b, h))
        x, y, z = spec.axes
        sizes, inside, removed = [], 0, dict.fromkeys(limits.active, 0)
        for i0 in range(0, len(x), 5):
            xs = x[i0 : i0 + 5]
            got = slabs.inside_block(spec, xs, y, z)
            want = _former_inside_block(spec, xs, y, z)
            np.testing.assert_array_equal(got[0], want[0])
            assert got[1].keys() == want[1].keys()
            for k in want[1]:
                np.testing.assert_array_equal(got[1][k], want[1][k])
                removed[k] += int(want[1][k].sum())
            j0, j1, k0, k1 = slabs.stroke_window(spec, xs, y, z)
            sizes.append((j1 - j0) * (k1 - k0) / (len(y) * len(z)))
            inside += int(want[0].sum())
        assert inside > 0
        if limits.stroke:
            assert min(sizes) == 0.0 and np.mean(sizes) < 0.5  # blocks out of reach, half the nodes untested
        if limits.leg_diameter == 0.145 or limits.max_condition == 3.0:  # the report's binding limits
            assert removed["collision" if limits.leg_diameter else "dexterity"] > 0  # both answers occur
