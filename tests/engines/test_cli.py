"""``stewart-drake cross-check`` and ``model --format``: verdicts, exit codes, one-line errors, files written."""

import json
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from stewart_drake.engines.cross_check import engine_status

ROOT = Path(__file__).resolve().parents[2]


def cli(*args, cwd=None):
    return subprocess.run(
        [sys.executable, "-m", "stewart_drake", *args], capture_output=True, text=True, cwd=cwd or ROOT, timeout=120
    )


def test_cross_check_json_verdict():
    if any(engine_status().values()):
        pytest.skip("needs both engines (pip install 'stewart-drake[engines]')")
    r = cli("cross-check", "--platform", "gonzalez-dutra-2009", "--poses", "50", "--samples", "3", "--json")
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert out["ok"] and set(out["engines"]) == {"pinocchio", "mujoco"}
    assert all(e["kinematics"]["poses"] == 50 for e in out["engines"].values())


@pytest.mark.parametrize(
    "args, message",
    [
        (["--poses", "0"], "poses must be >= 1, got 0"),
        (["--samples", "1"], "samples must be >= 2, got 1"),
        (["--seed", "-1"], "seed must be >= 0, got -1"),
        (["--poses", "100001"], "poses 100001 is more than 100000"),
    ],
)
def test_cross_check_bad_sizes_are_one_line_errors(args, message):
    r = cli("cross-check", *args)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"stewart-drake cross-check: error: {message}")
    assert "Traceback" not in r.stderr


def test_model_format_urdf_writes_the_tree_and_its_closures(tmp_path):
    r = cli("model", "--platform", "utn-dynamic", "--format", "urdf", "--write", str(tmp_path / "m"))
    assert r.returncode == 0, r.stderr
    assert r.stdout.split() == [
        str(tmp_path / "m" / "utn-dynamic.urdf"),
        str(tmp_path / "m" / "utn-dynamic.closures.yaml"),
    ]
    doc = yaml.safe_load((tmp_path / "m" / "utn-dynamic.closures.yaml").read_text())
    assert doc["urdf"] == "utn-dynamic.urdf" and len(doc["closures"]) == 6


def test_model_format_refuses_a_foreign_file_and_writes_nothing(tmp_path):
    (tmp_path / "utn-dynamic.closures.yaml").write_text("mine\n")
    r = cli("model", "--platform", "utn-dynamic", "--format", "urdf", "--write", str(tmp_path))
    assert r.returncode == 2 and "was not written by stewart-drake" in r.stderr
    assert not (tmp_path / "utn-dynamic.urdf").exists()
    assert (tmp_path / "utn-dynamic.closures.yaml").read_text() == "mine\n"


def test_model_inspect_is_sdf_only():
    r = cli("model", "--format", "mjcf", "--inspect")
    assert r.returncode == 2 and "--inspect only applies with --format sdf" in r.stderr


def test_model_format_mjcf_prints_the_mjcf():
    r = cli("model", "--platform", "utn-dynamic", "--format", "mjcf")
    assert r.returncode == 0 and '<mujoco model="utn-dynamic">' in r.stdout
