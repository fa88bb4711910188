"""RC-servo hexapod (``mechanisms/servo``, ``mechanisms/servo_loop``) cross-checked against Drake
(``drake/servo_model``): the plant's frames, FK and IK, the controller system, and the 50 Hz loop closed in
simulation."""

import numpy as np
import pytest

from stewart_drake.drake.servo_model import compare_with_drake, run_closed_loop, run_controller
from stewart_drake.mechanisms.servo import quantise_pulses, solve
from stewart_drake.mechanisms.servo_loop import tracking_bounds
from tests.mechanisms.test_servo import random_poses


def test_drake_cross_checks(hexapod):
    poses = random_poses(hexapod, 15, seed=5)
    r = compare_with_drake(hexapod, poses)
    assert r["frames"] < 1e-15  # the same numbers read back
    assert r["home"] < 1e-9  # SNOPT to 1e-12 feasibility; angle error ~ gap / (a · sin(rod, arm)) ≈ 1e-10
    assert r["fk"] < 1e-12  # pure float kinematics: s = 0.11 m at ~1e-16 relative
    # Drake IK vs pulse-derived angles: IK closes rods to IK_GAP_TOL_M = 1e-8 m; an arm of a = 25 mm
    # turns ~gap / (a sin(arm, rod)) ≈ 1e-8 / 0.02 = 5e-7 rad for that.
    assert r["ik"] < 1e-6
    assert r["mirror_fk"] > 1e-3  # ignoring the odd/even sign breaks the rods by millimetres


def test_controller_quantises_latches_and_delays(hexapod):
    t = np.linspace(0, 0.2, 11)
    poses = np.tile(hexapod.home_pose(), (11, 1))
    poses[:, 3] = np.radians(5) * np.sin(2 * np.pi * 5 * t)
    log = run_controller(hexapod, t, poses)
    assert np.allclose(log["t"], np.arange(0, 0.2 + 1e-9, 0.02))
    assert np.all(log["pulse_us"][0] == 1500)  # initial state: neutral
    expected = quantise_pulses(solve(hexapod, log["pose"]).pulse)
    assert np.array_equal(log["pulse_us"][1:], expected[:-1])  # one frame of delay, integer µs
    assert np.all(log["pulse_us"] == np.round(log["pulse_us"]))
    assert np.all(log["status"] == 0)


def test_closed_loop_hold_is_within_quantisation_and_sag(hexapod):
    """A constant offset pose held for 0.4 s: once settled, each arm sits within half a pulse step
    (0.5 µs = 0.056°) plus its static sag (load / kp ≈ 0.02°) of eq. 9, and the platform within the
    Jacobian image of that. A wrong pulse sign, gain or mounting would miss by degrees."""
    pose = hexapod.home_pose() + [0.003, -0.002, 0.004, 0.05, -0.03, 0.08]
    log = run_closed_loop(hexapod, [0.0, 1.0], [pose, pose], duration=0.4)
    b = tracking_bounds(hexapod, log)
    assert b["quantisation"] == pytest.approx(np.radians(45) / 800)
    arm = np.abs(log["arm_angle"][-1] - log["arm_angle_ref"][-1])
    assert np.all(arm <= b["arm"][-1]) and b["arm"][-1].max() < np.radians(0.1)
    assert np.all(np.abs(log["pose"][-1] - pose) <= b["pose"][-1])
    assert log["rod_gap"][-1].max() < 1e-6  # SAP ball constraints at 1 ms steps (DESIGN: ~1e-6 m)


def test_closed_loop_tracks_a_trajectory(hexapod):
    """1 s of heave ±6 mm, roll ±8°, yaw ±15° through the 50 Hz loop. Bound (servo_loop.tracking_bounds):
    the reference's change over the loop's latency Λ = 20 ms frame + 2 ms + kd/kp (5.7 ms), plus half a
    pulse step and the sag; the arms' worst speed (2.5 rad/s) is below the servo's 6.2 rad/s, so the speed
    limit adds no lag. Checked per servo and per pose axis on the run's worst case (per sample, the
    reaction of neighbouring servos' frame steps adds ~0.04° blips where an arm reverses, which the
    bound does not model)."""
    t = np.linspace(0, 1.0, 201)
    traj = np.tile(hexapod.home_pose(), (len(t), 1))
    traj[:, 2] += 0.006 * np.sin(np.pi * t)
    traj[:, 3] = np.radians(8) * np.sin(2 * np.pi * t)
    traj[:, 5] = np.radians(15) * np.sin(np.pi / 2 * t)
    log = run_closed_loop(hexapod, t, traj)
    b = tracking_bounds(hexapod, log)
    arm = np.abs(log["arm_angle"] - log["arm_angle_ref"])
    pose = np.abs(log["pose"] - log["reference"])
    assert np.all(arm.max(0) <= b["arm"].max(0))
    assert np.all(pose.max(0) <= b["pose"].max(0))
    # The bound is not vacuous: the frame latency dominates and shows in the error.
    assert arm.max() > 0.5 * b["arm"].max()
    settled = log["t"] >= 0.1  # the ball constraints settle from a ~0.3 mm start-up kick within ~50 ms
    # ~1e-6 m under steady loads (DESIGN); the servos' 50 Hz steps load the rods impulsively: a few µm,
    # still far below the tracking bound's ~0.4 mm scale.
    assert log["rod_gap"][settled].max() < 1e-5
    assert np.all(log["status"] == 0)
