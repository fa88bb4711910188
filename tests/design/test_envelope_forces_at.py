"""``envelope.cartesian_leg_forces_at``: the forces of many samples at a few distinct poses, its pose-only work
done once per pose, must be ``cartesian_leg_forces`` at the gathered poses bit for bit (the report's envelope
check compares them with the exact worst case), and must refuse a singular pose as it does."""

import numpy as np
import pytest

from stewart_drake.core.geometry import load_preset
from stewart_drake.design.envelope import cartesian_leg_forces, cartesian_leg_forces_at
from stewart_drake.design.verify import sample_box
from stewart_drake.errors import SingularPoseError
from tests._own_platform import own_radial


def _samples(p, convention, n=3000, seed=5):
    rng = np.random.default_rng(seed)
    home = p.home_pose()
    poses = home + np.c_[rng.uniform(-0.03, 0.03, (7, 3)), np.radians(rng.uniform(-12, 12, (7, 3)))]
    k = rng.integers(0, len(poses), n)
    V = sample_box(rng, n, np.array([0.3, 0.3, 0.2, 0.5, 0.5, 1.0]))
    A = sample_box(rng, n, np.array([3.0, 3.0, 5.0, 10.0, 10.0, 20.0]))
    return poses, k, V, A


@pytest.mark.parametrize("convention", ["utn", "zyx"])
def test_equals_cartesian_leg_forces_bit_for_bit(tmp_path, convention):
    own = own_radial(tmp_path).replace(mass=12.0, inertia=np.diag([0.3, 0.3, 0.5]))  # a plate of its own
    for p in (load_preset("utn-dynamic"), own):
        poses, k, V, A = _samples(p, convention)
        F = cartesian_leg_forces_at(p, poses, k, V, A, convention)
        assert np.ptp(F) > 1.0  # forces that vary (N), not a constant
        np.testing.assert_array_equal(F, cartesian_leg_forces(p, poses[k], V, A, convention))


def test_singular_pose_refused_with_the_same_message():
    p = load_preset("utn-dynamic")
    poses, k, V, A = _samples(p, "utn", n=50)
    poses[3, 3] = np.pi / 2  # utn's middle angle at 90°: gimbal lock, J = ∂L/∂q singular
    k[:10] = 0
    k[10] = 3  # the first sample at the singular pose is sample 11
    with pytest.raises(SingularPoseError) as ours:
        cartesian_leg_forces_at(p, poses, k, V, A)
    with pytest.raises(SingularPoseError) as reference:
        cartesian_leg_forces(p, poses[k], V, A)
    assert str(ours.value) == str(reference.value)
