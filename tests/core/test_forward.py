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
