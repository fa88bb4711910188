"""The calibration commands take the user's machine file as ``--platform``: plan-measurements and
simulate-measurements use its platform (the geometry: the same files as from its platform file alone), and
calibrate reads the measurements its ``calibration:`` names and writes a calibrated platform without the payload
(the machine adds the payload to the plate itself: a calibrated file carrying it would count it twice)."""

from __future__ import annotations

import json

import numpy as np
import pytest

import stewart_drake as sd
from stewart_drake.core.geometry import load_platform
from tests.cli._inprocess import cli

NEWCOMER = "examples/newcomer-210kg.yaml"


@pytest.fixture(scope="module")
def machine_and_platform(tmp_path_factory):
    """A copy of the 210 kg machine whose ``calibration:`` names ``meas/measurements.csv`` beside it, and its
    platform alone as a platform file."""
    d = tmp_path_factory.mktemp("machine")
    text = open(NEWCOMER, encoding="utf-8").read()
    (d / "machine.yaml").write_text(text + "calibration: meas/measurements.csv\n", encoding="utf-8")
    sd.load_machine(NEWCOMER).platform.to_yaml(d / "platform.yaml")
    return d


def test_the_machine_file_gives_the_files_its_platform_gives(machine_and_platform, capsys):
    d = machine_and_platform
    for source in ("machine", "platform"):
        rc, _, err = cli(capsys, "plan-measurements", "--platform", d / f"{source}.yaml", "--poses", 30,
                         "--candidates", 300, "--out", d / f"plan-{source}")  # fmt: skip
        assert rc == 0, err
        rc, _, err = cli(capsys, "simulate-measurements", "--platform", d / f"{source}.yaml", "--poses",
                         d / f"plan-{source}" / "poses.csv", "--seed", 4, "--out", d / f"meas-{source}")  # fmt: skip
        assert rc == 0, err
    for name in ("plan/poses.csv", "meas/measurements.csv", "meas/truth/platform.yaml"):
        folder, _, file = name.partition("/")
        assert (d / f"{folder}-machine" / file).read_bytes() == (d / f"{folder}-platform" / file).read_bytes()


def test_calibrate_reads_the_machines_measurements_and_leaves_the_payload_out(machine_and_platform, capsys):
    d = machine_and_platform
    rc, _, err = cli(capsys, "plan-measurements", "--platform", d / "machine.yaml", "--poses", 30, "--candidates", 300,
                     "--out", d / "plan")  # fmt: skip
    assert rc == 0, err
    rc, _, err = cli(capsys, "simulate-measurements", "--platform", d / "machine.yaml", "--poses",
                     d / "plan" / "poses.csv", "--seed", 4, "--out", d / "meas")  # fmt: skip
    assert rc == 0, err
    rc, out, err = cli(capsys, "calibrate", "--platform", d / "machine.yaml", "--out", d / "cal", "--json")
    assert rc == 0, err
    result = json.loads(out)
    assert result["source"].endswith("measurements.csv") and result["converged"]
    calibrated = load_platform(d / "cal" / "calibrated.yaml")
    bare, loaded = sd.load_machine(d / "machine.yaml").platform, sd.load_machine(d / "machine.yaml").loaded_platform
    assert calibrated.mass == bare.mass == 60.0 != loaded.mass  # the 150 kg payload stays in the machine


@pytest.mark.parametrize("source", [NEWCOMER, "utn-dynamic"])
def test_calibrate_without_measurements_names_the_option(source, tmp_path, capsys):
    rc, out, err = cli(capsys, "calibrate", "--platform", source, "--out", tmp_path / "cal")
    assert rc == 2 and out == ""
    assert err.strip() == (
        f"stewart-drake calibrate: error: --measurements is required: --platform {source} is not a machine file "
        "naming them in calibration:"
    )
    assert not (tmp_path / "cal").exists()


def test_the_api_takes_a_machine_file_or_a_machine_as_its_platform(machine_and_platform):
    d = machine_and_platform
    machine = sd.load_machine(d / "machine.yaml")
    plans = [sd.plan_measurements(p, 12, candidates=200) for p in (d / "machine.yaml", machine, machine.platform)]
    assert all(np.array_equal(plans[0].poses, p.poses) for p in plans[1:])
