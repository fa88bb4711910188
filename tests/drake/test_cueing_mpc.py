"""MPC cueing on the user's 210 kg machine: every commanded pose re-checked here with the exact IK (stroke, leg
speed, joint cones), the rider at rest kept at home, a drive far beyond the workspace kept inside, the fallback
that scales a bad step, a sustained acceleration cued by tilt, only a preview anticipating the drive, and the
vestibular model in the cost checked against ``vestibular.perceive``."""

import math
import re

import numpy as np
import pytest
from scipy import signal

from stewart_drake.control.cueing.drive import GRAVITY, Drive
from stewart_drake.control.cueing.generators import car_drive
from stewart_drake.control.cueing.platform_motion import platform_drive
from stewart_drake.control.cueing.vestibular import perceive
from stewart_drake.core.kinematics import leg_lengths, length_jacobian
from stewart_drake.drake import cueing_mpc
from stewart_drake.drake.cueing_mpc import MpcParams, error_model, legs_and_jacobian, mpc_cue
from stewart_drake.errors import CueingError
from stewart_drake.spec.load import load_machine
from stewart_drake.workspace.limits import Limits, limit_margins

RATE = 100.0  # Hz: the drives' rate, as a simulator's


@pytest.fixture(scope="module")
def platform():
    return load_machine("examples/newcomer-210kg.yaml").platform


def drive(name, duration, f=None, w=None) -> Drive:
    """A drive at ``RATE`` whose specific force is rest plus ``f(t)`` (N, 3) and angular velocity ``w(t)``."""
    t = np.arange(0.0, duration, 1.0 / RATE)
    force = np.tile([0.0, 0.0, GRAVITY], (t.size, 1)) + (0.0 if f is None else f(t))
    return Drive(name, t, force, np.zeros((t.size, 3)) if w is None else w(t))


def assert_inside(platform, run, v_max):
    """Every commanded pose within the stroke and every leg speed within ``v_max``, by the exact IK here (not the
    run's own figures), and the run's per-solve re-check equal to it."""
    L = leg_lengths(platform, run.poses)
    excess = np.maximum(platform.L_min - L, L - platform.L_max).max(axis=1)
    assert excess.max() <= 0.0
    np.testing.assert_allclose(run.stroke_violation, excess[1:], atol=1e-12)
    assert np.all(np.abs(np.diff(L, axis=0)) * RATE <= v_max)
    assert np.all(run.leg_speed <= v_max)


def test_rest_keeps_the_platform_at_home(platform):
    run = mpc_cue(drive("rest", 2.0), platform, MpcParams())
    # at rest the cost's linear term is zero, so U = 0 is optimal and OSQP's iterates from zero stay there
    np.testing.assert_allclose(run.poses, np.tile(platform.home_pose(), (len(run.poses), 1)), atol=1e-12)
    assert run.fallbacks == {"tightened": 0, "scaled": 0}
    assert run.solve_times.shape == (len(run.t) - 1,)


def test_lane_change_is_inside_on_every_sample(platform):
    d = car_drive("lane-change", duration=4.0, rate=RATE)
    run = mpc_cue(d, platform, MpcParams())
    assert_inside(platform, run, platform.legs.max_speed)
    assert np.ptp(run.poses[:, 1]) > 0.05  # it moved: the check above is not of a platform standing still


def test_a_drive_beyond_the_workspace_is_never_outside(platform):
    # 3 g lateral, a 2 g surge at 0.5 Hz and 1 rad/s of yaw: far beyond a 0.3 m stroke; without the tilt-rate
    # limit the platform rolls until the legs' ends and speeds bind, where the linearisation errs most
    t = np.arange(0.0, 4.0, 1.0 / RATE)
    f = np.column_stack([20.0 * np.sin(np.pi * t), np.full(t.size, 30.0), np.full(t.size, GRAVITY)])
    w = np.column_stack([0 * t, 0 * t, np.full(t.size, 1.0)])
    run = mpc_cue(Drive("beyond", t, f, w), platform, MpcParams(max_tilt_rate=None))
    assert_inside(platform, run, platform.legs.max_speed)
    L = leg_lengths(platform, run.poses)
    # the stroke bound: within 25 mm of its ends (the tightened re-solve keeps 4 × 5 mm when the horizon is infeasible)
    assert np.minimum(L - platform.L_min, platform.L_max - L).min() < 0.025
    assert run.leg_speed.max() > platform.legs.max_speed / 1.25  # faster than the re-solve's limit: speeds bound too


def test_a_bad_step_is_scaled_back_inside(platform, monkeypatch):
    # the program answers every sample with 50 m/s² on every pose coordinate: each first step leaves the
    # workspace (or its leg speed) soon, and the fallback must scale it back
    def wild(self, x0, Rs, qbar, guess, tight):
        return np.full(6 * self.params.horizon, 50.0)

    monkeypatch.setattr(cueing_mpc.CueingProgram, "solve", wild)
    run = mpc_cue(drive("rest", 1.0), platform, MpcParams())
    assert run.fallbacks["scaled"] > 0
    assert_inside(platform, run, platform.legs.max_speed)


def test_joint_cones_are_kept(platform):
    # a base-joint cone 1.5° wider than the legs lean at home; unbounded, this lane change leans them 3.2° more
    lean_home = math.pi - limit_margins(platform, platform.home_pose(), Limits(base_cone=math.pi))["base_joint"][0]
    limits = Limits(base_cone=float(lean_home) + math.radians(1.5))
    run = mpc_cue(car_drive("lane-change", duration=4.0, rate=RATE), platform, MpcParams(), limits=limits)
    margin, _ = limit_margins(platform, run.poses, limits)["base_joint"]
    assert margin.min() >= 0.0
    assert margin.min() < math.radians(1.0)  # the cone bound the motion: the check above is not vacuous


