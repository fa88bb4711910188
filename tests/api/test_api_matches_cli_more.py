"""The API and the command line give the same numbers for the remaining commands with ``--json``: ``dsp-ik``
``servo``, ``leg fk``, ``leg ik``, ``model --inspect`` and ``view --json`` (each command's API function is called in SI, the CLI in its own units, and the API's numbers
converted here, independently of the CLI's code).

Tolerances: a number the CLI prints unrounded is the API's times 1e3 or π/180 once: a few ulps (1e-12
relative; a pulse in µs is the API's seconds times 1e6). ``dsp-ik`` rounds its float lengths and differences to 1e-4 mm, so those agree within half that,
5e-5 mm, plus the ulps.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import stewart_drake as sd
from stewart_drake.cli import main
from tests.api.test_api_matches_cli import OWN_YAML

RTOL = 1e-12
MM = 1e3


def cli_json(capsys, *argv) -> tuple[int, dict]:
    rc = main(list(argv))
    return rc, json.loads(capsys.readouterr().out)


# dsp-ik: one pose within the range, one whose plate dips below the base (flagged, exit 1); angles in pi
# fractions (the firmware's own unit) and in degrees.
DSP_CASES = [
    (
        ["10", "-5", "700", "0.05", "-0.02", "0.1"],
        "pi",
        (0.010, -0.005, 0.700, 0.05 * math.pi, -0.02 * math.pi, 0.1 * math.pi),
    ),
    (["-37.9", "12", "-40", "9", "-4.5", "30"], "deg", (-0.0379, 0.012, -0.040, *np.radians([9, -4.5, 30]))),
]


@pytest.mark.parametrize(("typed", "unit", "si"), DSP_CASES)
def test_dsp_ik_matches_cli(capsys, typed, unit, si):
    rc, cli = cli_json(capsys, "dsp-ik", "--pose", *typed, "--angle-unit", unit, "--json", "--trace")
    api = sd.dsp_ik(si, trace=True)
    assert rc == (0 if api.ok else 1)
    d = api.to_dict()
    pose = d["pose"]
    # the firmware's words are the same integers on both sides
    assert [cli["pose"][f"{k}_mm"] for k in ("px", "py", "pz")] == [round(pose[k] * MM) for k in ("px", "py", "pz")]
    assert cli["pose"]["px_mm"] == math.trunc(float(typed[0]))  # truncated toward zero, as the firmware stores it
    for k in ("alpha", "beta", "gamma"):
        assert math.isclose(cli["pose"][f"{k}_pi"], pose[k] / math.pi, rel_tol=RTOL)
    assert cli["pose"]["angle_words"] == pose["angle_words"]
    assert cli["dsp_lengths_mm"] == [round(v * MM) for v in d["dsp_lengths"]] == api.dsp_words.tolist()
    assert cli["trace"] == d["trace"]
    for key in ("float_lengths", "difference"):
        np.testing.assert_allclose(cli[f"{key}_mm"], np.array(d[key]) * MM, rtol=0, atol=5e-5 + 1e-9)
    for side in ("firmware", "float"):
        assert cli["geometry_mm"][side] == pytest.approx({k: v * MM for k, v in d["geometry"][side].items()}, rel=RTOL)
    assert (cli["engine"], cli["saturations"]) == (d["engine"], d["saturations"])
    # the same flags; the command line names its option (--pose) where the API names its parameter (pose)
    assert [f.replace("--pose:", "pose:", 1) for f in cli["flags"]] == d["flags"]


def test_dsp_ik_case_below_base_is_flagged():
    """The second case is a pose whose plate dips below the base: flagged by both (so the exit-1 path is run)."""
    assert not sd.dsp_ik(DSP_CASES[1][2]).ok
    assert sd.dsp_ik(DSP_CASES[0][2]).ok


def test_dsp_ik_refuses_angle_beyond_half_turn():
    with pytest.raises(sd.StewartError, match="beyond ±180°"):
        sd.dsp_ik([0, 0, 0.7, 3.2, 0, 0])


SERVO_YAML = """\
name: api-test-servo
length_unit: mm
arm_length: 30.0
rod_length: 130.0
paired:
  base_radius: 70.0
  pair_spacing: 56.0
  platform_radius: 58.0
  anchor_half_angle_deg: 12.0
servo:
  neutral_us: [1500, 1520, 1480, 1500, 1510, 1490]
  rate_us: 400.0
  rate_deg: 45.0
  travel_deg: 40.0
