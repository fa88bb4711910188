"""The workspace section's cheaper paths give the same numbers: ``reachable_nodes`` classifies only the nodes
near the stroke workspace (a prefilter on |p + l_i(0)|) and must return exactly the nodes and order that
classifying every node gives; ``stroke_column_lengths`` measures only the columns every leg can reach and must
agree with a dense z-sampling of each column, the skipped ones included (they are empty)."""

import numpy as np
import pytest

import stewart_drake.workspace as ws
from stewart_drake.analyses.workspace import reachable_nodes
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_vectors


@pytest.mark.parametrize("name", ["gonzalez-dutra-2009", "utn-kinematic"])
def test_prefiltered_nodes_are_those_of_classifying_every_node(name):
    p = load_preset(name)
    h = 0.02
    g = [np.arange(lo, hi + h / 2, h) for lo, hi in ws.default_bounds(p)]
    X, Y, Z = np.meshgrid(*g, indexing="ij")
    q = np.zeros(X.shape + (6,))
    q[..., 0], q[..., 1], q[..., 2] = X, Y, Z
    every = q[ws.classify(p, q)]
    got = reachable_nodes(p, h)
    assert 1000 < len(got) < q[..., 0].size  # a real workspace, and a box larger than it (the prefilter drops nodes)
    np.testing.assert_array_equal(got, every)


def test_column_lengths_against_dense_sampling_including_unreachable_columns():
    p = load_preset("gonzalez-dutra-2009")
    b = ws.default_bounds(p)
    rng = np.random.default_rng(2)
    x = rng.uniform(b[0, 0], b[0, 1], 150)
    y = rng.uniform(b[1, 0], b[1, 1], 150)
    lengths = ws.stroke_column_lengths(p, x, y, z_bounds=(0.0, np.inf))
    dz = 2.5e-4
    z = np.arange(dz / 2, b[2, 1] + 0.1, dz)
    l0 = leg_vectors(p, np.zeros(6))  # (6, 3): l_i = p + l_i(0) at zero orientation
    L2 = (x[:, None, None] + l0[:, 0]) ** 2 + (y[:, None, None] + l0[:, 1]) ** 2 + (z[None, :, None] + l0[:, 2]) ** 2
    inside = np.all((L2 >= p.L_min**2) & (L2 <= p.L_max**2), axis=-1)  # (columns, z)
    sampled = inside.sum(axis=1) * dz
    assert (lengths == 0).sum() > 10 and (lengths > 0).sum() > 10  # both kinds of columns are tried
    # the midpoint count errs by at most one sample at each end of each of (at most 3) intervals
    np.testing.assert_allclose(lengths, sampled, atol=6 * dz)
    assert np.all(sampled[lengths == 0] == 0)  # a skipped column holds no pose within the stroke
