"""The closed-loop verdict sees chatter and saturation at a trajectory's ends (issue 24, item 3)."""

import json
from pathlib import Path

import numpy as np
import pytest

from stewart_drake.cli import main
from stewart_drake.control import ControllerConfig
from stewart_drake.control.chatter import CHATTER_RANGE_FRACTION, chatter_measure, end_saturation, loop_verdict
from stewart_drake.control.feedforward import feedforward_forces
from stewart_drake.control.laws import STATUS
from stewart_drake.control.simulation_log import SimulationLog
from stewart_drake.core.geometry import load_platform
from stewart_drake.core.trajectory import SEED, fit_trajectory

NEWCOMER = Path(__file__).parents[2] / "examples" / "newcomer-150kg.yaml"


def _log(platform, traj, force, T=1e-3, saturated_ticks=()):
    """A SimulationLog on the tick grid whose forces are ``force`` and whose status counts saturated ticks
    of leg 1 at the tick indices ``saturated_ticks``."""
    n = len(force)
    t = np.arange(n) * T
    status = np.zeros((n, len(STATUS)))
    status[:, STATUS.index("ticks")] = np.arange(1, n + 1)
    status[:, STATUS.index("last_tick_time")] = t
    sat = np.zeros(n)
    sat[list(saturated_ticks)] = 1
    status[:, 4] = np.cumsum(sat)
    z = np.zeros((n, 6))
    return SimulationLog("fixed", platform.name, traj.name, T, t, z, z, z, z, force, status, t, z)


def test_ripple_of_a_square_wave_is_its_amplitude():
    """Force = quasi-static force + a ±A square wave at 250 Hz: the ripple (RMS about the quasi-static force)
    is A exactly (the RMS of a ±A square wave), the ratio A / RMS(quasi-static)."""
    p = load_platform("utn-dynamic")
    traj = fit_trajectory(SEED, p)
    cfg = ControllerConfig.for_platform(p)
    t = np.arange(2000) * 1e-3
    F = feedforward_forces(p, traj, t, 0.0, 1e-3)
    A = 7.5
    wave = A * np.where((np.arange(2000) // 2) % 2 == 0, 1.0, -1.0)[:, None]
    m = chatter_measure(p, traj, _log(p, traj, F + wave), cfg)
    np.testing.assert_allclose(m["force_ripple_N"], A, rtol=1e-12)
    assert m["chatter_ratio"] == pytest.approx(A / np.sqrt(np.mean(F**2, axis=0)).min(), rel=1e-12)
    assert m["ripple_range_fraction"] == pytest.approx(A / cfg.timing.command_range, rel=1e-12)
    # the cause: the largest quantisation step, the 1 mm IK LSB through the set-point-rate feed-forward kv/T
    assert m["chatter_cause"].startswith("the IK's length LSB (1 mm) through kv/T: ")
    assert float(m["chatter_cause"].split(": ")[1].split()[0]) == pytest.approx(cfg.gains.kv * 1e-3 / 1e-3, rel=1e-3)


def test_chatter_verdict_thresholds():
    """Below the range bound a ripple above the working force is a warning; above it a failure."""
    p = load_platform("utn-dynamic")
    traj = fit_trajectory(SEED, p)
    cfg = ControllerConfig.for_platform(p)
    t = np.arange(1000) * 1e-3
    F = feedforward_forces(p, traj, t, 0.0, 1e-3)
    sq = np.where(np.arange(1000) % 2 == 0, 1.0, -1.0)[:, None]
    small = loop_verdict(p, traj, _log(p, traj, F + 0.5 * CHATTER_RANGE_FRACTION * cfg.timing.command_range * sq), cfg)
    big = loop_verdict(p, traj, _log(p, traj, F + 2 * CHATTER_RANGE_FRACTION * cfg.timing.command_range * sq), cfg)
    assert small["failures"] == [] and small["warnings"] and "working force" in small["warnings"][0]
    assert big["failures"] and big["failures"][0].startswith("chatter: ")


def test_saturation_at_the_end_is_flagged():
    p = load_platform("utn-dynamic")
    traj = fit_trajectory(SEED, p)
    F = np.zeros((1000, 6))
    assert end_saturation(_log(p, traj, F, saturated_ticks=[500])) == []
    assert end_saturation(_log(p, traj, F, saturated_ticks=[500, 997])) == [(1, 0.997)]
    v = loop_verdict(p, traj, _log(p, traj, F, saturated_ticks=[997]), ControllerConfig.for_platform(p))
    assert any("saturated at the trajectory's end (t = 0.9970 s)" in f for f in v["failures"])


def test_newcomer_platform_chatters_and_exits_1(tmp_path, capsys):
    """The newcomer's 150 kg platform (stroke 0.9-1.5 m): the fixed-point loop's force ripple is ~10 % of its
    6 kN range (the float twin's ~0.2 %), caused by the 1 mm IK LSB through kv/T; it exited 0 before."""
    pytest.importorskip("pydrake")  # runs a Drake-backed command; the numpy-layer run (no pydrake) skips it
    out = tmp_path / "sim"
    rc = main(["simulate", "--platform", str(NEWCOMER), "--fit", "--duration", "1", "--out", str(out), "--no-progress"])
    err = capsys.readouterr().err
    s = json.loads((out / "summary.json").read_text())
    assert rc == 1 and "chatter: force ripple" in err and "IK's length LSB (1 mm) through kv/T" in err
    assert s["ripple_range_fraction"] > CHATTER_RANGE_FRACTION and s["chatter_ratio"] > 1
    assert any(f.startswith("chatter: ") for f in s["failures"])


def test_the_named_cause_is_the_cause():
    """The newcomer's chatter is named as the 1 mm IK LSB: the same loop with a 0.1 mm LSB (16-bit words
    still hold the 1.5 m legs) has a ripple ~10x smaller (the force per LSB step scales with the LSB) and
    passes; measured 603 N -> 47 N over 2 s."""
    pytest.importorskip("pydrake")  # runs a Drake-backed command; the numpy-layer run (no pydrake) skips it
    from stewart_drake.control import DspTiming
    from stewart_drake.core.trajectory import design_poses
    from stewart_drake.drake.simulation import Scenario, build_simulation
    from stewart_drake.fixedpoint.generic import QFormat

    p = load_platform(str(NEWCOMER))
    traj = fit_trajectory(SEED, p)
    ripple = {}
    for lsb in (1e-3, 1e-4):
        cfg = ControllerConfig.for_platform(
            p, DspTiming(command_range=6000.0), poses=design_poses(traj, 1.0), ik_format=QFormat(16, lsb, "tfr16")
        )
        log = build_simulation(Scenario(p, traj, "fixed", cfg, engine="python")).run(1.0)
        v = loop_verdict(p, traj, log, cfg)
        ripple[lsb] = max(v["force_ripple_N"])
        assert bool(v["failures"]) == (lsb == 1e-3)
    assert ripple[1e-3] > 5 * ripple[1e-4]
