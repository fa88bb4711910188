"""The compiled classical washout step against the numpy law: the same poses sample by sample, whether a drive
is fed in one call or in pieces (the state carried between calls, as a real-time loop feeds it)."""

import numpy as np
import pytest

from stewart_drake.control.cueing.classical import HAND_SET, ClassicalParams, classical
from stewart_drake.control.cueing.classical_kernel import WashoutKernel, classical_compiled
from stewart_drake.control.cueing.generators import DRIVES, shipped_drive
from stewart_drake.core.geometry import load_preset

HOME = load_preset("gonzalez-dutra-2009").home_pose()


@pytest.mark.parametrize("name", ["ship-ss6", "car-slalom", "car-braking", "aircraft-turn-reversal"])
@pytest.mark.parametrize("params", [HAND_SET, ClassicalParams()], ids=["hand-set", "default"])
def test_compiled_step_gives_the_numpy_laws_poses(name, params):
    """Same filters, same recursion and order of sums as scipy's lfilter: only the last bit of an arcsine or cosine
    (libm's against numpy's) may differ, and it does not grow through the stable filters: 1e-15 (m, rad) on
    excursions of 0.01–1."""
    drive = shipped_drive(name)
    assert np.abs(classical_compiled(drive, params, HOME) - classical(drive, params, HOME)).max() <= 1e-15


def test_state_carries_between_calls():
    """A drive fed in uneven pieces gives bit for bit the poses of one call."""
    drive = DRIVES["car-lane-change"]()
    u = np.hstack([drive.specific_force, drive.angular_velocity])
    kernel = WashoutKernel(HAND_SET, drive.dt, HOME)
    pieces = np.vstack([kernel.run(u[a:b]) for a, b in ((0, 1), (1, 8), (8, 500), (500, len(u)))])
    assert np.array_equal(pieces, classical_compiled(drive, HAND_SET, HOME))