"""
DEG = math.pi / 180


@pytest.fixture(params=["hobby-servo", "own"])
def servo_platform(request, tmp_path):
    if request.param == "own":
        path = tmp_path / "servo.yaml"
        path.write_text(SERVO_YAML)
        return str(path)
    return request.param


# (typed pose in mm and degrees or None, from_home, trim µs or None): home, a reachable pose, one beyond the
# travel (exit 1), and a trimmed pose
SERVO_CASES = [
    (None, False, None),
    ((4, -3, 2, 3, -2, 5), True, None),
    ((0, 0, 0, 40, 0, 0), True, None),
    ((2, 1, -4, 0, 4, -3), True, (1490, 1500, 1510, 1500, 1505, 1495)),
]


@pytest.mark.parametrize(("typed", "from_home", "trim"), SERVO_CASES)
def test_servo_matches_cli(capsys, servo_platform, typed, from_home, trim):
    argv = ["servo", "--platform", servo_platform, "--json"]
    argv += ["--pose", *map(str, typed)] if typed is not None else []
    argv += ["--from-home"] if from_home else []
    argv += ["--trim", *map(str, trim)] if trim is not None else []
    rc, cli = cli_json(capsys, *argv)
    si = None if typed is None else [v * f for v, f in zip(typed, [1e-3] * 3 + [DEG] * 3)]
    api = sd.servo(
        si, platform=servo_platform, from_home=from_home, trim=None if trim is None else np.array(trim) * 1e-6
    )
    d = api.to_dict()
    assert rc == (0 if api.ok else 1) and cli["ok"] == d["ok"]
    assert cli["preset"] == d["preset"] and cli["units"]["convention"] == d["convention"]
    if typed is None:  # home: the CLI shows the home pose in its units
        np.testing.assert_allclose(cli["pose"], np.array(d["pose"]) * ([MM] * 3 + [1 / DEG] * 3), rtol=RTOL, atol=1e-12)
    else:
        assert cli["pose"] == list(typed)
        z = d["pose"][2] - (d["home_height"] if from_home else 0.0)
        np.testing.assert_allclose(np.r_[d["pose"][:2], z, d["pose"][3:]], si, rtol=RTOL, atol=1e-15)
    assert math.isclose(cli["home_height"], d["home_height"] * MM, rel_tol=RTOL)
    for key, api_key in (("alpha0_deg", "alpha0"), ("angles_deg", "angles")):
        np.testing.assert_allclose(cli[key], np.degrees(d[api_key]), rtol=RTOL, atol=1e-12)
    for key in ("pulse", "pulse_raw"):
        np.testing.assert_allclose(cli[f"{key}_us"], np.array(d[key]) * 1e6, rtol=RTOL)
    assert len(cli["violations"]) == len(d["violations"])
    for c, a in zip(cli["violations"], d["violations"]):
        assert (c["servo"], c["kind"]) == (a["servo"], a["kind"])
        for k in ("angle", "limit", "excess"):
            if k in a:
                assert math.isclose(c[f"{k}_deg"], math.degrees(a[k]), rel_tol=RTOL, abs_tol=1e-12)


def test_servo_cases_include_a_travel_violation(servo_platform):
    """The third servo case is beyond the travel on both platforms: the exit-1 path is compared too."""
    assert not sd.servo([0, 0, 0, 40 * DEG, 0, 0], from_home=True, platform=servo_platform).ok
    assert sd.servo([0.004, -0.003, 0.002, 3 * DEG, -2 * DEG, 5 * DEG], from_home=True).ok


def test_servo_refuses_trim_without_room_for_travel():
    with pytest.raises(sd.StewartError, match="--trim|trim"):
        sd.servo(trim=[1500e-6] * 5 + [9000e-6])


# leg: the default leg and a leg of the test's own (--l1 --l2 --l3, mm at the CLI, m in the API)
LEGS = [{}, {"l1": 95.0, "l2": 70.0, "l3": 25.0}]


def leg_argv(dims: dict) -> list[str]:
    return [a for n, v in dims.items() for a in (f"--{n}", str(v))]


def leg_si(dims: dict) -> dict:
    return {n: v * 1e-3 for n, v in dims.items()}


@pytest.mark.parametrize("dims", LEGS)
@pytest.mark.parametrize("q", [(30.0, -45.0), (100.0, -150.0)])  # the second is outside both joint limits
def test_leg_fk_matches_cli(capsys, dims, q):
    rc, cli = cli_json(capsys, "leg", "fk", *map(str, q), *leg_argv(dims), "--json")
    api = sd.leg_fk(*(v * DEG for v in q), **leg_si(dims))
    d = api.to_dict()
    assert rc == (0 if api.ok else 1) and cli["within_limits"] == d["within_limits"]
    assert cli["q"] == list(q)
    np.testing.assert_allclose(cli["foot"], np.array(d["foot"]) * MM, rtol=RTOL)
    assert math.isclose(cli["gamma"], math.degrees(d["gamma"]), rel_tol=RTOL)
    np.testing.assert_allclose(cli["T03"], d["T03"], rtol=RTOL, atol=1e-15)
    assert len(cli["limit_violations"]) == len(d["limit_violations"]) == (0 if api.ok else 2)
    for c, a in zip(cli["limit_violations"], d["limit_violations"]):
        assert c["joint"] == a["joint"]
        for k in ("value_rad", "limit_rad", "excess_rad"):
            assert math.isclose(c[k], a[k], rel_tol=RTOL, abs_tol=1e-15)


@pytest.mark.parametrize("dims", LEGS)
@pytest.mark.parametrize(("target", "gamma"), [((100.0, -50.0), None), ((90.0, -60.0), -30.0)])
def test_leg_ik_matches_cli(capsys, dims, target, gamma):
    argv = ["leg", "ik", *map(str, target), *leg_argv(dims), "--json"]
    argv += [] if gamma is None else ["--gamma", str(gamma)]
    rc, cli = cli_json(capsys, *argv)
    api = sd.leg_ik(*(v * 1e-3 for v in target), gamma=None if gamma is None else gamma * DEG, **leg_si(dims))
    d = api.to_dict()
    assert rc == (0 if api.ok else 1)
    assert cli["target"] == list(target) and cli["gamma"] == gamma
    np.testing.assert_allclose(d["target"], np.array(target) * 1e-3, rtol=RTOL)
    assert set(cli["solutions"]) == set(d["solutions"]) == {"a", "b"}
    for b, c in cli["solutions"].items():
        a = d["solutions"][b]
        assert c["within_limits"] == a["within_limits"]
        assert len(c["q"]) == (2 if gamma is None else 3)
        np.testing.assert_allclose(c["q"], np.degrees(a["q"]), rtol=RTOL, atol=1e-12)
    if gamma is not None:  # the seed's 3R method frees q3: leg_fk (q1, q2, fixed ankle) is no round trip for it
        return
    # a round trip, independent of the CLI: the API's branch a puts the foot back on the target
    fk = sd.leg_fk(*d["solutions"]["a"]["q"][:2], **leg_si(dims))
    np.testing.assert_allclose(fk.foot, np.array(target) * 1e-3, rtol=0, atol=1e-12)


@pytest.fixture(params=["utn-dynamic", "own"])
def platform_arg(request, tmp_path):
    """The ``--platform`` value: a preset, or a YAML platform of the tests' own (a 6-6 radial one)."""
    if request.param == "own":
        path = tmp_path / "mine.yaml"
        path.write_text(OWN_YAML)
        return str(path)
    return request.param


