"""``dynamics.open_loop_growth_rates`` evaluates its 18 inverse-dynamics calls as two batches: the same rates, bit for
bit, as one call per pose (the formula it had, written out here), on the presets and a platform of our own."""

import numpy as np
import pytest

from stewart_drake.core.dynamics import G_EARTH, leg_forces, leg_forces_with_legs, open_loop_growth_rates
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import length_jacobian
from tests._own_platform import own_radial


def _one_call_per_pose(platform, q0, legs: bool) -> np.ndarray:
    """The growth rates with every column of M_eff and ∂F/∂q from its own call (6 + 12 calls)."""
    z = np.zeros(6)
    law = leg_forces_with_legs if legs else leg_forces

    def forces(q_, qdd_, g):
        return law(platform, q_, z, qdd_, "utn", gravity=g)

    J = length_jacobian(platform, q0, "utn")
    M_eff = J.T @ np.stack([forces(q0, e, 0.0) for e in np.eye(6)], -1)
    h = 1e-6
    dF = np.stack([(forces(q0 + h * e, z, G_EARTH) - forces(q0 - h * e, z, G_EARTH)) / (2 * h) for e in np.eye(6)], -1)
    ev = np.linalg.eigvals(np.linalg.solve(M_eff, -J.T @ dF))
    return np.sort(np.sqrt(ev.astype(complex)).real)[::-1]


@pytest.mark.parametrize("name", ["utn-dynamic", "gonzalez-dutra-2009", "own"])
def test_batched_growth_rates_equal_one_call_per_pose(name, tmp_path):
    p = (
        own_radial(tmp_path).replace(mass=12.0, inertia=np.diag([0.3, 0.3, 0.5]))
        if name == "own"
        else load_preset(name)
    )
    rng = np.random.default_rng(5)
    poses = [p.home_pose()] + [
        p.home_pose() + rng.uniform(-1, 1, 6) * np.array([0.02, 0.02, 0.02, 0.05, 0.05, 0.05]) for _ in range(4)
    ]
    for q in poses:
        for legs in (True, False):
            expected = _one_call_per_pose(p, q, legs)
            assert np.isfinite(expected).all()
            np.testing.assert_array_equal(open_loop_growth_rates(p, q, legs=legs), expected)
