"""Classical washout against its stated filters: the frequency response of each channel, a sustained acceleration
felt through tilt at the rate limit (checked with the platform's own felt motion), parameter checks."""

import math

import numpy as np
import pytest
from scipy import signal

from stewart_drake.control.cueing.classical import HAND_SET, ClassicalParams, classical
from stewart_drake.control.cueing.drive import GRAVITY, Drive
from stewart_drake.control.cueing.platform_motion import platform_drive
from stewart_drake.errors import CueingError

HOME = np.array([0.0, 0.0, 0.65, 0.0, 0.0, 0.0])


def _drive(t, f=None, w=None):
    n = len(t)
    f0 = np.tile([0.0, 0.0, GRAVITY], (n, 1)) if f is None else f
    return Drive("test", t, f0, np.zeros((n, 3)) if w is None else w)


@pytest.mark.parametrize("params", [ClassicalParams(), HAND_SET])
def test_sines_follow_the_channels_transfer_functions(params):
    # a 1.5 Hz sine in heave (no tilt) and yaw rate: after 30 s the excursion is the input times H(jω) of the
    # stated continuous filters; the bilinear transform warps 1.5 Hz at 200 Hz by (ω dt)²/12 ≈ 1.9e-3
    dt, w0, A = 0.005, 2 * math.pi * 1.5, 1.0
    t = np.arange(0, 40, dt)
    u = A * np.sin(w0 * t)
    f = np.column_stack([0 * t, 0 * t, GRAVITY + u])
    w = np.column_stack([0 * t, 0 * t, u])
    q = classical(_drive(t, f, w), params, HOME)
    p = params
    second = [1.0, 2 * p.hp_zeta * p.hp_z, p.hp_z**2]
    tf_z = ([1.0, 0.0], np.polymul(second, [1.0, p.hp_break])) if p.hp_break else ([1.0], second)
    tf_yaw = ([1.0, 0.0], [1.0, 2 * p.hp_rot_zeta * p.hp_rot, p.hp_rot**2])
    late = t > 30
    for col, tf, gain in ((2, tf_z, p.scale_z), (5, tf_yaw, p.scale_rot)):
        _, h = signal.freqs(*tf, worN=[w0])
        expected = HOME[col] + gain * A * np.abs(h[0]) * np.sin(w0 * t + np.angle(h[0]))
        np.testing.assert_allclose(q[late, col], expected[late], atol=4e-3 * gain * A * np.abs(h[0]))
    np.testing.assert_array_equal(q[:, [0, 1, 3, 4]], np.tile(HOME[[0, 1, 3, 4]], (len(t), 1)))


def test_sustained_braking_is_felt_through_tilt_at_the_rate_limit():
    # −3 m/s² from t = 1 s on: the translational channel washes out to home (third order), the tilt reaches the
    # pitch whose gravity gives k·3 m/s² and turns at most tilt_rate; the felt surge (platform_drive) ends at it
    p = ClassicalParams()
    dt = 0.01
    t = np.arange(0, 60, dt)
    fx = np.where(t > 1, -3.0, 0.0)
    q = classical(_drive(t, np.column_stack([fx, 0 * t, GRAVITY + 0 * t])), p, HOME)
    assert np.max(np.abs(np.diff(q[:, 4]))) <= p.tilt_rate * dt * (1 + 1e-12)
    np.testing.assert_allclose(q[-1, :3], HOME[:3], atol=1e-4)
    assert q[-1, 4] == pytest.approx(math.asin(p.scale_xy * 3.0 / GRAVITY), rel=1e-4)
    felt = platform_drive(q, t, HOME)
    assert felt.specific_force[-2, 0] == pytest.approx(-p.scale_xy * 3.0, rel=1e-4)


def test_parameters_are_checked():
    with pytest.raises(CueingError, match="hp_xy must be a positive number, got -1"):
        ClassicalParams(hp_xy=-1)
    with pytest.raises(CueingError, match="tilt_rate must be a finite number, got nan"):
        ClassicalParams(tilt_rate=float("nan"))
    assert ClassicalParams(hp_break=0).hp_break == 0
