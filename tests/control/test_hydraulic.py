"""The hydraulic cylinder's law (``control.hydraulic``): energy over a cycle (the pump's = the valve's and the
leakage's losses + the oil's compression + the work on the leg), passivity of the losses, the linearisation
against finite differences, and a small step against the linear model."""

import math

import numpy as np
import pytest
from scipy.linalg import expm

from stewart_drake.control import hydraulic as hy
from stewart_drake.design.hydraulic import HydraulicParameters

P = HydraulicParameters.defaults(4000.0, 0.3, 0.5)  # the 210 kg machine's force, stroke and speed
L_MIN = 0.55


def _cycle(h, n_cycles=1, frequency=5.0, amplitude=0.02):
    """The cylinder under a prescribed leg motion x = 0.15 + A·sin(2πft) and a force command that pushes and
    pulls, stepped at ``h``: (t, x, v, states (n+1, 3, 6), powers {name: (n, 6)})."""
    n = int(round(n_cycles / (frequency * h)))
    t = np.arange(n + 1) * h
    w = 2 * math.pi * frequency
    x = 0.15 + amplitude * np.sin(w * t)[:, None] * np.ones(6)
    v = amplitude * w * np.cos(w * t)[:, None] * np.ones(6)
    u = 500.0 + 1500.0 * np.sin(w * t[:, None] + np.linspace(0, 3, 6))
    act = hy.HydraulicActuation(P, h, L_MIN)
    state, _ = act.start(u[0], x[0] + L_MIN, v[0])
    states, powers = [state], []
    for k in range(1, n + 1):
        state, _, pw = act.advance(state, u[k - 1], x[k] + L_MIN, v[k])
        states.append(state)
        powers.append(pw)
    return t, x, v, np.array(states), {k: np.array([p[k] for p in powers]) for k in powers[0]}


def _balance(h):
    """(pump energy, losses + compression from the states + work, per leg) over the cycle at step ``h``: the
    trapezoid rule over the step ends (the first step's start left out); compression as Σ p̄·V̄·Δp/β, from the
    pressures' own trajectory, independent of the flows."""
    t, x, v, S, pw = _cycle(h)
    trap = lambda y: (0.5 * (y[1:] + y[:-1]) * h).sum(axis=0)  # noqa: E731
    va, vb = hy.volumes(P, x[1:])
    comp = 0.0
    for ch, vol in ((0, va), (1, vb)):
        p = S[1:, ch]
        comp = comp + (0.5 * (p[1:] + p[:-1]) * 0.5 * (vol[1:] + vol[:-1]) * np.diff(p, axis=0)).sum(axis=0)
    comp = comp / P.bulk_modulus
    out = trap(pw["throttle"]) + trap(pw["leakage"]) + trap(pw["mechanical"]) + comp
    return trap(pw["hydraulic"]), out


def test_pump_energy_is_losses_compression_and_work_over_a_cycle():
    e_in, e_out = _balance(2e-4)
    e_in2, e_out2 = _balance(4e-4)
    # the powers at a step's end hold that step's velocity where the next step's starts: a first-order error in
    # h, whose Richardson estimate at h is |r_2h − r_h| (r the residual); ×1.5 for the estimate's own error
    tol = 1.5 * np.abs((e_in - e_out) - (e_in2 - e_out2))
    np.testing.assert_array_less(np.abs(e_in - e_out), tol + 1e-9 * np.abs(e_in))
    assert (np.abs(e_in - e_out) < 1e-3 * np.abs(e_in)).all()  # a balance to 0.1 % of the pump's energy


def test_the_losses_are_dissipative_both_ways():
    _, _, _, S, pw = _cycle(1e-3)
    assert (S[:, 2] > 0.01).any() and (S[:, 2] < -0.01).any()  # the spool opened both ways
    assert (pw["throttle"] >= 0).all() and (pw["leakage"] >= 0).all()
    assert ((S[:, 0] > 0) & (S[:, 0] < P.supply_pressure) & (S[:, 1] > 0)).all()  # pressures in their range


