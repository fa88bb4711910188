"""The viewer's readouts, reachability search, replay loading and CLI, and the animation's helpers —
without a browser (tests/report/test_browser.py drives the pages)."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.drake.animation import _frames, leg_warnings, log_saturating, stroke_margin
from stewart_drake.drake.viewer import (
    MAX_LABEL,
    ReplayError,
    labels,
    load_replay,
    nearest_reachable,
    reachable,
    readout,
)

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def utn():
    return load_preset("utn-dynamic")


def cli(*args, timeout=120):
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.run(
        [sys.executable, "-m", "stewart_drake.cli", *args],
        capture_output=True,
        text=True,
        env=env,
        cwd=ROOT,
        timeout=timeout,
    )


def test_readout_at_home(utn):
    r = readout(utn, utn.home_pose())
    np.testing.assert_array_equal(r.lengths, leg_lengths(utn, utn.home_pose()))
    np.testing.assert_allclose(r.margin, np.minimum(r.lengths - utn.L_min, utn.L_max - r.lengths))
    assert r.reachable and r.fraction == 1.0
    # A 3-6 platform has at most 16 assembly modes; the home lengths of utn-dynamic have all 16 real
    # (the forward-kinematics analysis finds the same), one of them the home pose itself.
    assert r.modes == 16 and r.modes_near == 1
    assert labels(r)[0] == f"L1 {r.lengths[0] * 1e3:.1f} mm, margin {r.margin[0] * 1e3:+.1f}"


def test_nearest_reachable_lies_on_the_boundary(utn):
    pose = utn.home_pose() + [0.05, 0.0, 0.35, 0.0, np.radians(10), 0.0]
    assert not reachable(utn, pose)
    near, s = nearest_reachable(utn, pose)
    assert 0 < s < 1 and reachable(utn, near)
    # Bisection to 2^-40 of the segment: a step of 1e-9 further along it is out of the stroke.
    assert not reachable(utn, utn.home_pose() + (s + 1e-9) * (pose - utn.home_pose()))
    assert stroke_margin(utn, leg_lengths(utn, near)).min() == pytest.approx(0.0, abs=1e-9)
    r = readout(utn, pose, modes=False)
    assert not r.reachable and r.modes is None
    text = labels(r)
    assert any(t.startswith("UNREACHABLE: legs") for t in text) and any(t.startswith("ghost:") for t in text)
    # every line fits the panel (the two unreachable lines were cut off), and the wrapped text is all there
    assert max(map(len, text)) <= MAX_LABEL and len(set(text)) == len(text)
    joined = " ".join(t.strip() for t in text)
    assert f"{r.fraction * 100:.0f} % from home" in joined and "out of stroke" in joined


def test_leg_warnings_band(utn):
    band = 0.05 * (utn.L_max - utn.L_min)
    L = np.array([utn.L_min + 0.5 * band, utn.L_min + 2 * band, utn.L_max - 0.5 * band, utn.L_max + 0.01, 0.7, 0.7])
    np.testing.assert_array_equal(leg_warnings(utn, L), [True, False, True, True, False, False])
    sat = np.array([False, False, False, False, True, False])
    np.testing.assert_array_equal(leg_warnings(utn, L, sat), [True, False, True, True, True, False])


def test_log_saturating_from_counts():
    status = np.zeros((4, 10))
    status[2:, 5] = 1  # leg 2 saturates once between samples 1 and 2
    status[3, 9] = 3
    sat = log_saturating(status)
    assert sat.shape == (4, 6)
    assert sat[2, 1] and sat[3, 5] and sat.sum() == 2


def test_frames_thin_to_the_rate():
    t = np.arange(4001) * 1e-3  # 4 s at 1 kHz
    idx = _frames(t, 25.0)
    assert len(idx) == 101 and idx[0] == 0 and idx[-1] == 4000
    np.testing.assert_allclose(np.diff(t[idx]), 0.04, atol=1e-3)


def _fake_log(path, utn, n=50):
    t = np.linspace(0, 1, n)
    pose = np.tile(utn.home_pose(), (n, 1))
    pose[:, 2] += 0.05 * np.sin(2 * np.pi * t)
    np.savez(path, t=t, pose=pose, status=np.zeros((n, 10)), platform="utn-dynamic")
    return t, pose


def test_load_replay_npz_and_run_csv(utn, tmp_path):
    t, pose = _fake_log(tmp_path / "log.npz", utn)
    t2, p2, sat, name = load_replay(tmp_path)
    np.testing.assert_array_equal(t2, t)
    np.testing.assert_array_equal(p2, pose)
    assert name == "utn-dynamic" and sat.shape == (len(t), 6) and not sat.any()
    run = tmp_path / "run"
    run.mkdir()
    rows = ["t,px,py,pz,alpha,beta,gama"] + [f"{k * 0.1},0,0,0.7,0.1,0,0" for k in range(5)]
    (run / "trajectory.csv").write_text("\n".join(rows) + "\n")
    (run / "summary.json").write_text(json.dumps({"platform": "utn-dynamic", "convention": "utn"}))
    t3, p3, sat3, name3 = load_replay(run)
    assert len(t3) == 5 and sat3 is None and name3 == "utn-dynamic"
    np.testing.assert_allclose(p3[0], [0, 0, 0.7, 0.1, 0, 0])


def test_load_replay_errors(tmp_path):
    with pytest.raises(ReplayError, match="no such file"):
        load_replay(tmp_path / "missing.npz")
    bad = tmp_path / "bad.csv"
    bad.write_text("a,b\n1,2\n")
    with pytest.raises(ReplayError, match="line 1"):
        load_replay(bad)
    bad.write_text("t,px,py,pz,alpha,beta,gama\n0,0,0,0.7,0,0,0\n0.1,0,zero,0.7,0,0,0\n")
    with pytest.raises(ReplayError, match="line 3"):
        load_replay(bad)


def test_cli_view_once(utn):
    r = cli("view", "--platform", "utn-dynamic", "--duration", "0", "--json", "--pose", "10", "0", "720", "0", "5", "0")
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout[r.stdout.index("{") :])
    pose = utn.home_pose() * 0 + [0.01, 0, 0.72, 0, np.radians(5), 0]
    np.testing.assert_allclose(out["lengths_m"], leg_lengths(utn, pose), rtol=1e-14)
    assert out["reachable"] and out["assembly_modes"] >= 1


def test_cli_view_unreachable_and_bad_input(tmp_path, utn):
    r = cli(
        "view", "--platform", "utn-dynamic", "--duration", "0", "--no-modes", "--pose", "0", "0", "1100", "0", "0", "0"
    )
    assert r.returncode == 1 and "unreachable" in r.stderr and "beyond the stroke" in r.stderr
    r = cli("view", "--platform", "utn-dynamic", "--duration", "0", "--replay", str(tmp_path / "nope.npz"))
    assert r.returncode == 2 and r.stderr.strip().count("\n") == 0 and "nope.npz" in r.stderr
    r = cli("view", "--platform", "utn-dynamic", "--duration", "-1")
    assert r.returncode == 2 and "--duration" in r.stderr


def test_cli_view_replays_a_log(tmp_path, utn):
    _fake_log(tmp_path / "log.npz", utn)
    r = cli("view", "--platform", "utn-dynamic", "--replay", str(tmp_path), "--speed", "4", "--duration", "2", "--json")
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout[r.stdout.index("{") :])
    # Played to the end at 4x: the last readout is the last logged pose.
    np.testing.assert_allclose(out["pose"], utn.home_pose() + [0, 0, 0.05 * np.sin(2 * np.pi), 0, 0, 0], atol=1e-12)


def test_cli_view_json_is_the_whole_stdout_and_a_privileged_port_is_refused(capsys):
    """Found when the CLI fuzz test drew `view` vectors (bounded by --duration): with --json the
    "listening at" line came first on stdout (not JSON), and --port 1 made Drake abort the process (a
    SystemExit from its DRAKE_DEMAND: port 0 or >= 1024)."""
    from stewart_drake.cli import main
    from stewart_drake.drake.viewer import open_meshcat
    from stewart_drake.errors import OPTION_PORT, SimulationError

    assert main(["view", "--duration", "0", "--no-modes", "--json"]) == 0
    io = capsys.readouterr()
    assert json.loads(io.out)["reachable"] and "stewart-drake view: utn-dynamic at http://" in io.err
    for port in ("1", "1023"):
        assert main(["view", "--port", port, "--duration", "0"]) == 2
        assert capsys.readouterr().err.strip() == "stewart-drake view: error: " + OPTION_PORT.format(value=port)
    with pytest.raises(SimulationError, match="--port 80: "):
        open_meshcat(80)
