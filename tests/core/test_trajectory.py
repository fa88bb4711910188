"""The one ``Trajectory`` type: closed-form references with exact rates, tables, programs, pickling."""

import pickle

import numpy as np
import pytest

from stewart_drake.core.geometry import load_preset
from stewart_drake.core.trajectory import ROTATING, SEED, constant_trajectory, fit_trajectory, table_trajectory
from stewart_drake.script import run_program

T = np.linspace(-0.5, 4.5, 1001)


def test_seed_and_rotating_poses_are_the_stated_formulas_bit_for_bit():
    """SPEC §3's seed (px = −0.1, py = 0.1 sin 2t, pz = 0.7 m) and the rotating reference (pz = 0.7 m,
    a_x = 5° sin 3t, a_z = 15° sin 2t), written out independently: equal to the last bit (the simulation's
    logs depend on these bits)."""
    z = np.zeros_like(T)
    seed = np.stack([z - 0.1, 0.1 * np.sin(2.0 * T), z + 0.7, z, z, z], axis=-1)
    rot = np.stack([z, z, z + 0.7, np.radians(5.0) * np.sin(3.0 * T), z, np.radians(15.0) * np.sin(2.0 * T)], axis=-1)
    np.testing.assert_array_equal(SEED.pose(T), seed)
    np.testing.assert_array_equal(ROTATING.pose(T), rot)
    np.testing.assert_array_equal(SEED.pose(1.25), seed[np.argmin(np.abs(T - 1.25))])  # a scalar time gives (6,)


@pytest.mark.parametrize("traj", [SEED, ROTATING], ids=["seed", "rotating"])
def test_exact_rates_match_central_differences(traj):
    """``derivatives`` against central differences of ``pose`` (step h = 1e-4 s): the truncation error is
    ≤ |q'''|·h²/6 ≤ 27·0.26·1e-8/6 ≈ 1.2e-8 for the rate and ≤ |q''''|·h²/12 ≈ 1.8e-8 for the acceleration;
    rounding adds ~ε·|q|/h ≈ 1e-12 and ε·|q|/h² ≈ 2e-8."""
    h = 1e-4
    q, qd, qdd = traj.derivatives(T)
    np.testing.assert_array_equal(q, traj.pose(T))
    np.testing.assert_allclose(qd, (traj.pose(T + h) - traj.pose(T - h)) / (2 * h), atol=3e-8)
    np.testing.assert_allclose(qdd, (traj.pose(T + h) - 2 * traj.pose(T) + traj.pose(T - h)) / h**2, atol=1e-7)
    assert np.abs(qd).max() > 0.1  # it moves


def test_table_and_constant_trajectories_have_no_closed_form_rates():
    tab = table_trajectory("tab", [0.0, 1.0], [SEED.pose(0.0), SEED.pose(1.0)])
    np.testing.assert_array_equal(tab.pose(0.5), (SEED.pose(0.0) + SEED.pose(1.0)) / 2)
    with pytest.raises(ValueError, match="trajectory 'tab' has no closed-form rates"):
        tab.derivatives(0.5)
    np.testing.assert_array_equal(
        constant_trajectory("c", SEED.pose(0.0)).pose(np.zeros((2, 3))), np.broadcast_to(SEED.pose(0.0), (2, 3, 6))
    )


def test_every_kind_of_trajectory_pickles_to_the_same_poses():
    """A Monte Carlo worker receives its scenario pickled: fitted, tabulated, constant and program
    trajectories must survive the round trip with the same poses bit for bit."""
    p = load_preset("utn-kinematic")
    prog = run_program("mover(0, 0, 60, 5, 0, 0) en 0.5\nwait 0.1\n", "p.stw", p).trajectory
    trajs = [
        fit_trajectory(ROTATING, p),
        table_trajectory("tab", [0.0, 0.2, 0.4], SEED.pose(np.array([0.0, 0.2, 0.4]))),
        constant_trajectory("c", p.home_pose(), 1.0),
        prog,
    ]
    for tr in trajs:
        back = pickle.loads(pickle.dumps(tr))
        assert back.name == tr.name and back.duration == tr.duration
        np.testing.assert_array_equal(back.pose(T[:200]), tr.pose(T[:200]))
    assert prog.duration == pytest.approx(0.6) and len(prog.moves) == 1
    np.testing.assert_array_equal(prog.pose(prog.t), prog.q)  # the program's pose function goes through its samples
