"""The calibration commands end to end: plan-measurements → simulate-measurements → calibrate → the
calibrated file loads, ik/fk speak readings, firmware generate bakes the offsets in and firmware check
passes; bad input is one line with exit 2, an identification that does not converge exit 1."""

from __future__ import annotations

import json

import numpy as np
import pytest

from stewart_drake.calibration.model import Layout
from stewart_drake.calibration.plan import Box, candidate_poses
from stewart_drake.calibration.validate import truth_errors
from stewart_drake.cli import main
from stewart_drake.core.geometry import load_platform, load_preset
from tests.cli._inprocess import cli


@pytest.fixture(scope="module")
def flow(tmp_path_factory):
    """plan (30 poses) → simulate (seed 1) → calibrate with a 20 % holdout, in one folder."""
    d = tmp_path_factory.mktemp("calibration")
    assert (
        main(
            [
                "plan-measurements",
                "--platform",
                "utn-dynamic",
                "--poses",
                "30",
                "--candidates",
                "400",
                "--out",
                str(d / "plan"),
            ]
        )
        == 0
    )
    assert (
        main(
            [
                "simulate-measurements",
                "--platform",
                "utn-dynamic",
                "--poses",
                str(d / "plan" / "poses.csv"),
                "--seed",
                "1",
                "--out",
                str(d / "meas"),
            ]
        )
        == 0
    )
    assert main(["calibrate", "--platform", "utn-dynamic", "--measurements", str(d / "meas" / "measurements.csv"), "--holdout", "0.2", "--out", str(d / "cal")]) == 0  # fmt: skip
    return d


def test_outputs_and_the_calibrated_file(flow):
    plan = json.loads((flow / "plan" / "plan.json").read_text())
    assert plan["planned"]["d_index"] > plan["random"]["d_index"]
    assert (flow / "plan" / "plan.stw").read_text().count("move(") == 30
    assert sorted(p.name for p in (flow / "cal").iterdir()) == [
        ".stewart-drake-manifest.json", "calibrated.yaml", "calibration.json", "corrections.png", "residuals.png",
    ]  # fmt: skip
    assert not (flow / "meas" / "truth" / "platform.yaml").samefile(flow / "meas" / "measurements.csv")
    cal = load_platform(flow / "cal" / "calibrated.yaml")
    truth = load_platform(flow / "meas" / "truth" / "platform.yaml")
    nominal = load_preset("utn-dynamic")
    d = json.loads((flow / "cal" / "calibration.json").read_text())
    # every identified parameter within 4.5 σ of the truth (33 Gaussian errors: P(any beyond) ~ 2e-4)
    z = (Layout(nominal, "pose").theta(cal) - Layout(nominal, "pose").theta(truth)) / [
        q["sigma"] for q in d["parameters"]
    ]
    assert np.any(cal.length_offset) and np.abs(z).max() < 4.5, z
    val = candidate_poses(nominal, Box.default(nominal), 100, seed=99)[:30]
    assert truth_errors(truth, cal, val)["position"]["rms"] < 15e-6
    assert d["converged"] and d["validation"]["poses"] == 6 and len(d["validation"]["lines"]) == 6
    assert d["identifiability"]["identifiable"] == 33 and d["identifiability"]["frame_freedoms"] == []
    text = (flow / "cal" / "calibrated.yaml").read_text()
    assert "calibration:" in text and d["sha256"] in text


def test_ik_readings_and_fk_readings_round_trip(flow, capsys):
    f = flow / "cal" / "calibrated.yaml"
    cal = load_platform(f)
    rc, out, _ = cli(capsys, "ik", "--platform", f, "--pose", 5, -3, 720, 2, -1, 3, "--json")
    r = json.loads(out)
    assert rc == 0 and np.allclose(np.subtract(r["lengths"], r["readings"]), cal.length_offset * 1e3, atol=1e-9)
    rc, out, _ = cli(capsys, "fk", "--platform", f, "--readings", *r["readings"], "--json")
    pose = json.loads(out)["solutions"][0]["pose"]
    assert rc == 0 and np.allclose(pose, [5, -3, 720, 2, -1, 3], atol=1e-6)
    rc, out, _ = cli(capsys, "ik", "--platform", "utn-dynamic", "--pose", 5, -3, 720, 2, -1, 3, "--json")
    assert "readings" not in json.loads(out)  # no offsets: the output it always had


