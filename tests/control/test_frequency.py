"""The z-domain PID of ``control.frequency`` is the law of ``control.laws``, tick for tick."""

import numpy as np

from stewart_drake.control.frequency import LoopModel, controller_matrices
from stewart_drake.control.gains import ControllerConfig
from stewart_drake.control.laws import FloatLaw
from stewart_drake.control.timing import DspTiming
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths


def test_controller_state_space_is_the_float_law():
    p = load_preset("utn-dynamic")
    # a sensor count far below the signals (1e-12 m against ~0.1 mm moves) and a command range no tick reaches:
    # the law is then linear, and its state space must give its commands up to the count's rounding
    cfg = ControllerConfig.for_platform(p, DspTiming(sensor_resolution=1e-12, command_range=1e9))
    law = FloatLaw(p, cfg)
    rng = np.random.default_rng(1)
    home = p.home_pose()
    L0 = leg_lengths(p, home)
    state = law.initial_pid_state(L0, np.zeros(6))
    Ac, Bc, Cc, Dc = (np.kron(X, np.eye(6)) for X in controller_matrices(cfg.gains, cfg.timing.sample_period))
    # the state space's state in the law's layout, as deviations from the held lengths
    c = np.concatenate([state[:6], state[6:12] - L0, state[12:18], state[18:24] - L0, state[24:]])
    # the law rounds each reading to the 1e-12 m count (≤ 0.5e-12 m): through the direct gain kp + kd/T and the
    # states that remember it (integrator, difference filter: a few ticks' worth), a few times that per command
    g, T = cfg.gains, cfg.timing.sample_period
    atol = 4 * 0.5e-12 * (g.kp + g.kd / T + g.ki * T)
    for _ in range(50):
        ref = home + rng.normal(0, 1e-4, 6)
        meas = L0 + rng.normal(0, 1e-4, 6)
        u, sp, state, _ = law.step(state, ref, meas)
        w = np.concatenate([sp - L0, meas - L0])
        u_ss = Cc @ c + Dc @ w
        c = Ac @ c + Bc @ w
        np.testing.assert_allclose(u_ss, u, rtol=1e-9, atol=atol)


def _model(name="utn-dynamic", feedforward=True):
    p = load_preset(name)
    cfg = ControllerConfig.for_platform(p)
    lead = 4e-3 if feedforward else None
    return p, LoopModel.build(p, p.home_pose(), cfg.gains, 1e-3, 1e-3, 2e-3, 1e-3, lead)


def test_plant_static_gain_is_the_leg_space_compliance():
    # at z = 1 the actuators pass a constant command whole and the plate settles where K·δL = δF: the tick map's
    # static gain is K⁻¹ (the model's own K, so this pins the discretisation, lag and delay, not K)
    p, m = _model()
    G0 = m.plant_response([1e-7])[0]
    np.testing.assert_allclose(G0.real, np.linalg.inv(m.K), rtol=1e-6, atol=1e-6 * np.abs(np.linalg.inv(m.K)).max())


def test_integral_action_gives_unit_static_response():
    # the PID integrates the error: at low frequency every leg follows its own set-point (T → I, error ∝ f)
    for ff in (True, False):
        _, m = _model(feedforward=ff)
        assert m.spectral_radius < 1
        T0 = m.setpoint_response([1e-5])[0]
        np.testing.assert_allclose(T0, np.eye(6), atol=1e-3)
