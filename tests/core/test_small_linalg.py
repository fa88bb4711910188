"""``core.small_linalg``: the batched 2 × 2 Gram matrices and 2 × 2 / 3 × 3 solves give numpy's bits (its OpenBLAS's
dsyrk and dgesv, fused multiply-adds included) on random matrices of every pivot order and of magnitudes 1e-12 …
1e12, on ties, and on the inverse dynamics' own matrices; they refuse singular matrices as numpy does; and the
inverse dynamics gives the same forces, bit for bit, with the compiled loops and with numpy alone."""

import numpy as np
import pytest

from stewart_drake.core import small_linalg as ss
from stewart_drake.core.dynamics import leg_forces_with_legs
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.trajectory import ROTATING

needs_kernel = pytest.mark.skipif(ss.library() is None, reason="no C compiler, or another BLAS: numpy runs")


def _random(rng, shape):
    """Standard normal entries, each matrix scaled by its own 10^U(-12, 12)."""
    return rng.normal(size=shape) * 10.0 ** rng.uniform(-12, 12, shape[:-2] + (1, 1))


def _numpy_solve(A, y):
    return np.linalg.solve(A, y[..., None])[..., 0]


@needs_kernel
def test_random_matrices_give_numpy_bits():
    rng = np.random.default_rng(3)
    B = _random(rng, (40000, 3, 2))
    assert ss.same_bits(ss.gram(B), ss.numpy_gram(B))
    for n in (2, 3):
        A = _random(rng, (40000, n, n))
        A[:5000, 1] = -A[:5000, 0]  # ties of the first column's magnitudes: LAPACK takes the first row
        A[:5000, 1, 1:] *= 1.5
        y = _random(rng, (40000, 1, n))[:, 0]
        x = ss.Solver2(A).solve(y) if n == 2 else ss.solve3(A, y)
        assert ss.same_bits(x, _numpy_solve(A, y)), n


@needs_kernel
def test_a_second_right_hand_side_reuses_the_factors():
    rng = np.random.default_rng(4)
    A, y1, y2 = rng.normal(size=(500, 2, 2)), rng.normal(size=(500, 2)), rng.normal(size=(500, 2))
    s = ss.Solver2(A)
    assert ss.same_bits(s.solve(y1), _numpy_solve(A, y1)) and ss.same_bits(s.solve(y2), _numpy_solve(A, y2))


def test_singular_and_non_finite_matrices_answer_as_numpy():
    """An exactly singular matrix in a batch raises numpy's LinAlgError; a NaN gives numpy's NaNs (numpy runs)."""
    A = np.tile(np.eye(3), (4, 1, 1))
    A[2] = [[1.0, 2.0, 3.0], [2.0, 4.0, 6.0], [0.0, 0.0, 1.0]]
    with pytest.raises(np.linalg.LinAlgError):
        ss.solve3(A, np.ones((4, 3)))
    with pytest.raises(np.linalg.LinAlgError):
        ss.Solver2(A[:, :2, :2]).solve(np.ones((4, 2)))
    A[2] = np.eye(3)
    A[1, 0, 0] = np.nan
    assert ss.same_bits(ss.solve3(A, np.ones((4, 3))), _numpy_solve(A, np.ones((4, 3))))


def test_inverse_dynamics_equal_with_and_without_the_loops(monkeypatch):
    """A feed-forward table's forces (rotating reference, 2001 rows) bit for bit with the compiled loops and with
    numpy's per-matrix calls (the loops disabled): the fixed-point words downstream depend on every bit."""
    p = load_preset("utn-dynamic")
    t = np.arange(2001) * 1e-3
    q, qd, qdd = ROTATING.derivatives(t)
    F = leg_forces_with_legs(p, q, qd, qdd)
    monkeypatch.setattr(ss, "_LIB", [None])
    assert ss.same_bits(F, leg_forces_with_legs(p, q, qd, qdd))


def test_approximate_inverse_is_an_inverse_and_refuses_as_numpy():
    """X A = I to the rounding of Gauss–Jordan on well-conditioned 6 × 6 matrices (κ ≤ ~1e3: 1e-12 relative is
    ~1e3 × 16 ulp); an exactly singular matrix in the batch raises numpy's LinAlgError, as np.linalg.inv does."""
    rng = np.random.default_rng(6)
    A = rng.normal(size=(2000, 6, 6)) + 6 * np.eye(6)
    X = ss.approximate_inverse(A)
    np.testing.assert_allclose(X @ A, np.broadcast_to(np.eye(6), A.shape), atol=1e-12)
    A[7] = 0.0
    with pytest.raises(np.linalg.LinAlgError):
        ss.approximate_inverse(A)
