"""Differentiated quantisation (issue 24, item 5c): a gentle motion written with 6 decimals at 10 kHz is
refused by dynamics, size and simulate (its accelerations are rounding noise), and ``--smooth TOL`` gives
the true forces back."""

import json
from pathlib import Path

import numpy as np
import pytest

import stewart_drake.examples
from stewart_drake.cli import main
from stewart_drake.core.geometry import load_platform
from stewart_drake.core.quantisation import RESOLVED, noisy_columns, quantum, smooth_columns
from stewart_drake.core.trajectory import TRAJECTORIES, Trajectory
from stewart_drake.design.sizing import size_trajectory

H = 1e-4  # 10 kHz


def _gentle(decimals=6, n=12000):
    """pz = 0.7 + 0.05 sin(t) m (5 cm at 1 rad/s), rounded to ``decimals`` places: 1 µm steps at 6."""
    t = np.arange(n) * H
    pz = np.round(0.7 + 0.05 * np.sin(t), decimals)
    return t, np.c_[0 * t, 0 * t, pz, 0 * t, 0 * t, 0 * t]


def _write(path, t, q):
    path.write_text(
        "t,px,py,pz,ax,ay,az\n" + "".join(f"{a:.4f},{q_[0]},{q_[1]},{q_[2]:.6f},0,0,0\n" for a, q_ in zip(t, q))
    )
    return str(path)


def test_quantum_and_noise_of_rounded_columns():
    """Rounding to 1 µm at 10 kHz: the quantum is found (to float precision) and the acceleration noise is the
    uniform-rounding model q/(√2·h²) where the motion moves many quanta per sample (0.05·sin(20 t): up to
    100 µm per sample, so the errors are independent and the file's second differences show the model's RMS,
    within the ~2 % sampling spread of 12000 samples); the slow motion's correlated errors show no more."""
    t = np.arange(12000) * H
    fast = np.round(np.c_[0 * t, 0 * t, 0.7 + 0.05 * np.sin(20 * t), 0 * t, 0 * t, 0 * t], 6)
    (c,) = noisy_columns(t, fast)
    model = 1e-6 / (np.sqrt(2) * H**2)
    assert c.column == 2 and c.quantum == pytest.approx(1e-6, rel=1e-6)
    assert c.accel_noise == pytest.approx(model, rel=0.02)
    # 0.05·20²: the peak, read at a stride where the rounding's error bound is at most RESOLVED of it (the stride's
    # own bias, (ω·m·h)²/12, is ~1e-4 here)
    assert c.motion_accel == pytest.approx(0.05 * 400, rel=RESOLVED)
    t, q = _gentle()
    (c,) = noisy_columns(t, q)
    assert c.column == 2 and 0.5 * model < c.accel_noise <= model
    assert c.motion_accel == pytest.approx(0.05 * np.sin(1.2), rel=RESOLVED)  # 0.05·sin(t) up to t = 1.2 s
    assert quantum(np.round(np.sin(np.arange(1000) * 0.01), 4) * np.pi / 180) == pytest.approx(1e-4 * np.pi / 180)
    assert noisy_columns(*_gentle(decimals=15)) == []
    tw = np.arange(40) * 0.1
    assert noisy_columns(tw, np.c_[0 * tw, 0 * tw, 0.7 + 0.01 * (tw > 2), 0 * tw, 0 * tw, 0 * tw]) == []


def test_a_staircase_coarser_than_the_motion_per_sample_is_refused():
    """A motion that moves less than one rounding step per sample is a staircase: its second differences
    are zero at most samples, and spikes of ±q/h² at each step. 0.1 mm at 10 kHz of a 1 cm motion and 4
    decimals at 1 kHz of a 60 s slow one: the noise is orders of magnitude above the motion's accelerations."""
    t = np.arange(0, 4, H)
    (c,) = noisy_columns(t, np.round(np.c_[0 * t, 0.01 * np.sin(2 * t), 0.7 + 0 * t, 0 * t, 0 * t, 0 * t], 4))
    # the staircase shows fewer spikes than white noise: its noise is at most the model's and > 1000x the motion
    assert c.column == 1 and c.accel_noise <= 1e-4 / (np.sqrt(2) * H**2) and c.accel_noise > 1000 * c.motion_accel
    t = np.arange(0, 60, 1e-3)
    slow = np.c_[0.05 * np.sin(0.2 * t), 0 * t, 0.7 + 0.02 * np.sin(0.1 * t), 0 * t, 0 * t, 0 * t]
    assert [c.column for c in noisy_columns(t, np.round(slow, 4))] == [0, 2]
    # an exact ramp on the quantum (every step one q) shows no noise: its second differences are all zero
    ramp = np.round(0.7 + 0.001 * np.arange(len(t)), 3)
    assert noisy_columns(t, np.c_[0 * t, 0 * t, ramp, 0 * t, 0 * t, 0 * t]) == []


@pytest.mark.parametrize("name", ["seed", "rotating"])
def test_the_shipped_trajectories_written_with_six_decimals_at_100_hz_pass(name):
    """The closed-form references written as a CSV would be (6 decimals, 100 samples/s): 1 µm of rounding at
    h = 10 ms is 7e-3 m/s² of noise against peaks of ~0.4 m/s² (seed) and ~1 rad/s² (rotating): small."""
    t = np.arange(0, 4, 0.01)
    q = np.round(TRAJECTORIES[name].pose(t), 6)
    assert noisy_columns(t, q) == []


