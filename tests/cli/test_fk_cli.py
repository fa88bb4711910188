"""``stewart-drake fk``."""

import json

import numpy as np

from stewart_drake.cli import main
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.rotations import rotation_matrix


def run(capsys, *argv):
    rc = main(list(argv))
    out, err = capsys.readouterr()
    return rc, out, err


def test_fk_json_round_trip_in_mm_deg(capsys):
    """IK of a pose, printed in mm, fed back: the pose in mm/deg (utn) to 1e-6 mm / 1e-6 deg (the
    lengths are printed with repr precision, so only float rounding is lost)."""
    p = load_preset("utn-kinematic")
    q = np.array([10.0, -5.0, 120.0, 3.0, -2.0, 5.0])
    L = leg_lengths(p, np.r_[q[:3] * 1e-3, np.radians(q[3:])]) * 1e3
    rc, out, _ = run(capsys, "fk", "--lengths", *(repr(float(v)) for v in L), "--json")
    d = json.loads(out)
    assert rc == 0 and d["method"] == "newton" and d["length_unit"] == "mm" and d["convention"] == "utn"
    (s,) = d["solutions"]
    np.testing.assert_allclose(s["pose"], q, atol=1e-6)
    assert s["residual"] < 1e-9 and s["converged"] and s["above_base"] and s["within_stroke"]
    assert s["det_sign"] in (-1, 1) and s["condition"] > 1


def test_fk_convention_and_units(capsys):
    """--convention zyx --angle-unit rad --length-unit m: angles of the same rotation in zyx."""
    p = load_preset("utn-dynamic")
    q = np.array([0.02, 0.01, 0.68, 0.1, -0.05, 0.2])  # zyx angles
    L = leg_lengths(p, q, "zyx")
    rc, out, _ = run(
        capsys,
        "fk",
        "--platform",
        "utn-dynamic",
        "--lengths",
        *(repr(float(v)) for v in L),
        "--length-unit",
        "m",
        "--angle-unit",
        "rad",
        "--convention",
        "zyx",
        "--json",
    )
    np.testing.assert_allclose(json.loads(out)["solutions"][0]["pose"], q, atol=1e-12)
    assert np.allclose(
        rotation_matrix(q[3:], "zyx"), rotation_matrix(json.loads(out)["solutions"][0]["pose"][3:], "zyx")
    )


def test_fk_all_modes(capsys):
    p = load_preset("utn-dynamic")
    L = leg_lengths(p, p.home_pose()) * 1e3
    rc, out, _ = run(
        capsys, "fk", "--platform", "utn-dynamic", "--lengths", *(repr(float(v)) for v in L), "--all", "--json"
    )
    d = json.loads(out)
    assert rc == 0 and len(d["solutions"]) == 16 and d["complete"] and d["max_solutions"] == 16
    np.testing.assert_allclose(d["solutions"][0]["pose"], [0, 0, 700, 0, 0, 0], atol=1e-9)  # nearest home first
    assert sum(s["above_base"] for s in d["solutions"]) == 8
    assert all(s["certified"] for s in d["solutions"])


def test_fk_text_output(capsys):
    rc, out, _ = run(capsys, "fk", "--lengths", *(["473.1868"] * 6))
    assert rc == 0 and "method: newton" in out and "above base" in out


def test_fk_impossible_lengths_exit_2(capsys):
    """Legs 1 and 2 share a plate joint with base anchors 925 mm apart: 300 and 1300 mm cannot close."""
    rc, out, err = run(capsys, "fk", "--lengths", "300", "1300", "473", "473", "473", "473")
    assert rc == 2 and out == ""
    assert "stewart-drake fk: error: forward kinematics: no assembly found for lengths (300.000, 1300.000" in err


def test_fk_outside_stroke_exit_1(capsys):
    """2000 mm legs assemble (pz ~ 1946 mm) but are past the 700 mm stroke: reported, exit status 1."""
    rc, out, _ = run(capsys, "fk", "--lengths", *(["2000"] * 6), "--json")
    d = json.loads(out)
    assert rc == 1 and d["solutions"][0]["within_stroke"] is False


def test_fk_bad_length(capsys):
    rc, _, err = run(capsys, "fk", "--lengths", "473", "473", "-1", "473", "473", "473")
    assert rc == 2 and "--lengths: leg 3 length -1 mm must be a positive number" in err