def test_firmware_bakes_the_offsets_in_and_checks(flow, capsys, tmp_path, monkeypatch):
    from stewart_drake.system.c_build import CACHE_ENV

    monkeypatch.setenv(CACHE_ENV, str(tmp_path / "cache"))
    f = flow / "cal" / "calibrated.yaml"
    rc, _, _ = cli(capsys, "firmware", "generate", "--platform", f, "--length-lsb", "3e-5", "--out", tmp_path / "fw")
    assert rc == 0
    counts = np.round(load_platform(f).length_offset / 1e-5).astype(int)
    c = (tmp_path / "fw" / "sd_firmware.c").read_text()
    assert f"SD_LENGTH_OFFSET[6] = {{{', '.join(map(str, counts))}}};" in c
    rc, out, _ = cli(capsys, "firmware", "check", tmp_path / "fw" / "sd_firmware.c", "--platform", f, "--length-lsb", "3e-5", "--poses", "2000", "--duration", "0.1")  # fmt: skip
    assert rc == 0 and "identical to the emulation" in out


def test_too_few_poses_and_bad_rows_are_one_line(flow, capsys, tmp_path):
    lines = (flow / "meas" / "measurements.csv").read_text().splitlines()
    few = tmp_path / "few.csv"
    few.write_text("\n".join(lines[:5]) + "\n")
    rc, out, err = cli(capsys, "calibrate", "--platform", "utn-dynamic", "--measurements", few, "--out", tmp_path / "o")
    assert rc == 2 and err.count("\n") == 1
    assert "4 poses give 24 equations for 33 unknowns (33 parameters); give at least 6 poses" in err
    bad = tmp_path / "bad.csv"
    bad.write_text("\n".join(lines[:3] + [lines[3].replace(lines[3].split(",")[8], "nan", 1)] + lines[4:]) + "\n")
    rc, out, err = cli(capsys, "calibrate", "--platform", "utn-dynamic", "--measurements", bad, "--out", tmp_path / "o")
    assert rc == 2 and f"{bad}:4: column pz: values must be finite, got 'nan'" in err and err.count("\n") == 1
    assert not (tmp_path / "o").exists()


def test_an_identification_that_does_not_converge_exits_1(flow, capsys, tmp_path):
    lines = (flow / "meas" / "measurements.csv").read_text().splitlines()
    rows = [ln.split(",") for ln in lines[1:]]
    shuffled = [",".join(rows[(k + 1) % len(rows)][:6] + rows[k][6:]) for k in range(len(rows))]  # readings vs poses
    f = tmp_path / "shuffled.csv"
    f.write_text(lines[0] + "\n" + "\n".join(shuffled) + "\n")
    rc, out, err = cli(capsys, "calibrate", "--platform", "utn-dynamic", "--measurements", f, "--out", tmp_path / "o")
    assert rc == 1 and "the identification did not converge" in err and err.count("\n") == 1
    assert "residual RMS" in out  # the result is still shown
    assert not (tmp_path / "o").exists()


def test_simulate_measurements_refuses_keys_that_are_not_geometric(capsys, tmp_path, flow):
    rc, _, err = cli(capsys, "simulate-measurements", "--platform", "utn-dynamic", "--poses", flow / "plan" / "poses.csv", "--errors", "plate_mass=±10%", "--out", tmp_path / "o")  # fmt: skip
    assert rc == 2 and "--errors: key 'plate_mass' is not a geometric error (keys: anchor, leg_offset)" in err


