"""The screw actuator's law (``control.screw``): energy conservation over a cycle, passivity, the linearisation
against finite differences, and the step response against the linear model."""

import math

import numpy as np
import pytest

from stewart_drake.control import screw
from stewart_drake.design.screw import ScrewParameters

P = ScrewParameters.defaults(4000.0)  # the 210 kg machine's legs.max_force
H = 1e-3  # s: the plant step


def _cycle(h=H, amplitude=0.02, frequency=2.0, params=P):
    """One period of a prescribed leg motion L = A·sin(2πft) under a command that drives and brakes
    (F0 + F1·cos): the law stepped at ``h`` as the loop steps it. Returns (t, L, v, a, i, F)."""
    n = int(round(1 / (frequency * h)))
    t = np.arange(n + 1) * h
    w = 2 * math.pi * frequency
    L = amplitude * np.sin(w * t)[:, None] * np.ones(6)
    v = amplitude * w * np.cos(w * t)[:, None] * np.ones(6)
    acc = -amplitude * w**2 * np.sin(w * t)[:, None] * np.ones(6)
    u = 800.0 + 1500.0 * np.cos(w * t[:, None] + np.linspace(0, 2, 6))  # N: phases per leg, some braking
    act = screw.ScrewActuation(params, h)
    i = np.empty((n + 1, 6))
    i[0] = act.initial_current(u[0])
    for k in range(n):
        i[k + 1] = act.step(i[k], u[k])
    return t, L, v, acc, i, screw.leg_force(params, i, v)


def test_energy_in_is_work_plus_losses_over_a_cycle():
    t, L, v, acc, i, F = _cycle()
    n = len(t) - 1
    p = screw.powers(P, i[:n], v[:n])
    # the electrical energy from the motor's circuit, V = R·i + Kt·ω (independent of the force law)
    V = P.winding_resistance * i[:n] + P.torque_constant * P.ratio * v[:n]
    electrical = (V * i[:n]).sum(axis=0) * H
    # the work the held force does on the leg over each step, along the exact motion
    work = (F[:n] * np.diff(L, axis=0)).sum(axis=0)
    losses = (p["copper"] + p["screw"] + p["friction"]).sum(axis=0) * H
    # the power is held at each step's start (left rule): against the exact ∫F dL the error of a step is at
    # most ½·h²·|F|·max|L̈| (Taylor of L over the step), so the cycle's at most that summed
    bound = 0.5 * H**2 * (np.abs(F[:n]).sum(axis=0) * np.abs(acc).max())
    np.testing.assert_array_less(np.abs(electrical - losses - work), bound)
    assert np.all(bound < 0.01 * np.abs(electrical).max())  # the bound is tight enough to mean something
    np.testing.assert_allclose(p["electrical"].sum(axis=0) * H, electrical, rtol=1e-12)


def test_every_loss_is_dissipative_driving_and_back_driven():
    _, _, v, _, i, _ = _cycle()
    p = screw.powers(P, i, v)
    shaft = P.torque_constant * i * P.ratio * v
    assert (shaft > 1).any() and (shaft < -1).any()  # the cycle drives and back-drives
    for name in ("copper", "screw", "friction"):
        assert (p[name] >= 0).all(), name
    # back-driven, the screw's loss is (1 − η) of the load's power; driving, (1 − η) of the motor's: away from
    # the blend (|L̇| ≥ 5 v_s, tanh ≥ 0.9999), within the blend's 1e-4 of each
    moving = np.abs(v) > 5 * screw.FRICTION_SPEED
    drive = moving & (shaft > 0)
    np.testing.assert_allclose(p["screw"][drive], (1 - P.efficiency) * shaft[drive], rtol=1e-4 * 2)


def test_the_current_limit_gives_the_force_limit_at_rest():
    act = screw.ScrewActuation(P, H)
    i = act.initial_current(np.full(6, 1e6))
    np.testing.assert_allclose(screw.leg_force(P, i, np.zeros(6)), 4000.0 - 0.0, rtol=1e-12)
    assert P.max_force == pytest.approx(4000.0, rel=1e-12)


@pytest.mark.parametrize("current, velocity", [(3.0, 0.02), (-2.0, 0.004), (5.0, -0.05), (1.0, 0.0)])
def test_the_linearisation_is_the_laws_jacobian(current, velocity):
    a, b, c, d = screw.linearisation(P, current, velocity)
    u0 = current * P.force_per_amp  # the command that holds this current
    # central differences: error ~ δ²·f'''/6; δ = 1e-6 of the scale against terms that change over v_s (1e-2)
    di, dv, du = 1e-6 * abs(current), 1e-7, 1e-6 * abs(u0)
    f = lambda i, v: screw.leg_force(P, np.array([i]), np.array([v]))[0]  # noqa: E731
    g = lambda i, u: screw.current_derivative(P, np.array([i]), np.array([u]))[0]  # noqa: E731
    assert (f(current + di, velocity) - f(current - di, velocity)) / (2 * di) == pytest.approx(c, rel=1e-7)
    assert (f(current, velocity + dv) - f(current, velocity - dv)) / (2 * dv) == pytest.approx(d, rel=1e-6)
    assert (g(current + di, u0) - g(current - di, u0)) / (2 * di) == pytest.approx(a, rel=1e-7)
    assert (g(current, u0 + du) - g(current, u0 - du)) / (2 * du) == pytest.approx(b, rel=1e-7)


def test_a_small_step_follows_the_linear_model():
    i0, v0, du, dv = 3.0, 0.02, 5.0, 1e-4  # A, m/s, then a 5 N command step and a 0.1 mm/s velocity step
    a, b, c, d = screw.linearisation(P, i0, v0)
    act = screw.ScrewActuation(P, H / 10)
    u0 = i0 * P.force_per_amp
    n = 50
    t = np.arange(1, n + 1) * H / 10
    i, F = np.full(6, i0), []
    for _ in range(n):
        i = act.step(i, np.full(6, u0 + du))
        F.append(screw.leg_force(P, i, np.full(6, v0 + dv))[0])
    F0 = screw.leg_force(P, np.array([i0]), np.array([v0]))[0]
    linear = c * (b / -a) * du * (1 - np.exp(a * t)) + d * dv
    # the current is linear in the command (ZOH exact): what is left is F's curvature in L̇ and i·L̇, second
    # order: |½·F_vv·dv²| + |F_iv·δi·dv| with F_vv ≤ d's scale over v_s, F_iv ≤ c·|ln η|/v_s
    second = (
        0.5 * abs(d) / screw.FRICTION_SPEED * dv**2
        + c * abs(math.log(P.efficiency)) / screw.FRICTION_SPEED * (du / P.force_per_amp) * dv
    )
    np.testing.assert_allclose(np.array(F) - F0, linear, atol=4 * second + 1e-9 * F0)
    assert abs(linear[-1]) > 100 * (4 * second)  # the response is far above the tolerance


def test_motor_demand_inverts_the_law():
    # the current motor_demand asks for gives, through leg_force, the force asked for plus the rotor's m_eff·L̈
    rng = np.random.default_rng(3)
    F, v, acc = rng.normal(0, 2000, (40, 6)), rng.normal(0, 0.05, (40, 6)), rng.normal(0, 2, (40, 6))
    d = screw.motor_demand(P, F, v, acc)
    np.testing.assert_allclose(screw.leg_force(P, d["current"], v), F + P.reflected_mass * acc, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(d["speed"], v * 2 * math.pi / P.lead, rtol=1e-15)