def test_the_example_programs_samples_pass():
    """The shipped motion programs, sampled at 100 and 1000 samples/s and written with 9 decimals."""
    platform = load_platform("utn-kinematic")  # the platform the examples are written for
    for program in sorted(Path(stewart_drake.examples.__path__[0]).glob("*.stw")):
        for rate in (100.0, 1000.0):
            tr = Trajectory.from_program(program, platform, rate=rate)
            assert noisy_columns(tr.t, np.round(tr.q, 9)) == [], (program.name, rate)


def test_smoothing_spline_keeps_the_tolerance_and_the_true_acceleration():
    t, q = _gentle()
    s = smooth_columns(t, q, 1e-6)
    assert np.sqrt(np.mean((s - q) ** 2)) <= 1e-6 * (1 + 1e-9)  # the stated tolerance (RMS)
    assert noisy_columns(t, s) == []
    acc = np.diff(s[:, 2], 2) / H**2  # true: -0.05 sin(t), |a| <= 0.05 m/s²
    assert np.abs(acc - (-0.05 * np.sin(t[1:-1]))).max() < 0.01


@pytest.mark.parametrize("command", ["dynamics", "size", "simulate"])
def test_commands_refuse_and_smooth(tmp_path, capsys, command):
    if command == "simulate":
        pytest.importorskip("pydrake")  # runs a Drake-backed command; the numpy-layer run (no pydrake) skips it
    f = _write(tmp_path / "gentle.csv", *_gentle(n=6000))
    extra = ["--out", str(tmp_path / "o"), "--no-progress", "--duration", "0.3"] if command == "simulate" else []
    assert main([command, "--trajectory", f, *extra]) == 2
    err = capsys.readouterr().err
    assert "column pz is rounded too coarsely" in err and "--smooth TOL" in err and err.count("\n") == 1
    if command == "size":
        assert main(["size", "--trajectory", f, "--smooth", "1e-6", "--json"]) == 0
        out = json.loads(capsys.readouterr().out)
        t, q = _gentle(n=6000, decimals=15)
        true = size_trajectory(
            load_platform("utn-dynamic"),
            t,
            q,
            np.c_[0 * q[:, :2], 0.05 * np.cos(t), 0 * q[:, :3]],
            np.c_[0 * q[:, :2], -0.05 * np.sin(t), 0 * q[:, :3]],
        )
        # smoothed peak force within 1 % of the analytic motion's (it was ~100x it from the rounded file)
        assert max(r["peak_force_n"] for r in out["legs"]) == pytest.approx(np.abs(true.force).max(), rel=0.01)


def test_the_controller_and_trajectories_import_without_scipy_interpolate():
    """scipy.interpolate (~1 s of CPU to import) loads only when a trajectory is smoothed: importing the
    controller, the trajectories and the firmware certificate's section (a fresh interpreter) does not."""
    import subprocess
    import sys

    code = (
        "import sys, stewart_drake.control, stewart_drake.core.trajectory, stewart_drake.analyses.firmware_certificate;"
        "print('scipy.interpolate' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["False"]


def _write_rows(path, t, q, decimals):
    rows = np.c_[t, np.round(q, decimals)]
    np.savetxt(path, rows, delimiter=",", fmt=["%.6f"] + [f"%.{decimals}f"] * 6, header="t,px,py,pz,a,b,g", comments="")
    return str(path)


@pytest.mark.parametrize(
    "case,command",
    [("10khz_0.1mm", "dynamics"), ("1khz_4_decimals", "dynamics"), ("1khz_4_decimals", "simulate")],
)
def test_commands_refuse_staircases(tmp_path, capsys, case, command):
    """A 10 kHz CSV in mm rounded to 0.1 mm of a gentle 5 mm motion, and a 60 s slow motion at 1 kHz in metres
    with 4 decimals: each moves less than a rounding step per sample, so its differentiated accelerations
    are steps of q/h², thousands of times the motion's. Refused naming the file, the column and the step."""
    if command == "simulate":
        pytest.importorskip("pydrake")  # runs a Drake-backed command; the numpy-layer run (no pydrake) skips it
    if case == "10khz_0.1mm":
        t = np.arange(0, 1, 1e-4)
        f = _write_rows(tmp_path / "fine.csv", t, np.c_[0 * t, 5 * np.sin(2 * t), 700 + 0 * t, 0 * t, 0 * t, 0 * t], 1)
        args, column, step = ["--length-unit", "mm"], "py", "0.0001 m"
    else:
        t = np.arange(0, 60, 1e-3)
        slow = np.c_[0.05 * np.sin(0.2 * t), 0 * t, 0.7 + 0.02 * np.sin(0.1 * t), 0 * t, 0 * t, 0 * t]
        f = _write_rows(tmp_path / "slow.csv", t, slow, 4)
        args, column, step = [], "px", "0.0001 m"
    if command == "simulate":
        args = ["--out", str(tmp_path / "o"), "--no-progress", "--duration", "0.3"]
    assert main([command, "--trajectory", f, *args]) == 2
    err = capsys.readouterr().err
    assert f"{f}: column {column} is rounded too coarsely for its motion: steps of {step}" in err
    assert "--smooth TOL" in err and err.count("\n") == 1
