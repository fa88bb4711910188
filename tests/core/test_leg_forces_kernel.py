"""The compiled inverse dynamics (``core.leg_forces_kernel``) against numpy's ``dynamics.leg_forces_with_legs``, the
reference and the fallback.

The tolerance (the module's docstring): each side computes J and Q to a relative δ ≤ 100 ε, so the difference of two
is ≤ 200 ε, and F = J⁻ᵀ Q moves by at most κ(J)·200 ε relative to the row's largest force; ``RELATIVE_TOLERANCE``
(1e-12) covers κ ≤ 20, which the references of the presets and of the 210 kg machine stay under (checked here).
Random references check the κ-scaled bound itself. Rows the loop cannot prove well-conditioned, or that are not
finite, give numpy's answer or error."""

import numpy as np
import pytest

from stewart_drake.core import leg_forces_kernel as K
from stewart_drake.core.dynamics import leg_forces_with_legs
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import length_jacobian, scaled_condition
from stewart_drake.core.trajectory import Trajectory
from stewart_drake.errors import StewartError
from stewart_drake.spec import load_machine
from tests._own_platform import NEWCOMER_PLATFORM

EPS = np.finfo(float).eps
H = 1e-3  # the 1 kHz controller's sample period: the tables' difference step
PRESETS = ("utn-dynamic", "utn-kinematic", "gonzalez-dutra-2009")

pytestmark = pytest.mark.skipif(K.library() is None, reason="no C compiler: numpy runs (tested below)")


def _newcomer_with_payload(tmp_path):
    """The 210 kg machine: its platform with the 150 kg payload 300 mm above the plate (examples/newcomer-210kg.yaml)."""
    path = tmp_path / "newcomer.yaml"
    path.write_text(NEWCOMER_PLATFORM + "payload: {mass: 150kg, position: [0, 0, 300mm]}\n")
    return load_machine(path).loaded_platform


def _reference_rows(platform, name: str, seconds: float = 2.0):
    """``(q, qd, qdd)`` at the ticks of ``seconds`` of the reference, fitted to the platform, as the tables take them."""
    trajectory = getattr(Trajectory, name)(platform, fit=True)
    t = np.arange(int(seconds / H) + 1) * H
    qm, q0, qp = trajectory.pose(t - H), trajectory.pose(t), trajectory.pose(t + H)
    return q0, (qp - qm) / (2 * H), (qp - 2 * q0 + qm) / H**2


def _relative(F, ref) -> np.ndarray:
    """``(n,)`` each row's largest difference over its largest force."""
    return np.abs(F - ref).max(-1) / np.abs(ref).max(-1)


@pytest.mark.parametrize("name", ["seed", "rotating"])
@pytest.mark.parametrize("platform_name", [*PRESETS, "newcomer-210kg"])
def test_the_references_are_within_the_stated_tolerance(platform_name, name, tmp_path):
    platform = _newcomer_with_payload(tmp_path) if platform_name == "newcomer-210kg" else load_preset(platform_name)
    q, qd, qdd = _reference_rows(platform, name)
    kappa = scaled_condition(platform, length_jacobian(platform, q))
    assert kappa.max() <= 20  # where RELATIVE_TOLERANCE's derivation holds
    ffi, lib = K.library()
    F = np.empty_like(q)
    fb = ffi.from_buffer
    rows = (fb("double[]", np.ascontiguousarray(a)) for a in (q, qd, qdd))
    assert lib.sd_leg_forces(len(q), fb("double[]", K.platform_constants(platform)), 0, *rows, fb("double[]", F)) == 0
    assert _relative(F, leg_forces_with_legs(platform, q, qd, qdd)).max() <= K.RELATIVE_TOLERANCE
    np.testing.assert_array_equal(K.leg_forces(platform, q, qd, qdd), F)  # every row by the loop


@pytest.mark.parametrize("convention", ["utn", "zyx"])
@pytest.mark.parametrize("platform_name", PRESETS)
def test_random_references_are_within_the_condition_scaled_bound(platform_name, convention):
    platform = load_preset(platform_name)
    rng = np.random.default_rng(42)
    n = 2000
    q = platform.home_pose() + rng.uniform(-1, 1, (n, 6)) * [0.05, 0.05, 0.03, 0.15, 0.15, 0.3]
    qd = rng.normal(size=(n, 6)) * [0.5, 0.5, 0.5, 2, 2, 2]
    qdd = rng.normal(size=(n, 6)) * [10, 10, 10, 30, 30, 30]
    kappa = scaled_condition(platform, length_jacobian(platform, q, convention))
    F = K.leg_forces(platform, q, qd, qdd, convention)
    assert np.all(_relative(F, leg_forces_with_legs(platform, q, qd, qdd, convention)) <= 200 * EPS * kappa)


def test_a_batch_with_a_row_the_loop_leaves_gives_numpys_answer_or_error():
    """A gimbal-locked row (utn a_x = 90°: E_W, hence J, singular) raises numpy's SingularPoseError with its message;
    a non-finite row raises numpy's error."""
    platform = load_preset("utn-dynamic")
    q = np.tile(platform.home_pose(), (5, 1))
    z = np.zeros_like(q)
    locked = q.copy()
    locked[3, 3] = np.pi / 2
    for bad in (locked, np.where(np.arange(5)[:, None] == 2, np.nan, q)):
        with pytest.raises(StewartError) as numpy_error:
            leg_forces_with_legs(platform, bad, z, z)
        with pytest.raises(type(numpy_error.value)) as kernel_error:
            K.leg_forces(platform, bad, z, z)
        assert str(kernel_error.value) == str(numpy_error.value)


def test_without_the_compiled_loop_numpy_runs(monkeypatch):
    platform = load_preset("gonzalez-dutra-2009")
    q, qd, qdd = _reference_rows(platform, "rotating", 0.2)
    monkeypatch.setattr(K, "_LIB", [None])
    assert K.engine() == "numpy"
    np.testing.assert_array_equal(K.leg_forces(platform, q, qd, qdd), leg_forces_with_legs(platform, q, qd, qdd))
