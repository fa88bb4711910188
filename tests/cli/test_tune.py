"""``stewart-drake tune``: the tuned machine file written once and never over the original, bad input refused
naming the flag (exit 2), an unattainable bandwidth exits 1 with the best gains shown and nothing written."""

import json
from pathlib import Path

import pytest

from stewart_drake.spec import load_machine
from tests.cli._inprocess import cli

NEWCOMER = str(Path(__file__).parents[2] / "examples" / "newcomer-210kg.yaml")


def test_writes_the_tuned_machine_and_never_replaces_a_file_unasked(capsys, tmp_path):
    out = tmp_path / "tuned.yaml"
    # a 1 s run keeps the two verifying simulations short; the gains and format do not depend on it
    rc, stdout, err = cli(capsys, "tune", "--machine", NEWCOMER, "--set", "run.duration=1s", "--out", out)
    assert rc == 0, err
    d = json.loads(stdout)
    m = load_machine(str(out))
    assert {k: getattr(m.controller.gains, k) for k in ("kp", "ki", "kd", "kv")} == d["after"]["linear"]["gains"]
    assert m.firmware.length_lsb == d["format"]["length_lsb_m"] and d["out"] == str(out)
    assert d["after"]["linear"]["gain_margin_db"] >= 6.0 and d["after"]["linear"]["phase_margin_deg"] >= 30.0
    for side in ("before", "after"):  # before/after: margins, bandwidth, ripple, tracking
        assert {"linear", "ripple", "run"} <= set(d[side])
    assert d["seconds"] > 0
    before = out.read_text()
    rc, _, err = cli(capsys, "tune", "--machine", NEWCOMER, "--out", out)
    assert rc == 2 and "--out" in err and "--force" in err and out.read_text() == before


def test_the_machine_file_itself_and_a_folder_are_refused(capsys, tmp_path):
    own = tmp_path / "m.yaml"
    own.write_text(Path(NEWCOMER).read_text())
    rc, _, err = cli(capsys, "tune", "--machine", own, "--out", own, "--force")
    assert rc == 2 and "is the machine file itself" in err
    assert own.read_text() == Path(NEWCOMER).read_text()
    rc, _, err = cli(capsys, "tune", "--machine", own, "--out", tmp_path, "--force")
    assert rc == 2 and err.startswith(f"stewart-drake tune: error: --out {tmp_path} is a folder")


@pytest.mark.parametrize(
    "flag, value, words",
    [
        ("--gain-margin", "-3dB", "--gain-margin must be a number >= 0 dB"),
        ("--phase-margin", "200deg", "--phase-margin must be a number 0 … 180 deg"),
        ("--bandwidth", "fast", "--bandwidth"),
        ("--bandwidth", "600Hz", "--bandwidth must be a positive frequency below the Nyquist frequency 500 Hz"),
        ("--error-budget", "0mm", "--error-budget must be a number > 0 m"),
    ],
)
def test_bad_input_exits_2_naming_the_flag(capsys, tmp_path, flag, value, words):
    # written FLAG=VALUE: argparse takes a bare "-3dB" for an option
    rc, _, err = cli(capsys, "tune", "--machine", NEWCOMER, f"{flag}={value}", "--out", tmp_path / "t.yaml")
    lines = err.strip().splitlines()
    assert rc == 2 and len(lines) == 1 and words in lines[0], err
    assert not (tmp_path / "t.yaml").exists()


def test_unattainable_bandwidth_exits_1_showing_the_best(capsys, tmp_path):
    out = tmp_path / "t.yaml"
    rc, stdout, err = cli(
        capsys, "tune", "--machine", NEWCOMER, "--set", "run.duration=1s", "--bandwidth", "200Hz", "--out", out
    )
    assert rc == 1 and "no gains of the" in err and "bandwidth >= 200 Hz" in err
    d = json.loads(stdout)
    assert d["after"] is None and d["failures"] and not out.exists()
