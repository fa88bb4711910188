"""Pinocchio and MuJoCo against the closed forms: closure residuals and leg lengths at 10³ poses, leg forces along
the seed and rotating trajectories, on the three presets and a platform of the tests' own; and a one-millimetre
anchor error in one engine's model is caught."""

import dataclasses

import numpy as np
import pytest

import stewart_drake as sd
from stewart_drake.cli import main
from stewart_drake.core.geometry import PRESETS, load_preset
from stewart_drake.core.sampling import random_poses
from stewart_drake.core.sdf import xml_vec
from stewart_drake.engines import cross_check as X
from stewart_drake.engines.models import closures, mjcf_text

from .own_platform import OWN, own_platform

STATUS = X.engine_status()
pytestmark = pytest.mark.skipif(
    all(STATUS.values()), reason="neither pinocchio nor mujoco is installed (pip install 'stewart-drake[engines]')"
)


def available(name):
    if STATUS[name] is not None:
        pytest.skip(STATUS[name])


@pytest.fixture(params=[*PRESETS, "own"])
def platform(request, tmp_path):
    return own_platform(tmp_path) if request.param == "own" else load_preset(request.param)


@pytest.mark.parametrize("engine", X.ENGINES)
def test_engine_agrees_with_the_closed_forms(platform, engine):
    available(engine)
    r = X.cross_check(platform, engines=[engine], poses=1000, samples=7)[engine]
    kin = r["kinematics"]
    assert kin["poses"] == 1000
    assert kin["closure_residual_m"] <= kin["tolerance_m"]
    assert kin["leg_length_error_m"] <= kin["tolerance_m"]
    for name, d in r["dynamics"].items():
        # the expectation for an exact engine (1e-6 relative) and the derived rounding bound κ·ε·1000
        assert d["relative_error"] <= min(1e-6, d["tolerance_relative"]), name
        assert d["max_force_n"] > 1.0  # the forces compared are real, not zeros
    assert r["ok"]


def test_leg_masses_matter_in_the_compared_forces():
    """The engines' forces carry the legs: dropping them (massless legs) moves the forces far beyond the tolerance,
    so the agreement above is not the plate's alone."""
    available("pinocchio")
    p = load_preset("utn-dynamic")
    q, qd, qdd = X.trajectories(p, 5)["rotating"]
    light = p.replace(legs=dataclasses.replace(p.legs, cylinder_mass=1e-9, piston_mass=1e-9))
    F = X.engine_model("pinocchio", p).leg_forces(q, qd, qdd)
    F_light = X.engine_model("pinocchio", light).leg_forces(q, qd, qdd)
    assert np.abs(F - F_light).max() > 0.1  # N: 0.3 kg of leg against a 1.36 kg plate


def shifted(text: str, old: str, new: str) -> str:
    assert text.count(old) == 1
    return text.replace(old, new)


def test_a_millimetre_anchor_error_in_mujocos_model_is_caught(tmp_path):
    available("mujoco")
    p = own_platform(tmp_path)
    t = p.top_anchors_per_leg[0]
    bad = shifted(
        mjcf_text(p),
        f'<site name="top_anchor_1" pos="{xml_vec(*t)}"/>',
        f'<site name="top_anchor_1" pos="{xml_vec(t[0] + 1e-3, t[1], t[2])}"/>',
    )
    eng = X.engine_model("mujoco", p, mjcf=bad)
    kin = X.kinematics_check(eng, p, random_poses(p, 100, seed=3))
    assert not kin["ok"]
    # the anchor is 1 mm off in the plate frame: the closure residual is that millimetre at every pose
    assert abs(kin["closure_residual_m"] - 1e-3) <= 1e-9
    good = X.kinematics_check(X.engine_model("mujoco", p), p, random_poses(p, 100, seed=3))
    assert good["ok"]


def test_a_millimetre_anchor_error_in_pinocchios_closures_is_caught(tmp_path):
    available("pinocchio")
    p = own_platform(tmp_path)
    bad = closures(p)
    bad[3]["p_b"] = [bad[3]["p_b"][0], bad[3]["p_b"][1] + 1e-3, bad[3]["p_b"][2]]
    eng = X.engine_model("pinocchio", p, closure_list=bad)
    kin = X.kinematics_check(eng, p, random_poses(p, 100, seed=3))
    assert not kin["ok"]
    assert abs(kin["closure_residual_m"] - 1e-3) <= 1e-9
    q, qd, qdd = X.trajectories(p, 5)["seed"]
    # the forces move too: the closure pulls the plate 1 mm off its anchor
    dyn = X.dynamics_check(eng, p, q, qd, qdd, condition=X.engine_condition(eng, p, q, qd, qdd))
    assert not dyn["ok"]