def test_inspect_model_matches_cli(capsys, platform_arg, tmp_path):
    """``model --inspect --json`` is already SI: the API's dict is the CLI's, key for key (``--write`` too)."""
    rc, cli = cli_json(
        capsys, "model", "--platform", platform_arg, "--inspect", "--json", "--write", str(tmp_path / "a")
    )
    api = sd.inspect_model(platform_arg, write=tmp_path / "b")
    d = api.to_dict()
    assert rc == 0 and api.ok
    assert set(cli) == set(d)
    for k in d:
        if k == "sdf_file":  # two folders, the same file name and the same SDF text
            assert cli[k].rsplit("/", 1)[1] == d[k].rsplit("/", 1)[1]
            assert open(cli[k]).read() == open(d[k]).read()
        else:
            assert cli[k] == d[k], k
    assert len(api.actuators) == 6 and api.anchor_error < 1e-6  # six legs; anchors as the geometry's


# view: a reachable pose (exit 0) and one beyond the stroke (exit 1: the readout still printed), in mm and degrees
VIEW_POSES = [(10.0, 0.0, 720.0, 0.0, 5.0, 0.0), (0.0, 0.0, 1100.0, 0.0, 0.0, 0.0)]


@pytest.mark.parametrize("typed", VIEW_POSES)
def test_viewer_readout_matches_cli(capsys, platform_arg, typed):
    """``view --duration 0 --json`` draws once and prints the readout; ``viewer_readout`` computes it without
    a viewer. Both already SI: equal within the ulps of the typed pose's mm/deg → SI products."""
    rc, cli = cli_json(capsys, "view", "--platform", platform_arg, "--duration", "0", "--json", "--no-modes", "--pose", *map(str, typed))  # fmt: skip
    si = [v * f for v, f in zip(typed, [1e-3] * 3 + [DEG] * 3)]
    api = sd.viewer_readout(platform_arg, si, modes=False)
    d = api.to_dict()
    assert rc == (0 if api.ok else 1)
    assert set(cli) == set(d)
    for k in d:
        if isinstance(d[k], (bool, type(None))):
            assert cli[k] == d[k], k
        else:
            np.testing.assert_allclose(cli[k], d[k], rtol=1e-9, atol=1e-12, err_msg=k)


def test_viewer_readout_cases_cover_both_exits(platform_arg):
    """The second pose is beyond the stroke on both platforms (so the exit-1 readout is compared too)."""
    oks = [sd.viewer_readout(platform_arg, [v * f for v, f in zip(p, [1e-3] * 3 + [DEG] * 3)], modes=False).ok for p in VIEW_POSES]  # fmt: skip
    assert oks == [True, False]


def test_viewer_readout_counts_modes_and_defaults_to_home():
    r = sd.viewer_readout("utn-dynamic")
    np.testing.assert_array_equal(r.pose, sd.load_platform("utn-dynamic").home_pose())
    assert r.ok and r.fraction == 1.0 and r.modes >= 1 and r.modes_near >= 1  # home is one of its own modes