def test_a_sustained_acceleration_is_cued_by_tilt(platform):
    # 1 m/s² forward for 6 s: translation washes out, tilt (nose up, f_x = −g sin(pitch)) carries the cue, and
    # the tilt turns no faster than the canals' threshold; the program predicts the acceleration held (decay=None)
    d = drive("accelerate", 6.0, lambda t: np.column_stack([np.where(t > 0.5, 1.0, 0.0), 0 * t, 0 * t]))
    params = MpcParams(decay=None)
    run = mpc_cue(d, platform, params)
    pitch = run.poses[:, 4]
    assert -GRAVITY * np.sin(pitch[-1]) > 0.5  # more than half of the 1 m/s² is tilt at the end
    assert np.abs(np.diff(pitch)).max() * RATE <= params.max_tilt_rate * (1 + 1e-3)  # QP tolerance 1e-3
    assert abs(run.poses[-1, 0] - run.poses[0, 0]) < 0.1  # washed out: not a surge held at a stroke end


def test_preview_moves_before_the_vehicle_and_the_present_does_not(platform):
    # a 1 m/s² surge from t = 1 s: only the program that sees the recorded future moves before it
    d = drive("surge", 1.5, lambda t: np.column_stack([np.where(t >= 1.0, 1.0, 0.0), 0 * t, 0 * t]))
    before = d.t < 1.0
    ahead = mpc_cue(d, platform, MpcParams(preview=True)).poses[before]
    present = mpc_cue(d, platform, MpcParams()).poses[before]
    assert np.abs(ahead - platform.home_pose()).max() > 1e-3
    np.testing.assert_allclose(present, np.tile(platform.home_pose(), (before.sum(), 1)), atol=1e-12)


def test_the_cost_model_is_the_vestibular_models(platform):
    # the MPC's linear error model, driven by the platform's pose accelerations and the vehicle's motion, against
    # vestibular.perceive of the vehicle less perceive of what the rider on the platform feels
    dt = 0.002
    t = np.arange(0.0, 6.0, dt)
    home = platform.home_pose()
    A, W, B, V = 0.05, 2.0, 0.02, 1.1
    q = np.tile(home, (t.size, 1))
    q[:, 1] = A * np.sin(W * t)
    q[:, 3] = B * np.sin(V * t) ** 2
    acc = np.zeros((t.size, 6))
    acc[:, 1] = -A * W**2 * np.sin(W * t)
    acc[:, 3] = 2 * B * V**2 * np.cos(2 * V * t)
    f = np.column_stack([0.5 * np.sin(1.3 * t), 0 * t, np.full(t.size, GRAVITY)])
    vehicle = Drive("vehicle", t, f, np.column_stack([0 * t, 0.05 * np.sin(0.7 * t), 0 * t]))
    r = np.column_stack([vehicle.specific_force - [0, 0, GRAVITY], vehicle.angular_velocity])
    m = error_model()
    sys = signal.StateSpace(m["A"], np.hstack([m["Ba"], m["Br"]]), m["C"], np.hstack([m["Da"], m["Dr"]]))
    _, y, _ = signal.lsim(sys, np.hstack([acc, r]), t)
    seen = perceive(vehicle)
    felt = perceive(platform_drive(q, t, home))
    want = np.column_stack([seen.specific_force - felt.specific_force, seen.angular_velocity - felt.angular_velocity])
    inner = slice(5, -5)  # platform_drive's end samples are one-sided differences
    # the model is linear in the angles: it leaves out g (1 − cos roll) ≤ g B²/2 = 2e-3 m/s² in f_z, which the
    # otolith's lead passes with a gain up to τ_a/τ_L = 13.2/5.33 ≈ 2.5 (≤ 5e-3), and the rate map's O(B²) terms
    # (≤ 4e-4 rad/s here); the discretisations (bilinear, lsim) differ by ~1e-5
    np.testing.assert_allclose(y[inner, :3], want[inner, :3], atol=5e-3)
    np.testing.assert_allclose(y[inner, 3:], want[inner, 3:], atol=5e-4)
    assert np.abs(want[inner, :2]).max() > 0.1  # the perceived errors compared are not all near zero


def test_legs_and_jacobian_are_the_kinematics(platform):
    rng = np.random.default_rng(3)
    q = platform.home_pose() + rng.uniform(-1, 1, (5, 6)) * [0.05, 0.05, 0.05, 0.1, 0.1, 0.1]
    L, J = legs_and_jacobian(platform, q)
    np.testing.assert_allclose(L, leg_lengths(platform, q), atol=1e-15)
    np.testing.assert_allclose(J, length_jacobian(platform, q), atol=1e-14)
    h = 1e-6  # central differences: error ~ h² L''' ≈ 1e-12, rounding ~ 1e-16 / h = 1e-10
    fd = np.stack(
        [(leg_lengths(platform, q + h * e) - leg_lengths(platform, q - h * e)) / (2 * h) for e in np.eye(6)], -1
    )
    np.testing.assert_allclose(J, fd, atol=1e-8)


@pytest.mark.parametrize(
    "field, value, rule",
    [
        ("horizon", 0, "a whole number of steps in 1..200"),
        ("step", -0.1, "a positive number"),
        ("w_position", float("nan"), "a number >= 0"),
        ("max_tilt_rate", 0.0, "a positive number or None"),
        ("solver", "snopt", "one of osqp, clarabel"),
    ],
)
def test_bad_parameters_name_the_field_and_value(field, value, rule):
    message = CueingError.PARAM.format(name=f"mpc {field}", rule=rule, value=value)
    with pytest.raises(CueingError, match=re.escape(message)):
        MpcParams(**{field: value})
