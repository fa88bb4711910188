"""Forward simulation in the engines: the closed-form forces applied open loop (Pinocchio follows the plan to the
forces' interpolation error; MuJoCo's soft closures stretch less and track better as its solref stiffens) and the
passive platform released from home (energy kept by Pinocchio's rigid model; both engines fall alike)."""

import numpy as np
import pytest

from stewart_drake.core.geometry import PRESETS, load_preset
from stewart_drake.engines import cross_check as X

from .own_platform import own_platform

STATUS = X.engine_status()


@pytest.fixture(params=[*PRESETS, "own"])
def platform(request, tmp_path):
    return own_platform(tmp_path) if request.param == "own" else load_preset(request.param)


def needs(*names):
    for n in names:
        if STATUS[n] is not None:
            pytest.skip(STATUS[n])


def test_pinocchio_follows_the_closed_form_forces_open_loop(platform):
    needs("pinocchio")
    r = X.open_loop_check("pinocchio", platform)
    # the bound is the forces' linear interpolation over a step (|F̈| dt²/8) grown for 0.5 s: RK4's own error is
    # orders smaller at dt = 1 ms; the closures are rigid (their gap is rounding)
    assert r["position_error_m"] <= r["bound_m"]
    assert r["constraint_m"] <= 1e-10
    assert r["ok"]


def test_mujoco_soft_closures_stretch_less_as_solref_stiffens(platform):
    needs("mujoco")
    r = X.open_loop_check("mujoco", platform)
    gap, err, tau = np.array(r["constraint_m"]), np.array(r["position_error_m"]), np.array(r["solref_s"])
    assert (np.diff(gap) < 0).all() and (np.diff(err) < 0).all()
    # the connect is a spring of stiffness ∝ 1/τ²: the stretch falls as τ² where the impedance is constant and
    # slower where it rises with the stretch, but faster than τ (the damping alone)
    slope = np.polyfit(np.log(tau), np.log(gap), 1)[0]
    assert 1.0 < slope <= 2.0


def test_passive_release_falls_alike_and_pinocchio_keeps_its_energy(platform):
    needs("pinocchio", "mujoco")
    rp = X.passive_release("pinocchio", platform)
    rm = X.passive_release("mujoco", platform)
    assert rp["z"][0] - rp["z"][-1] > 0.05  # a real fall (m), not a platform at rest
    assert rp["in_stroke"] and rm["in_stroke"]  # the models carry no stroke limits: a fair fall stays inside
    # MuJoCo's plate hangs on closures stretched by at most their gap: its height differs from the rigid model's by
    # no more than that
    assert np.abs(rp["z"] - rm["z"]).max() <= rm["constraint_m"]
    # RK4's error per unit time ~ (dt/τ)⁴ for motions of time scale τ = √(L_min/g) (the fall through a leg's length)
    tau = np.sqrt(platform.L_min / 9.81)
    bound = (X.SIM_STEP / tau) ** 4 * (X.RELEASE_DURATION / tau) * rp["energy_exchanged_j"]
    assert rp["energy_drift_j"] <= bound
    # MuJoCo's closures are damped (solref damping ratio 1): energy leaves, and more than rounding
    assert rm["energy_drift_j"] > 1e3 * rp["energy_drift_j"]


def test_float_law_loop_in_both_engines_side_by_side(platform):
    """The float PID law closing the loop along the seed sway for 1 s: MuJoCo's soft closures are a compliance in
    series with the legs that the law cannot see (it reads leg lengths); its plate departs from Pinocchio's rigid
    one, and ten times less stiff closures (solref 20 ms against 2 ms) depart at least ten times more (the stretch
    goes as τ^1..2: ``test_mujoco_soft_closures_stretch_less_as_solref_stiffens``)."""
    needs("pinocchio", "mujoco")
    rp = X.float_loop("pinocchio", platform)
    assert rp["constraint_m"] <= 1e-10  # rigid closures: rounding
    soft = X.float_loop("mujoco", platform, solref=(0.02, 1.0))
    stiff = X.float_loop("mujoco", platform, solref=(0.002, 1.0))
    d_soft = np.linalg.norm(soft["p"] - rp["p"], axis=-1).max()
    d_stiff = np.linalg.norm(stiff["p"] - rp["p"], axis=-1).max()
    assert d_stiff < d_soft / 10