@pytest.mark.parametrize("spool, rate", [(0.3, 0.05), (-0.2, -0.08), (0.1, -0.02)])
def test_the_linearisation_is_the_laws_jacobian(spool, rate):
    state, u, x = np.array([4e6, 3e6, spool]), 1200.0, 0.12
    A, B = hy.linearisation(P, state, x, rate)
    f = lambda st, uu, xx, vv: hy.derivative(P, st[:, None], np.array([uu]), np.array([xx]), np.array([vv]))[:, 0]  # noqa: E731
    steps = np.array([1.0, 1.0, 1e-6])  # Pa, Pa, spool: central differences, error ~ δ²·f'''
    for j in range(3):
        d = np.zeros(3)
        d[j] = steps[j]
        col = (f(state + d, u, x, rate) - f(state - d, u, x, rate)) / (2 * steps[j])
        np.testing.assert_allclose(col, A[:, j], rtol=1e-5, atol=1e-9 * np.abs(A).max())
    for j, (du, dv, dx) in enumerate([(1e-3, 0, 0), (0, 1e-7, 0), (0, 0, 1e-7)]):
        col = (f(state, u + du, x + dx, rate + dv) - f(state, u - du, x - dx, rate - dv)) / (2 * (du + dv + dx))
        np.testing.assert_allclose(col, B[:, j], rtol=1e-5, atol=1e-9 * np.abs(B).max())


def test_a_small_step_follows_the_linear_model():
    # a steady extension at 0.05 m/s under 1 kN, then a 10 N command step: the law's force less an unstepped
    # run's (what is left of the settling) against the linear model's, sampled at the plant steps; the difference
    # is second order (twice the step, four times the difference)
    h, v0, u0, x0 = 1e-3, 0.05, 1000.0, 0.1
    act = hy.HydraulicActuation(P, h, L_MIN)
    st, _ = act.start(np.full(6, u0), np.full(6, x0 + L_MIN), np.full(6, v0))
    for _ in range(300):  # settle, the leg held at x0 (its velocity feeds the flows only)
        st, _, _ = act.advance(st, np.full(6, u0), np.full(6, x0 + L_MIN), np.full(6, v0))
    A, B = hy.linearisation(P, st[:, 0], x0, v0)
    Ad = expm(A * h)
    Bd = np.linalg.solve(A, (Ad - np.eye(3)) @ B[:, 0])  # zero-order hold of δu
    c = np.array([P.piston_area, -P.rod_area, 0.0])
    errs = []
    for du in (10.0, 20.0):
        s, r, d, peak, err = st.copy(), st.copy(), np.zeros(3), 0.0, 0.0
        for _ in range(30):
            s, F, _ = act.advance(s, np.full(6, u0 + du), np.full(6, x0 + L_MIN), np.full(6, v0))
            r, F_rest, _ = act.advance(r, np.full(6, u0), np.full(6, x0 + L_MIN), np.full(6, v0))
            d = Ad @ d + Bd * du
            peak, err = max(peak, abs(c @ d)), max(err, abs(F[0] - F_rest[0] - c @ d))
        errs.append(err)
        assert err < 0.02 * peak
    assert errs[1] > 2.5 * errs[0]  # second order in the step (4× for twice the step)


def test_the_steady_demand_holds_the_force_with_the_valves_flows():
    # the pressures balance the force, and the lands at that opening pass exactly the piston's flows
    rng = np.random.default_rng(5)
    F, v = rng.uniform(-2000, 5000, (30, 6)), rng.normal(0, 0.2, (30, 6))
    d = hy.steady_demand(P, F, v)
    np.testing.assert_allclose(P.piston_area * d["p_A"] - P.rod_area * d["p_B"], F, rtol=1e-9, atol=1e-6)
    state = np.stack([d["p_A"], d["p_B"], np.sign(v) * d["spool"]])
    f = hy.flows(P, state)
    np.testing.assert_allclose(f["A"], P.piston_area * v, rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(f["B"], -P.rod_area * v, rtol=1e-9, atol=1e-15)
    beyond = hy.steady_demand(P, np.full(6, 1.01 * P.max_force), np.full(6, 0.1))
    assert np.isinf(beyond["spool"]).all()
