"""Inverse dynamics against Drake: the plate as a free body, the Euler-chain plant (M, C, G in pose
coordinates), the closed-loop model with massive legs, and an open-loop closed-loop simulation."""

import numpy as np
import pytest

import stewart_drake.core.dynamics as D
import stewart_drake.drake.verify_dynamics as V
from stewart_drake.core.geometry import load_preset

# Both sides are double-precision evaluations of the same physics with O(10) operations per term and
# forces of O(10 N); J is well conditioned (< 100 here). Rounding gives ~1e-14 N; 1e-9 N is the bound.
TOL_N = 1e-9


@pytest.fixture(scope="module")
def plat():
    return load_preset("utn-dynamic")


def trajectory(kind, t):
    """Seed trajectory, and rotations about X, Y, Z separately and all together (with translation)."""
    if kind == "seed":
        return D.seed_trajectory(t)
    amp = np.array([0.02, 0.03, 0.015, 0, 0, 0])
    axes = {"about-x": [3], "about-y": [4], "about-z": [5], "all-axes": [3, 4, 5]}[kind]
    amp[axes] = 0.35
    return D.harmonic_trajectory(
        t, [-0.02, 0.01, 0.7, 0.03, -0.02, 0.05], amp, [1.3, 2.1, 1.7, 3.0, 2.5, 3.5], [0.1, 0.2, 0.3, 0.4, 0.5, 0.6]
    )


KINDS = ["seed", "about-x", "about-y", "about-z", "all-axes"]


@pytest.mark.parametrize("convention", ["utn", "zyx"])
@pytest.mark.parametrize("kind", KINDS)
def test_complete_model_matches_drake_free_body(plat, kind, convention):
    q, qd, qdd = trajectory(kind, np.linspace(0, 3, 9))
    F = D.leg_forces(plat, q, qd, qdd, convention)
    F_drake = V.drake_leg_forces(plat, q, qd, qdd, convention)
    assert np.abs(F - F_drake).max() <= TOL_N


def test_complete_model_matches_drake_with_offset_rotation_centre(plat):
    p = plat.replace(rotation_centre=[0.015, -0.01, 0.03])
    q, qd, qdd = trajectory("all-axes", np.linspace(0, 3, 9))
    q[:, 2] += 0.03
    assert np.abs(D.leg_forces(p, q, qd, qdd) - V.drake_leg_forces(p, q, qd, qdd)).max() <= TOL_N


@pytest.mark.parametrize("kind", ["about-x", "about-y", "about-z", "all-axes"])
def test_seed_model_differs_from_drake_by_the_coriolis_term_alone(plat, kind):
    q, qd, qdd = trajectory(kind, np.linspace(0, 3, 9))
    F_drake = V.drake_leg_forces(plat, q, qd, qdd)
    F_seed = D.leg_forces(plat, q, qd, qdd, coriolis=False)
    F_cor = D.coriolis_leg_forces(plat, q, qd)
    if kind == "about-z":
        # A spin about the plate's own z axis (a principal axis through the centre of mass, Ix = Iy):
        # ω × Iω = 0, no centripetal term, and a single Euler rate has Ė θ̇ = 0, so C q̇ vanishes.
        assert np.abs(F_cor).max() < 1e-15
    else:
        assert np.abs(F_cor).max() > 1e-3  # the difference is real (mN), not rounding
    assert np.abs(F_drake - F_seed - F_cor).max() <= TOL_N


def test_mass_coriolis_gravity_match_drake_chain(plat):
    p = plat.replace(rotation_centre=[0.01, 0.02, -0.005])
    for convention in ("utn", "zyx"):
        q, qd, _ = trajectory("all-axes", np.linspace(0, 2, 5))
        T = V.drake_dynamics_terms(p, q, qd, convention)
        np.testing.assert_allclose(D.mass_matrix(p, q, convention), T["M"], atol=1e-15)
        np.testing.assert_allclose(D.coriolis_vector(p, q, qd, convention), T["C"], atol=1e-14)
        np.testing.assert_allclose(D.gravity_vector(p, q, convention), T["G"], atol=1e-14)


def test_leg_mass_model_matches_drake_constrained_inverse_dynamics(plat):
    q, qd, qdd = trajectory("all-axes", np.linspace(0, 3, 4))
    F_drake = V.constrained_leg_forces(plat, q, qd, qdd)
    F = D.leg_forces_with_legs(plat, q, qd, qdd)
    # The 24x24 [B Gᵀ] solve loses a little more than the free body; still rounding-level.
    assert np.abs(F - F_drake).max() <= TOL_N
    # The legs (0.3 kg each against a 1.36 kg plate) are not negligible: they change forces by ~1 N.
    assert np.abs(F - D.leg_forces(plat, q, qd, qdd)).max() > 0.3


def test_open_loop_simulation_follows_and_drift_scales_with_time_step(plat):
    """Applying the closed-loop model's forces open loop: the plate follows the seed trajectory to
    micrometres over 0.5 s; the drift is first order in the time step (the discrete solver's error)."""
    errs = []
    for dt in (2e-3, 1e-3):
        t = np.arange(0, 0.5 + dt / 2, dt)
        q, qd, qdd = D.seed_trajectory(t)
        r = V.simulate_open_loop(
            plat, t, q, qd, D.leg_forces_with_legs(plat, q, qd, qdd), dt, record_every=int(0.05 / dt)
        )
        assert r["position_error"][0] == 0
        assert r["position_error"].max() < 2e-5  # m
        assert r["angle_error"].max() < 1e-4  # rad
        assert r["constraint"].max() < 1e-4  # m, ball constraints are compliant in SAP
        errs.append(r["position_error"][-1])
    assert 1.6 < errs[0] / errs[1] < 2.4
