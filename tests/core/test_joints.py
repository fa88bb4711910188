"""``core.joints``: the one definition of "points that are one joint" (closer than a tolerance), checked
on hand-made groups, at the tolerance boundary, against SciPy's connected components, and through the
platform code that uses it (base joints, collision pairs, the SDF base plate)."""

import numpy as np
import pytest
from scipy.sparse.csgraph import connected_components
from scipy.spatial.distance import cdist

from stewart_drake.core.geometry import MIN_ANCHOR_SEPARATION, Platform, base_joints
from stewart_drake.core.joints import coincident_groups, first_close_pair
from stewart_drake.core.sdf_models import platform_sdf
from stewart_drake.workspace.limits import leg_pairs

TOL = 1e-6
A, B, C = np.array([0.1, 0.2, 0.3]), np.array([-0.4, 0.1, 0.0]), np.array([0.3, -0.3, 0.05])
NEAR = np.array([0.4, -0.3, 0.2]) * TOL  # 0.54 TOL long: "the same point" at TOL


def test_groups_of_one_two_and_three_in_point_order():
    """Seven points: a triple (0, 3, 6), a pair (1, 4), singles 2 and 5. Groups are numbered by their
    lowest point, which is each group's ``first``."""
    pts = np.array([A, B, C + 3, A + NEAR, B - NEAR, C, A - NEAR])
    first, index = coincident_groups(pts, TOL)
    assert first.tolist() == [0, 1, 2, 5]
    assert index.tolist() == [0, 1, 2, 0, 1, 3, 0]
    # all distinct: one group per point, in order
    first, index = coincident_groups(np.array([A, B, C]), TOL)
    assert first.tolist() == index.tolist() == [0, 1, 2]


def test_tolerance_is_strict():
    """Closer than tol: two points exactly tol apart (0.5, a power of two: the distance is exact) are two
    groups; at the next float above tol they are one."""
    pts = np.array([[0.0, 0.0, 0.0], [0.5, 0.0, 0.0]])
    assert coincident_groups(pts, 0.5)[1].tolist() == [0, 1]
    assert first_close_pair(pts, 0.5) is None
    assert coincident_groups(pts, np.nextafter(0.5, 1.0))[1].tolist() == [0, 0]
    assert first_close_pair(pts, np.nextafter(0.5, 1.0)) == (0, 1)


def test_a_chain_is_one_group_whatever_the_order():
    """0.6 TOL steps: the ends are 1.2 TOL apart, yet the chain is one joint, in every point order (a
    greedy "join the first close leader" rule would split it when the middle point comes last)."""
    step = np.array([0.6 * TOL, 0.0, 0.0])
    chain = np.array([A, A + step, A + 2 * step])
    for order in ([0, 1, 2], [0, 2, 1], [2, 0, 1]):
        first, index = coincident_groups(chain[order], TOL)
        assert first.tolist() == [0] and index.tolist() == [0, 0, 0]
    # the first close pair in row order: (0, 1) is 1.2 TOL apart, (0, 2) is the first that is close
    assert first_close_pair(chain[[0, 2, 1]], TOL) == (0, 2)


def test_agrees_with_scipy_connected_components():
    """Random clusters of 2-9 points with jitter up to 1.3 TOL (so some chains, some split clusters):
    the same partition as SciPy's connected components of the "closer than TOL" graph, numbered by
    lowest member; ``first_close_pair`` is the first True above the diagonal of that graph."""
    rng = np.random.default_rng(7)
    for _ in range(300):
        n = int(rng.integers(2, 10))
        centres = rng.uniform(-1, 1, (int(rng.integers(1, n + 1)), 3))
        pts = centres[rng.integers(0, len(centres), n)] + rng.uniform(-1, 1, (n, 3)) * 0.75 * TOL
        graph = cdist(pts, pts) < TOL
        _, labels = connected_components(graph, directed=False)
        first, index = coincident_groups(pts, TOL)
        lowest = np.array([np.flatnonzero(labels == labels[i])[0] for i in range(n)])
        np.testing.assert_array_equal(first[index], lowest)
        assert np.all(np.diff(first) > 0)
        above = np.argwhere(np.triu(graph, 1))
        assert first_close_pair(pts, TOL) == (tuple(above[0].tolist()) if len(above) else None)


@pytest.fixture
def near_six_three():
    """A 6-3 platform built in code whose paired base anchors are 5e-7 m apart: one joint each by the
    platform's rule (closer than MIN_ANCHOR_SEPARATION), though not equal."""
    joints = np.array([[0.5 * np.cos(t), 0.5 * np.sin(t), 0.0] for t in np.radians([90, 210, 330])])
    base = np.repeat(joints, 2, axis=0) + np.tile([[0.0, 0.0, 0.0], [5e-7, 0.0, 0.0]], (3, 1))
    ph = np.radians(np.repeat([90, 210, 330], 2) + np.tile([-50, 50], 3))
    top = np.stack([0.3 * np.cos(ph), 0.3 * np.sin(ph), np.zeros(6)], -1)
    return Platform(
        name="near-6-3",
        base_anchors=base,
        top_anchors=top,
        leg_top=np.arange(6),
        stroke=[0.5, 1.1],
        mass=5.0,
        com=[0, 0, 0.01],
        inertia=np.diag([0.1, 0.1, 0.18]),
    )


def test_legs_on_one_base_joint_are_one_joint_everywhere(near_six_three):
    """The platform accepts the near pairs as three base joints; the collision check then skips the legs
    on one joint (they meet there: their segment distance is below 5e-7 m, a false collision), and the
    SDF base plate is the triangle of the three joints, not a hexagon with three 5e-7 m edges."""
    p = near_six_three
    assert 0 < np.linalg.norm(p.base_anchors[1] - p.base_anchors[0]) < MIN_ANCHOR_SEPARATION
    first, leg_joint = base_joints(p)
    assert first.tolist() == [0, 2, 4] and leg_joint.tolist() == [0, 0, 1, 1, 2, 2]
    pairs = {tuple(q) for q in leg_pairs(p).tolist()}
    assert pairs == {(i, j) for i in range(6) for j in range(i + 1, 6) if i // 2 != j // 2}
    assert platform_sdf(p).count('name="base_plate_edge_') == 3
