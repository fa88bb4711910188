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