def test_a_missing_engine_is_reported_not_raised(monkeypatch):
    monkeypatch.setattr(X, "engine_status", lambda: {"pinocchio": "pinocchio is not installed (x)", "mujoco": None})
    available("mujoco")
    r = X.cross_check(load_preset("utn-dynamic"), poses=10, samples=3)
    assert r["pinocchio"] == {"available": False, "reason": "pinocchio is not installed (x)", "ok": None}
    assert r["mujoco"]["ok"]


@pytest.mark.parametrize("engine", X.ENGINES)
def test_task_space_inertia_and_natural_frequencies_match_modes(platform, engine):
    """The engine's inertia reduced to the plate's Cartesian coordinates is ``modes``' M_C with the legs, and the
    natural frequencies with ``design.stiffness``' K agree; the legs' share is real (dropping it moves M)."""
    available(engine)
    eng = X.engine_model(engine, platform)
    r = X.modes_check(eng, platform, np.vstack([platform.home_pose(), random_poses(platform, 4, seed=5)]))
    assert r["mass_matrix_relative_error"] <= r["tolerance_relative"]
    assert r["frequency_relative_error"] <= r["tolerance_relative"]
    k = platform.legs.stiffness or X.NOMINAL_LEG_STIFFNESS
    f = sd.modes(platform, platform.home_pose(), leg_stiffness=k, legs=True).to_dict()["frequencies_hz"]
    np.testing.assert_allclose(r["frequencies_hz"], f, rtol=r["tolerance_relative"])
    plate_only = X.spatial_inertia(platform, platform.home_pose(), legs=False)
    st = X.plate_state(platform, platform.home_pose())
    assert np.linalg.norm(eng.task_mass_matrix(st, 0) - plate_only) > 1e3 * r["tolerance_relative"] * np.linalg.norm(
        plate_only
    )


def test_trajectories_shrink_to_stay_in_stroke(tmp_path):
    """A home pose near the short end of the stroke: the sway of a quarter stroke would pull legs below L_min, so it
    is halved until every leg stays in; the check still runs (no internal error on a user's platform)."""
    path = tmp_path / "low.yaml"
    path.write_text(OWN + "home_height: 430.0\n")
    p = sd.load_platform(str(path))
    q = X.trajectories(p, 13)["seed"][0]
    quarter = (p.L_max - p.L_min) / 4
    amp = np.abs(q[:, 1] - p.home_pose()[1]).max()
    assert amp < quarter and amp > quarter / 4  # halved once or twice, not to nothing
    L = X.leg_lengths(p, q)
    assert L.min() >= p.L_min and L.max() <= p.L_max


def test_a_disagreeing_engine_exits_1_with_its_table(monkeypatch, capsys):
    available("mujoco")
    real = X.cross_check

    def bad(*args, **kwargs):
        out = real(*args, **kwargs)
        out["mujoco"]["kinematics"].update(closure_residual_m=1e-3, ok=False)
        out["mujoco"]["ok"] = False
        return out

    monkeypatch.setattr("stewart_drake.api.cross_check.run_cross_check", bad)
    rc = main(["cross-check", "--platform", "utn-dynamic", "--engine", "mujoco", "--poses", "5", "--no-simulation"])
    out = capsys.readouterr().out
    assert rc == 1
    assert "closure residual 1.00e-03 m" in out and "DISAGREES" in out
    assert out.rstrip().endswith("verdict: an engine disagrees with the closed forms")


def test_a_platform_without_plate_mass_is_compared_with_the_plate_the_models_carry(tmp_path):
    """The models give a massless plate the SDF's placeholder (1e-6 kg): the closed form is evaluated with that plate,
    so the leg forces (then from the legs alone) agree to rounding instead of by the placeholder's weight."""
    available("pinocchio")
    path = tmp_path / "bare.yaml"
    path.write_text("\n".join(line for line in OWN.splitlines() if not line.startswith("plate:")))
    p = sd.load_platform(str(path))
    assert p.mass == 0
    r = X.cross_check(p, engines=["pinocchio"], poses=20, samples=3, simulate=False)["pinocchio"]
    assert r["ok"], r
    assert all(d["max_force_n"] > 0.1 for d in r["dynamics"].values())  # the legs' own weight and inertia
