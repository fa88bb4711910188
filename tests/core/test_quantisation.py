"""Differentiated quantisation (issue 24, item 5c): a gentle motion written with 6 decimals at 10 kHz is
refused by dynamics, size and simulate (its accelerations are rounding noise), and ``--smooth TOL`` gives
the true forces back."""

import json

import numpy as np
import pytest

from stewart_drake.cli import main
from stewart_drake.core.geometry import load_platform
from stewart_drake.core.quantisation import noisy_columns, smooth_columns
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


def test_noise_ratio_is_the_white_noise_value():
    """Rounding to 1 µm: RMS(Δ⁴)/RMS(Δ²) = √(70/6) for white noise (within the sampling spread of 12000
    samples, ~2 %); unrounded, the column is smooth (ratio ~(ωh)²) and not flagged; a few waypoints (a
    piecewise-linear file) are not noise."""
    t, q = _gentle()
    (c,) = noisy_columns(t, q)
    assert c.column == 2 and c.ratio == pytest.approx(np.sqrt(70 / 6), rel=0.03)
    # the acceleration noise is RMS(Δ²)/h², Δ² of independent errors uniform in ±δ/2 (variance 6 δ²/12, δ = 1 µm;
    # real rounding is correlated where the motion is slow, so the model is drawn here, seeded); the sampling
    # spread of 12000 samples is ~1 %
    noise = np.random.default_rng(5).uniform(-0.5e-6, 0.5e-6, len(t))
    (c,) = noisy_columns(t, np.c_[q[:, :2], 0.7 + 0.05 * np.sin(t) + noise, q[:, 3:]])
    assert c.accel_noise == pytest.approx(np.sqrt(6 / 12) * 1e-6 / H**2, rel=0.03)
    assert noisy_columns(*_gentle(decimals=15)) == []
    tw = np.arange(40) * 0.1
    assert noisy_columns(tw, np.c_[0 * tw, 0 * tw, 0.7 + 0.01 * (tw > 2), 0 * tw, 0 * tw, 0 * tw]) == []


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
