"""The workspace section classifies only the grid nodes within the stroke workspace's extents
(``analyses.workspace.reachable_nodes``): it must find exactly the nodes the whole box gives, in the same order."""

import numpy as np
import pytest

import stewart_drake.workspace as ws
from stewart_drake.analyses.workspace import reachable_nodes
from stewart_drake.core.geometry import load_preset


@pytest.mark.parametrize("name", ["gonzalez-dutra-2009", "utn-kinematic"])
def test_pruned_grid_finds_the_same_nodes(name):
    p = load_preset(name)
    h = 0.02
    w = ws.constant_orientation_workspace(p, resolution=h)
    whole = reachable_nodes(p, h)
    pruned = reachable_nodes(p, h, w)
    assert len(whole) > 1000  # a real workspace, not an empty comparison
    np.testing.assert_array_equal(pruned, whole)  # same nodes, same order (bit for bit)


def test_pruned_grid_with_a_coarser_workspace():
    """The extents may come from a coarser grid than the nodes': extent_error covers the difference."""
    p = load_preset("gonzalez-dutra-2009")
    w = ws.constant_orientation_workspace(p, resolution=0.04, refine=False)
    np.testing.assert_array_equal(reachable_nodes(p, 0.02, w), reachable_nodes(p, 0.02))