def test_the_calibration_commands_run_without_pydrake(flow, tmp_path):
    """plan-measurements, simulate-measurements and calibrate are numpy commands: with pydrake unimportable
    they run, and only their own command module is loaded."""
    from tests.cli.test_cli_lazy import run_blocked

    for argv, module in (
        (["plan-measurements", "--platform", "utn-dynamic", "--poses", "8", "--candidates", "200", "--out", tmp_path / "p", "--json"], "plan_measurements"),
        (["simulate-measurements", "--platform", "utn-dynamic", "--poses", flow / "plan" / "poses.csv", "--out", tmp_path / "m", "--json"], "simulate_measurements"),
        (["calibrate", "--platform", "utn-dynamic", "--measurements", tmp_path / "m" / "measurements.csv", "--no-plots", "--out", tmp_path / "c", "--json"], "calibrate"),
    ):  # fmt: skip
        status, out, err = run_blocked(*map(str, argv))
        assert status["rc"] == 0 and not status["pydrake"], err
        assert status["commands"] == [f"stewart_drake.commands.{module}"]
        json.loads(out)


def test_a_calibration_of_another_platform_exits_1_with_its_result(flow, capsys, tmp_path):
    """utn-dynamic's measurements calibrated as gonzalez-dutra-2009: exit 1 and one line; the summary and
    calibration.json (the result) are there, calibrated.yaml is not."""
    m = flow / "meas" / "measurements.csv"
    rc, out, err = cli(capsys, "calibrate", "--platform", "gonzalez-dutra-2009", "--measurements", m, "--no-plots", "--out", tmp_path / "o")  # fmt: skip
    assert rc == 1 and err.count("\n") == 1 and "the calibration is not usable: the calibrated model reads up to" in err
    assert "failed: the calibrated model reads up to" in out and "calibration.json written, no calibrated.yaml" in err
    d = json.loads((tmp_path / "o" / "calibration.json").read_text())
    assert d["converged"] and not d["ok"] and len(d["failures"]) == 1
    assert not (tmp_path / "o" / "calibrated.yaml").exists()


def test_copies_of_one_pose_exit_2(flow, capsys, tmp_path):
    lines = (flow / "meas" / "measurements.csv").read_text().splitlines()
    f = tmp_path / "copies.csv"
    f.write_text("\n".join([lines[0]] + [lines[1]] * 30) + "\n")
    rc, _, err = cli(capsys, "calibrate", "--platform", "utn-dynamic", "--measurements", f, "--out", tmp_path / "o")
    assert rc == 2 and err.count("\n") == 1 and "30 rows hold only 1 distinct poses (29 exact copies" in err
    assert not (tmp_path / "o").exists()


def test_simulated_readings_stay_within_the_stroke(flow, capsys, tmp_path):
    """anchor=±1m draws a machine whose legs would be ~2 m long on a 0.55–0.95 m stroke: refused in one line,
    nothing written; leg lengths of the machine drawn are what the message names."""
    rc, _, err = cli(capsys, "simulate-measurements", "--platform", "utn-dynamic", "--poses", flow / "plan" / "poses.csv", "--errors", "anchor=±1m", "--out", tmp_path / "o")  # fmt: skip
    assert rc == 2 and err.count("\n") == 1 and "--errors anchor=±1m: the machine drawn (seed 0) cannot reach" in err
    assert "outside the stroke [0.55, 0.95] m" in err and not (tmp_path / "o").exists()


def test_noise_free_measurements_calibrate(flow, capsys, tmp_path):
    """--noise length=0 position=0 angle=0: noise-free readings (the true machine's exactly), calibrated with the
    same statement: exit 0, the calibrated file equal to the truth to well below a micrometre (σ at the 1e-9 floor
    is ~0.1 µm at most on these poses)."""
    zero = ["--noise", "length=0", "position=0", "angle=0"]
    rc, _, _ = cli(capsys, "simulate-measurements", "--platform", "utn-dynamic", "--poses", flow / "plan" / "poses.csv", *zero, "--out", tmp_path / "m")  # fmt: skip
    assert rc == 0
    rc, out, _ = cli(capsys, "calibrate", "--platform", "utn-dynamic", "--measurements", tmp_path / "m" / "measurements.csv", *zero, "--no-plots", "--out", tmp_path / "c")  # fmt: skip
    assert rc == 0 and "warning: σ length, position, angle stated below 1e-09" in out
    lay = Layout(load_preset("utn-dynamic"), "pose")
    theta = lay.theta(load_platform(tmp_path / "c" / "calibrated.yaml"))
    assert np.abs(theta - lay.theta(load_platform(tmp_path / "m" / "truth" / "platform.yaml"))).max() < 1e-6
