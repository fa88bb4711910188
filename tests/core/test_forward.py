"""The numpy assembly-mode search (``core/assembly_modes``): least-squares position, random rotations, and the
polish as a plain callable. The Drake program and the searches it certifies: ``tests/drake/test_forward_drake.py``."""

import numpy as np
import pytest

from stewart_drake.core.assembly_modes import best_position, random_rotations
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.rotations import rotation_matrix


def test_best_position_exact_for_true_rotation():
    """Given the true orientation, the linear least-squares position is the true position."""
    p = load_preset("gonzalez-dutra-2009")
    q = p.home_pose() + [0.03, 0.02, -0.01, 0.1, 0.2, -0.1]
    P = best_position(p, rotation_matrix(q[3:])[None], leg_lengths(p, q))
    np.testing.assert_allclose(P[0], q[:3], atol=1e-12)


def test_random_rotations_are_rotations():
    R = random_rotations(100, np.random.default_rng(0))
    np.testing.assert_allclose(R @ np.swapaxes(R, 1, 2), np.broadcast_to(np.eye(3), R.shape), atol=1e-14)
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-14)


def test_polish_is_any_callable_and_decides_certification():
    """The core search takes the polish as a plain callable (no Drake): a mode is certified only when the
    callable reports success, a residual <= 1e-9 m and the same solution it started from."""
    from stewart_drake.core.assembly_modes import assembly_modes as search

    p = load_preset("utn-dynamic")
    L = leg_lengths(p, p.home_pose())
    kw = dict(n_starts=200, seed=1)
    agree = search(p, L, polish=lambda L_, p_, R_: (p_, R_, True, 0.0), **kw)
    assert len(agree) == 16 and all(m.certified for m in agree.modes)
    failed = search(p, L, polish=lambda L_, p_, R_: (p_, R_, False, 0.0), **kw)
    elsewhere = search(p, L, polish=lambda L_, p_, R_: (p_ + 1e-3, R_, True, 0.0), **kw)
    loose = search(p, L, polish=lambda L_, p_, R_: (p_, R_, True, 2e-9), **kw)
    assert not any(m.certified for am in (failed, elsewhere, loose) for m in am.modes)
    np.testing.assert_allclose(elsewhere.poses(), agree.poses(), atol=1e-12)  # a rejected polish moves nothing
    with pytest.raises(TypeError, match="polish must be a callable"):
        search(p, L, polish="snopt")


def _dedupe_one_at_a_time(p, R, scale, tol):
    """The definition: solution i is kept when it is farther than ``tol`` from every solution kept before it."""
    key = np.concatenate([p / scale, R.reshape(len(R), 9)], axis=-1)
    keep = []
    for i in range(len(key)):
        if not keep or np.min(np.max(np.abs(key[keep] - key[i]), axis=-1)) > tol:
            keep.append(i)
    return np.array(keep, dtype=np.intp)


def test_dedupe_keeps_what_testing_each_solution_in_turn_keeps():
    """``_dedupe`` (one pass per kept solution) keeps the same indices as the one-at-a-time definition: clusters
    of near-copies (spread so that a cluster's members are within ``tol`` of some but not of all others: which one
    is kept decides which drop), the search's own Newton solutions, a NaN row first and later (a NaN distance is not farther)."""
    from stewart_drake.core.assembly_modes import _dedupe
    from stewart_drake.core.newton_fk import CONVERGED, newton_core

    rng = np.random.default_rng(3)
    tol = 1e-6
    centres_p, centres_R = rng.normal(size=(12, 3)), random_rotations(12, rng)
    k = rng.integers(0, 12, 600)
    for spread in (0.2 * tol, 0.7 * tol, tol):
        p = centres_p[k] + rng.uniform(-spread, spread, (600, 3))
        R = centres_R[k] + rng.uniform(-spread, spread, (600, 3, 3))
        p[[5, 40]] = p[[4, 39]] + [tol, 0.0, 0.0]  # exactly at the tolerance along one coordinate
        for scale in (1.0, 0.7):
            want = _dedupe_one_at_a_time(p, R, scale, tol)
            np.testing.assert_array_equal(_dedupe(p, R, scale, tol), want)
            assert 12 <= len(want) < 600  # clusters merged (all 12 at the smallest spread), never all kept
        for rows in ([0], [7, 300]):
            pn = p.copy()
            pn[rows, 1] = np.nan
            np.testing.assert_array_equal(_dedupe(pn, R, 1.0, tol), _dedupe_one_at_a_time(pn, R, 1.0, tol))
    g = load_preset("utn-dynamic")
    L = leg_lengths(g, g.home_pose())
    R0 = random_rotations(800, rng)
    P, RR, _, _, status = newton_core(g, best_position(g, R0, L), R0, np.broadcast_to(L, (800, 6)), 1e-13, 40, 0.2, 0.5)
    P, RR = P[status == CONVERGED], RR[status == CONVERGED]
    want = _dedupe_one_at_a_time(P, RR, 0.5, tol)
    np.testing.assert_array_equal(_dedupe(P, RR, 0.5, tol), want)
    assert 2 <= len(want) <= 16
