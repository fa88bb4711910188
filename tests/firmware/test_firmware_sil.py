"""Software in the loop: the compiled firmware tick in the Drake diagram gives closed-loop logs
bit-identical to the Python engine's (every preset, seed and rotating trajectories), and a user's C file
runs through ``simulate --firmware``."""

import dataclasses
import json

import numpy as np
import pytest

from stewart_drake.cli import main
from stewart_drake.core.geometry import PRESETS, load_preset
from stewart_drake.core.trajectory import fit_trajectory, get_trajectory
from stewart_drake.drake.simulation import Scenario, build_simulation
from tests.firmware.firmware_cache import firmware_cache  # noqa: F401

DURATION = 0.12


def _logs_equal(a, b):
    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, np.ndarray):
            assert np.array_equal(x, y), f.name


@pytest.mark.parametrize("name", PRESETS)
@pytest.mark.parametrize("trajectory", ["seed", "rotating"])
def test_closed_loop_logs_bit_identical(name, trajectory):
    p = load_preset(name)
    traj = get_trajectory(trajectory)
    if name != "utn-dynamic":  # the references are made for utn-dynamic: move them into this platform's stroke
        traj = fit_trajectory(traj, p)
    logs = {eng: build_simulation(Scenario(p, traj, "fixed", engine=eng)).run(DURATION) for eng in ("python", "c")}
    _logs_equal(logs["python"], logs["c"])
    assert len(logs["c"].tick_times()) == round(DURATION / 1e-3)


def test_latency_modes_and_no_feedforward_identical():
    from stewart_drake.control import ControllerConfig, DspTiming

    p = load_preset("utn-dynamic")
    for latency in ("computation", "none"):
        timing = DspTiming(latency=latency, command_range=float(p.legs.max_force))
        cfg = ControllerConfig.for_platform(p, timing)
        a = build_simulation(Scenario(p, "seed", "fixed", cfg, feedforward=False, engine="python")).run(0.06)
        b = build_simulation(Scenario(p, "seed", "fixed", cfg, feedforward=False, engine="c")).run(0.06)
        _logs_equal(a, b)


def test_simulate_cli_runs_a_users_firmware(tmp_path, capsys):
    fw = tmp_path / "fw"
    # gains designed over the seed reference, as simulate designs them: the firmware then is the run's controller
    assert (
        main(
            [
                "firmware",
                "generate",
                "--platform",
                "utn-dynamic",
                "--trajectory",
                "seed",
                "--out",
                str(fw),
                "--no-compile",
            ]
        )
        == 0
    )
    capsys.readouterr()
    runs = {}
    for extra in ([], ["--engine", "python"], ["--engine", "c"], ["--firmware", str(fw / "sd_firmware.c")]):
        out = tmp_path / f"sim{len(runs)}"
        assert (
            main(
                [
                    "simulate",
                    "--platform",
                    "utn-dynamic",
                    "--duration",
                    "0.05",
                    "--no-progress",
                    "--out",
                    str(out),
                    *extra,
                ]
            )
            == 0
        )
        s = json.loads(capsys.readouterr().out)
        runs[tuple(extra[-1:])] = (s, np.load(out / "log.npz"))
    firmware = (str(fw / "sd_firmware.c"),)
    assert runs[()][0]["engine"] == "c"  # the default: the compiled firmware (a compiler is found here)
    assert runs[("python",)][0]["engine"] == "python" and runs[firmware][0]["firmware"].endswith("sd_firmware.c")
    base = runs[("python",)][1]
    for key in ((), ("c",), firmware):
        for k in base.files:
            assert np.array_equal(base[k], runs[key][1][k]), (key, k)


def test_simulate_engine_c_refuses_float_controller(capsys):
    assert main(["simulate", "--controller", "float", "--engine", "c", "--duration", "0.01", "--no-progress"]) == 2
    assert "--engine c" in capsys.readouterr().err


def test_simulate_refuses_firmware_with_the_python_engine(capsys, tmp_path):
    """``--firmware`` runs C: asked for together with ``--engine python`` it is a contradiction, refused
    before anything runs (not one of them silently ignored)."""
    fw = tmp_path / "fw.c"
    fw.write_text("")
    argv = ["simulate", "--firmware", str(fw), "--engine", "python", "--duration", "0.01", "--out", str(tmp_path / "o")]
    assert main([*argv, "--no-progress"]) == 2
    assert capsys.readouterr().err.strip().endswith("cannot run with --engine python; drop one of them")
    assert not (tmp_path / "o").exists()


def _bad_firmware(tmp_path, kind):
    """A --firmware value as a user writes it (relative to ``tmp_path``) and the error it must give."""
    from stewart_drake.errors import FirmwareError

    if kind == "folder":
        (tmp_path / "fwdir").mkdir()
        return "fwdir", FirmwareError.FILE_FOLDER.format(what="--firmware", path="fwdir")
    if kind == "missing":
        return "nope.c", FirmwareError.FILE_MISSING.format(what="--firmware", path="nope.c")
    if kind == "no name":
        return "", FirmwareError.FILE_NO_NAME.format(what="--firmware", path="")
    return "/dev/null", FirmwareError.FILE_SPECIAL.format(what="--firmware", path="/dev/null")


@pytest.mark.parametrize("kind", ["folder", "missing", "no name", "device"])
def test_simulate_names_a_firmware_that_is_not_a_file(kind, capsys, tmp_path, monkeypatch):
    """A --firmware value that is no C file is refused in one line naming the option and the value as
    written (it said "does not exist" for a folder, and "" became the current folder), before the run."""
    monkeypatch.chdir(tmp_path)
    value, message = _bad_firmware(tmp_path, kind)
    assert main(["simulate", "--firmware", value, "--duration", "0.01", "--out", "o", "--no-progress"]) == 2
    assert capsys.readouterr().err.strip() == f"stewart-drake simulate: error: {message}"
    assert not (tmp_path / "o").exists()


def test_simulate_firmware_without_a_tick_or_ik_names_the_users_file(capsys, tmp_path, monkeypatch):
    """A firmware without sd_tick named the cached library (sd-<hash>.so), and one without sd_ik gave the
    loader's "cannot load library ... undefined symbol" with the cache path: both now name the user's file
    as written."""
    from stewart_drake.errors import FirmwareError

    monkeypatch.chdir(tmp_path)

    ik_only = tmp_path / "ik_only.c"
    ik_only.write_text(
        '#include "sd_firmware.h"\nint sd_ik(const sd_word pose[6], sd_word lengths[6])\n'
        "{ for (int i = 0; i < 6; i++) lengths[i] = pose[i]; return 0; }\n"
    )
    empty = tmp_path / "empty.c"
    empty.write_text("")
    for fw, message in (
        ("ik_only.c", FirmwareError.NO_TICK.format(name="ik_only.c")),
        ("empty.c", FirmwareError.NO_IK.format(path="empty.c")),
    ):
        argv = ["simulate", "--firmware", fw, "--duration", "0.01", "--out", str(tmp_path / "o"), "--no-progress"]
        assert main(argv) == 2
        assert capsys.readouterr().err.strip() == f"stewart-drake simulate: error: {message}"
        assert not (tmp_path / "o").exists()
