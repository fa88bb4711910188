"""The compiled real-time FK kernel (core/fk_kernel.c) called directly, below ``solve_batch``'s input checks:
lengths that are not numbers (the per-call ``solve`` path does not validate) must stop Newton as diverged
with the residual numpy's Newton reports (NaN for a NaN length, inf for an infinite one), alone and beside
a good set in a pair, and the good set keeps its own bits."""

import numpy as np
import pytest

from stewart_drake.core import realtime_fk
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.newton_fk import CONVERGED, DIVERGED, newton_core
from stewart_drake.core.realtime_fk import INFO, RealtimeFK
from stewart_drake.core.rotations import rotation_matrix
from stewart_drake.core.sampling import random_poses


def kernel(fk: RealtimeFK, L: np.ndarray, q0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(poses (n, 6), info (n, len(INFO)))`` straight from ``sd_rtfk`` (no input checks; sets two at a time)."""
    ffi, lib = realtime_fk.library()
    L, q0 = np.ascontiguousarray(L, dtype=float), np.ascontiguousarray(q0, dtype=float)
    q, info = np.empty((len(L), 6)), np.empty((len(L), len(INFO)))
    fb = ffi.from_buffer
    lib.sd_rtfk(
        len(L), fk._gp, fk.conv, fb("double[]", L), fb("double[]", q0), 6, 0, fk.tol, fk.max_iter, 0,
        fb("double[]", q, require_writable=True), fb("double[]", info, require_writable=True),
    )  # fmt: skip
    return q, info


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_a_length_that_is_not_a_number_stops_newton_as_numpy_does(bad):
    p = load_preset("utn-kinematic")
    fk = RealtimeFK(p, engine="c")
    if fk.engine != "c":
        pytest.skip("no C compiler")
    q = random_poses(p, 2, seed=3, region="workspace")
    L = leg_lengths(p, q)
    q0 = q + 1e-3
    L[0, 4] = bad
    ref = newton_core(p, q0[:, :3], rotation_matrix(q0[:, 3:]), L, fk.tol, fk.max_iter)
    _, alone = kernel(fk, L[:1], q0[:1])
    poses, pair = kernel(fk, L, q0)  # the bad set paired with a good one
    for info in (alone[0], pair[0]):
        assert info[2] == DIVERGED == ref[4][0]
        assert np.array_equal(info[0], ref[2][0], equal_nan=True)  # NaN, or inf, as numpy's max |L* - L|
        assert info[3] == 0.0  # not certified
    assert pair[1, 2] == CONVERGED == ref[4][1]
    good_q, good = kernel(fk, L[1:], q0[1:])
    assert np.array_equal(pair[1], good[0]) and np.array_equal(poses[1], good_q[0])
