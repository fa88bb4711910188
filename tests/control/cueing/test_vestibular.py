"""The vestibular models: the filtered series against the transfer functions' own frequency response, the
state-space forms against the transfer functions, and the steady states the papers state."""

import numpy as np
import pytest
from scipy import signal

from stewart_drake.control.cueing.drive import GRAVITY, Drive
from stewart_drake.control.cueing.vestibular import bilinear, canal_ss, canal_tf, otolith_ss, otolith_tf, perceive


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_state_space_has_the_transfer_functions_response(axis):
    w = np.logspace(-3, 2, 40)
    for ss, tf in ((otolith_ss(axis), otolith_tf(axis)), (canal_ss(axis), canal_tf(axis))):
        A, B, C, D = ss
        h_ss = np.array([(C @ np.linalg.solve(1j * x * np.eye(len(A)) - A, B) + D).item() for x in w])
        _, h_tf = signal.freqs(*tf, worN=w)
        np.testing.assert_allclose(h_ss, h_tf, rtol=1e-9)


def test_perceived_sine_has_the_models_gain_and_phase():
    # a 0.5 Hz sine on every channel, 100 Hz: after 200 s (~7 adaptation time constants of the canal, 15 of the
    # otolith) the output is the sine times H(jω); the bilinear transform warps 0.5 Hz by (ω dt)²/12 ≈ 8e-5
    dt, w0 = 0.01, 2 * np.pi * 0.5
    t = np.arange(0, 300, dt)
    u = np.sin(w0 * t)
    d = perceive(Drive("sine", t, np.column_stack([u, u, u]), np.column_stack([u, u, u])))
    late = t > 200
    for i in range(3):
        for y, tf in ((d.specific_force[:, i], otolith_tf(i)), (d.angular_velocity[:, i], canal_tf(i))):
            _, h = signal.freqs(*tf, worN=[w0])
            expected = np.abs(h[0]) * np.sin(w0 * t + np.angle(h[0]))
            assert np.max(np.abs(y[late] - expected[late])) < 1e-3 * np.abs(h[0])


def test_rest_is_perceived_as_rest_and_a_constant_rotation_fades():
    t = np.arange(0, 120, 0.01)
    n = len(t)
    d = perceive(Drive("spin", t, np.tile([0, 0, GRAVITY], (n, 1)), np.tile([0, 0, 0.5], (n, 1))))
    np.testing.assert_allclose(d.specific_force, np.tile([0, 0, GRAVITY], (n, 1)), atol=1e-9)
    # started at rest at ω = 0.5 rad/s: the canal's steady state for a constant rate is 0 (adaptation)
    assert np.max(np.abs(d.angular_velocity)) < 1e-9


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_bilinear_is_scipys(axis):
    for tf in (otolith_tf(axis), canal_tf(axis), ([1.0], [1.0, 3.0, 2.25])):
        for b, b_ref in zip(bilinear(*tf, 0.01), signal.bilinear(*tf, fs=100.0)):
            np.testing.assert_allclose(b, b_ref, rtol=1e-12, atol=1e-15)
