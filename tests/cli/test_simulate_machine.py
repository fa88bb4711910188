"""``simulate`` runs a machine: the example 210 kg machine tracks with its own number format and chatters with
the DSP's default one; a firmware's recorded format reaches the loop (adopted, with a warning naming both
values); a firmware generated for another platform is refused; flags and ``--set`` name what the user wrote."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import numpy as np
import pytest

import stewart_drake as sd
from stewart_drake.api.simulation import plan_run
from stewart_drake.cli import main
from stewart_drake.errors import FIRMWARE_FORMAT_ADOPTED, MachineError
from stewart_drake.firmware.fingerprint import read_fingerprint
from stewart_drake.spec import load_machine

EXAMPLE = Path(__file__).parents[2] / "examples" / "newcomer-210kg.yaml"
RUN = ["--duration", "1", "--no-progress"]  # 1 s of the rotating motion: the chatter shows from the start
needs_cc = pytest.mark.skipif(shutil.which("cc") is None and shutil.which("gcc") is None, reason="no C compiler")


def simulate(tmp_path, *args):
    out = tmp_path / f"run{len(list(tmp_path.iterdir()))}"
    rc = main(["simulate", "--machine", str(EXAMPLE), *RUN, "--out", str(out), *args])
    summary = json.loads((out / "summary.json").read_text()) if (out / "summary.json").exists() else None
    return rc, summary


@pytest.fixture(scope="module")
def firmware_30um(tmp_path_factory):
    """A firmware generated at a 30 µm length LSB for the example machine's platform (written as a platform
    file), and one generated for utn-dynamic."""
    d = tmp_path_factory.mktemp("fw")
    load_machine(EXAMPLE).platform.to_yaml(d / "platform.yaml")
    assert main(["firmware", "generate", "--platform", str(d / "platform.yaml"), "--length-lsb", "3e-5", "--out",
                 str(d / "fw30"), "--no-compile"]) == 0  # fmt: skip
    assert main(["firmware", "generate", "--platform", "utn-dynamic", "--out", str(d / "utn"), "--no-compile"]) == 0
    return d


def test_the_example_machine_tracks_with_its_format(tmp_path, capsys):
    rc, summary = simulate(tmp_path)
    assert rc == 0, capsys.readouterr().err
    assert summary["firmware_format"] == {"word_bits": 16, "length_lsb_m": 3e-05, "trig": "tfr16", "convention": "utn"}
    # the plate carries the 150 kg payload: the loop's model is 210 kg
    assert load_machine(EXAMPLE).loaded_platform.mass == 210.0


def test_the_default_format_chatters_on_it(tmp_path, capsys):
    rc, summary = simulate(tmp_path, "--length-lsb", "1mm")
    err = capsys.readouterr().err
    assert rc == 1 and "chatter:" in err and "the IK's length LSB (1 mm)" in err
    assert summary["firmware_format"]["length_lsb_m"] == 0.001


@needs_cc
def test_the_firmware_format_is_adopted(tmp_path, capsys, firmware_30um):
    """The machine says 1 mm, the firmware was generated at 30 µm: the loop runs the firmware's 30 µm, says so,
    and tracks."""
    rc, summary = simulate(tmp_path, "--length-lsb", "1mm", "--firmware", str(firmware_30um / "fw30"))
    err = capsys.readouterr().err
    assert FIRMWARE_FORMAT_ADOPTED.format(what="length LSB 30 µm", machine="1 mm") in err
    assert rc == 0, err
    assert summary["firmware_format"]["length_lsb_m"] == 3e-05
    # within the tracking verdict's bound: 5 % of the 300 mm stroke range
    assert summary["max_leg_error_mm"] < 15.0


def test_the_api_adopts_and_says_so(firmware_30um):
    machine = sd.load_machine(EXAMPLE, ["firmware.length_lsb=1mm"])
    plan = plan_run(machine, duration=0.1, firmware=firmware_30um / "fw30")  # a plan: nothing is run
    assert plan.config.ik_format.length_lsb == 3e-05 and plan.machine.firmware.length_lsb == 3e-05
    assert plan.warnings[0] == FIRMWARE_FORMAT_ADOPTED.format(what="length LSB 30 µm", machine="1 mm")
    # the same format: nothing to adopt, nothing said
    plan = plan_run(sd.load_machine(EXAMPLE), duration=0.1, firmware=firmware_30um / "fw30")
    assert plan.warnings == ()


def test_a_firmware_for_another_platform_is_refused(tmp_path, capsys, firmware_30um):
    rc, _ = simulate(tmp_path, "--firmware", str(firmware_30um / "utn"))
    err = capsys.readouterr().err
    assert rc == 2
    assert "was generated for platform utn-dynamic (" in err and "not for this run's newcomer-6dof-sim (" in err
    with pytest.raises(MachineError, match="was generated for platform utn-dynamic"):
        plan_run(sd.load_machine(EXAMPLE), duration=0.1, firmware=firmware_30um / "utn")


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--period", "-1"], "--period must be > 0 s, got -1"),
        (["--set", "controller.period=-1"], "controller.period must be > 0 s, got -1"),
        (["--length-lsb", "30parsecs"], "--length-lsb: cannot read '30parsecs' as a number with a unit"),
        (["--word-bits", "24"], "--word-bits must be 16 with trig tfr16 (use trig exact), got 24"),
        (["--set", "controller.perod=1ms"], "unknown key 'controller.perod' (did you mean 'controller.period'?)"),
        (["--platform", "utn-dynamic"], "give --machine or --platform, not both"),
    ],
)
def test_flags_and_paths_are_named_as_written(tmp_path, capsys, args, message):
    rc, _ = simulate(tmp_path, *args)
    err = capsys.readouterr().err
    assert rc == 2 and message in err and err.count("\n") == 1, err


def test_api_errors_name_spec_paths():
    with pytest.raises(MachineError, match=r"^controller\.period must be > 0 s, got -1$"):
        sd.simulate(sd.load_platform("utn-dynamic"), period=-1)
    with pytest.raises(MachineError, match=r"^run\.duration must be > 0 s, got -1$"):
        sd.simulate(sd.load_platform("utn-dynamic"), duration=-1)
    with pytest.raises(MachineError, match=r"^firmware\.length_lsb must be > 0 m, got 0$"):
        sd.simulate(sd.load_platform("utn-dynamic"), **{"firmware.length_lsb": 0})


def test_a_firmware_generated_for_the_machine_runs_its_format(tmp_path):
    machine = sd.load_machine(EXAMPLE)
    r = sd.firmware.generate(machine, tmp_path / "fw", compile=False)
    assert r.config.ik_format == machine.firmware.qformat() and r.config.convention == "utn"
    assert r.config.timing.sample_period == machine.controller.period
    assert r.config.timing.sensor_resolution == machine.sensors.resolution
    # the gains are designed with the payload on the plate: those of the 210 kg plate, not of the bare 60 kg one
    bare = sd.firmware.generate(machine.platform, tmp_path / "bare", compile=False, length_lsb=3e-5)
    assert r.config.gains.kp != bare.config.gains.kp
    # the firmware and the machine agree: the loop adopts nothing
    assert plan_run(machine, duration=0.1, firmware=tmp_path / "fw").warnings == ()


def test_the_machine_sensor_noise_is_drawn_from_its_seed():
    machine = sd.load_machine(EXAMPLE, ["sensors.noise=1um", "run.seed=3"])
    noise = plan_run(machine, duration=0.1).scenario.sensor.noise
    assert noise.shape == (102, 6)  # ticks 0..100 and one more (the tick at the run's end)
    # σ of 612 draws: its relative standard error is 1/sqrt(2·612) ≈ 2.9 %; 15 % is five of them
    assert abs(noise.std() / 1e-6 - 1) < 0.15
    assert (plan_run(machine, duration=0.1).scenario.sensor.noise == noise).all()
    other = plan_run(machine.replace(**{"run.seed": 4}), duration=0.1).scenario.sensor.noise
    assert not (other == noise).all()
    assert plan_run(sd.load_machine(EXAMPLE), duration=0.1).scenario.sensor is None  # noise 0: an ideal sensor


def test_a_motion_program_is_a_machine_motion():
    platform = sd.load_platform("utn-dynamic")
    program = Path(__file__).parents[2] / "examples" / "seed_004.stw"
    traj = plan_run(platform, program, duration=0.1).scenario.trajectory
    assert traj.name == "seed_004"
    assert np.allclose(traj.pose(0.0), platform.home_pose(), atol=1e-12)  # a program starts at home


def test_a_preset_firmware_without_the_hash_is_compared_by_the_preset(tmp_path, firmware_30um):
    """A module generated before the platform's hash was recorded names its platform only: a preset name is
    enough to compare (its file's content)."""
    old = tmp_path / "old"
    old.mkdir()
    for f in ("sd_firmware.c", "sd_firmware.h"):
        text = (firmware_30um / "utn" / f).read_text()
        (old / f).write_text(re.sub(r', "platform_hash": "[0-9a-f]+"', "", text))
    assert read_fingerprint(old / "sd_firmware.c")[0]["platform_hash"] is None
    with pytest.raises(MachineError, match="was generated for platform utn-dynamic"):
        plan_run(sd.load_machine(EXAMPLE), duration=0.1, firmware=old)
    assert plan_run(sd.load_platform("utn-dynamic"), duration=0.1, firmware=old).warnings == ()


@needs_cc
def test_firmware_generate_for_a_machine_and_check_it(tmp_path, capsys):
    """``firmware generate --machine``: the machine's format and payload-designed gains, recorded with the
    machine file, so that ``firmware check`` emulates the same module, gains included."""
    fw = tmp_path / "fw"
    assert main(["firmware", "generate", "--machine", str(EXAMPLE), "--out", str(fw), "--no-compile"]) == 0
    recorded = read_fingerprint(fw / "sd_firmware.c")[0]
    assert (recorded["platform"], recorded["length_lsb"], recorded["word_bits"]) == (str(EXAMPLE), 3e-05, 16)
    capsys.readouterr()
    assert main(["firmware", "check", str(fw / "sd_firmware.c"), "--poses", "500", "--duration", "0.05"]) == 0
    assert "identical to the emulation" in capsys.readouterr().out
    argv = ["firmware", "generate", "--machine", str(EXAMPLE), "--platform", "utn-dynamic", "--out", str(tmp_path)]
    assert main(argv) == 2
    assert "give --machine or --platform, not both" in capsys.readouterr().err


def test_the_certificate_takes_the_machines_format():
    machine = sd.load_machine(EXAMPLE)
    cert = sd.firmware.certify(machine, max_cells=20_000).to_dict()
    assert cert["format"] == {"word_bits": 16, "length_lsb_m": 3e-05, "trig": "tfr16", "convention": "utn"}
    assert not cert["saturation_possible"]  # the example's 16-bit words hold its legs at 30 µm
    assert sd.firmware.certify(machine, length_lsb=1e-3, max_cells=2000).to_dict()["format"]["length_lsb_m"] == 1e-3


def test_format_flags_are_one_format(tmp_path, capsys):
    """--word-bits 24 needs --trig exact: given together they are checked together (the C engine's module has
    16-bit words: the emulation runs wider ones)."""
    argv = ["--word-bits", "24", "--trig", "exact", "--length-lsb", "10um", "--engine", "python", "--duration", "0.2"]
    rc, summary = simulate(tmp_path, *argv)
    assert rc == 0, capsys.readouterr().err
    assert summary["firmware_format"] == {"word_bits": 24, "length_lsb_m": 1e-05, "trig": "exact", "convention": "utn"}
    # a path given by a flag and by --set is named as the path the user set last
    rc, _ = simulate(tmp_path, "--word-bits", "24", "--set", "firmware.trig=exact", "--set", "firmware.word_bits=40")
    assert rc == 2 and "firmware.word_bits must be an integer 8..31, got 40" in capsys.readouterr().err


def test_a_loop_refuses_a_format_that_cannot_hold_the_stroke(capsys):
    """16-bit words at 20 µm clamp every set-point above 0.655 m on utn-dynamic (stroke end 0.95 m): the run is
    refused before it starts, naming the spec path in Python and the flag on the command line."""
    import stewart_drake as sd
    from stewart_drake.cli import main
    from stewart_drake.errors import MachineError

    with pytest.raises(
        MachineError, match=r"^firmware\.length_lsb 2e-05 m in 16-bit words holds lengths up to 0\.65534"
    ):
        sd.simulate("utn-dynamic", duration=0.01, **{"firmware.length_lsb": 2e-5})
    assert main(["simulate", "--platform", "utn-dynamic", "--length-lsb", "20um", "--duration", "0.01"]) == 2
    assert "--length-lsb 2e-05 m in 16-bit words" in capsys.readouterr().err
