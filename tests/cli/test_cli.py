import importlib
import json
import subprocess
import sys

import numpy as np
import pytest

from stewart_drake.cli import main
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths


def run(capsys, *argv):
    rc = main(list(argv))
    out, err = capsys.readouterr()
    return rc, out, err


def test_ik_json(capsys):
    rc, out, _ = run(capsys, "ik", "--pose", "0", "0", "100", "0", "0", "0", "--json")
    d = json.loads(out)
    assert rc == 0 and d["length_unit"] == "mm" and d["within_stroke"] is True and d["violations"] == []
    np.testing.assert_allclose(d["lengths"], 473.187, atol=1e-3)


def test_ik_units_and_convention(capsys):
    rc, out, _ = run(
        capsys,
        "ik",
        "--platform",
        "utn-dynamic",
        "--pose",
        "-0.1",
        "0.05",
        "0.7",
        "0.1",
        "0.05",
        "-0.1",
        "--length-unit",
        "m",
        "--angle-unit",
        "pi",
        "--convention",
        "zyx",
        "--json",
    )
    p = load_preset("utn-dynamic")
    expect = leg_lengths(p, [-0.1, 0.05, 0.7, 0.1 * np.pi, 0.05 * np.pi, -0.1 * np.pi], "zyx")
    np.testing.assert_allclose(json.loads(out)["lengths"], expect, rtol=1e-14)


def test_ik_violation_exit_1(capsys):
    rc, out, _ = run(capsys, "ik", "--pose", "0", "0", "600", "0", "0", "0", "--json")
    d = json.loads(out)
    assert rc == 1 and d["within_stroke"] is False
    assert {v["leg"] for v in d["violations"]} == {1, 2, 3, 4, 5, 6}
    assert all(v["side"] == "max" and v["limit"] == pytest.approx(700.0) for v in d["violations"])


def test_ik_poses_csv(tmp_path, capsys):
    f = tmp_path / "p.csv"
    f.write_text("px,py,pz,a,b,g\n0,0,100,0,0,0\n10,10,140,36,0,18\n")
    rc, out, _ = run(capsys, "ik", "--poses", str(f), "--json")
    res = json.loads(out)["results"]
    assert len(res) == 2
    np.testing.assert_allclose(res[1]["lengths"][0], 638.659, atol=1e-3)
    f.write_text("0,0,100,0,0,0\n0,0,abc,0,0,0\n")
    rc, out, err = run(capsys, "ik", "--poses", str(f))
    assert rc == 2 and err.strip() == f"stewart-drake ik: error: {f}:2: column 3: not a number: 'abc'"


@pytest.mark.parametrize(
    "argv, message",
    [
        (["ik", "--platform", "nope", "--pose", "0", "0", "0", "0", "0", "0"], "unknown platform 'nope'"),
        (["ik", "--poses", "/nonexistent.csv"], "poses file '/nonexistent.csv' does not exist"),
    ],
)
def test_bad_arguments_one_line(capsys, argv, message):
    rc, out, err = run(capsys, *argv)
    assert rc == 2 and message in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err


def test_console_script_bad_unit_exits_2():
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "stewart_drake.cli",
            "ik",
            "--pose",
            "0",
            "0",
            "0",
            "0",
            "0",
            "0",
            "--angle-unit",
            "grad",
        ],
        capture_output=True,
        text=True,
    )
    assert r.returncode == 2 and "invalid choice: 'grad'" in r.stderr and "Traceback" not in r.stderr


def test_model_inspect_json(capsys):
    rc, out, _ = run(capsys, "model", "--platform", "gonzalez-dutra-2009", "--inspect", "--json")
    d = json.loads(out)
    assert d["constraints"] == 6 and len(d["actuators"]) == 6 and d["anchor_error_m"] < 1e-12


def test_model_write(tmp_path, capsys):
    rc, out, _ = run(capsys, "model", "--platform", "utn-dynamic", "--write", str(tmp_path))
    assert (tmp_path / "utn-dynamic.sdf").read_text().startswith("<?xml")


def test_report_writes_atomically(tmp_path, capsys, monkeypatch):
    # the report package itself (``from stewart_drake import report`` is the public sd.report, whose instance
    # dict monkeypatch would consult to restore the attribute)
    report = importlib.import_module("stewart_drake.report")

    out = tmp_path / "rep"
    rc, stdout, err = run(capsys, "report", "--only", "seed_table", "--out", str(out), "--quick")
    assert rc == 0 and (out / "index.html").exists(), err
    before = (out / "index.html").read_text()

    def boom(*a, **k):
        raise RuntimeError("disk full")

    monkeypatch.setattr(report, "render_html", boom)
    with pytest.raises(RuntimeError):
        report.write_report([], out)
    assert (out / "index.html").read_text() == before  # the old report is untouched
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".rep")]  # no half-written folder left
