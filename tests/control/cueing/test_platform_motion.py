"""The motion felt on the platform against closed forms: a surge sine under a pitch sine, and the centripetal
acceleration of a head off the yaw axis."""

import numpy as np

from stewart_drake.control.cueing.drive import GRAVITY
from stewart_drake.control.cueing.platform_motion import platform_drive
from stewart_drake.core.rotations import rotation_matrix

HOME = np.array([0.0, 0.0, 0.7, 0.0, 0.0, 0.0])


def test_surge_and_pitch_match_the_closed_form():
    dt = 0.005
    t = np.arange(0, 4, dt)
    A, W, B, V = 0.1, 2.0, 0.1, 1.5
    q = np.tile(HOME, (len(t), 1))
    q[:, 0] += A * np.sin(W * t)
    q[:, 4] = B * np.sin(V * t)
    d = platform_drive(q, t, HOME)
    a_world = np.column_stack([-A * W**2 * np.sin(W * t), 0 * t, 0 * t]) + [0, 0, GRAVITY]
    f = np.einsum("nji,nj->ni", rotation_matrix(q[:, 3:]), a_world)
    w = np.column_stack([0 * t, B * V * np.cos(V * t), 0 * t])
    inner = slice(1, -1)
    # second central difference: error A W⁴ dt²/12 = 3e-6 m/s²; central rate: B V³ dt²/6 = 1.4e-6 rad/s
    np.testing.assert_allclose(d.specific_force[inner], f[inner], atol=1e-5)
    np.testing.assert_allclose(d.angular_velocity[inner], w[inner], atol=1e-5)
    np.testing.assert_allclose(d.attitude[:, 1], q[:, 4], atol=1e-12)  # a pure pitch: the same angle in zyx


def test_head_off_the_yaw_axis_feels_the_centripetal_acceleration():
    dt, W, r = 0.001, 0.8, 0.5
    t = np.arange(0, 3, dt)
    q = np.tile(HOME, (len(t), 1))
    q[:, 5] = W * t
    d = platform_drive(q, t, HOME, head=(r, 0.0, 0.0))
    # a point at radius r on a turntable: acceleration W² r towards the axis, i.e. −x of the head frame
    np.testing.assert_allclose(d.specific_force[1:-1], np.tile([-(W**2) * r, 0, GRAVITY], (len(t) - 2, 1)), atol=1e-6)
    np.testing.assert_allclose(d.angular_velocity[1:-1, 2], W, atol=1e-9)
