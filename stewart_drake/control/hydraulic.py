"""The hydraulic cylinder of a leg as a plain law, vectorised over the six legs: a servo valve feeding a
differential cylinder, with the chambers' pressure dynamics.

State per leg: the chamber pressures p_A (cap side, extends) and p_B (annulus), Pa, and the valve's spool s
(−1..1 of full opening); state arrays are ``(3, ..., 6)``: (p_A, p_B, s). The drive closes a force loop: the
spool command is s* = clip(k·(u − F_h) + A·ẋ/(K_v·√(Δp_s/2)), ±1) for a force command u (N), the cylinder's
force F_h = A_A·p_A − A_B·p_B and the piston's velocity ẋ (A = A_A extending, A_B retracting, Δp_s = p_s − p_t:
the velocity compensation, the opening that feeds the moving piston at half the supply's drop, without which the
force loop alone is a damper of A_A/(k·K_v·√(Δp_s/2)) N·s/m), and the spool follows as a first-order lag,
ds/dt = (s* − s)/τ_v. A critical-centre
valve's turbulent lands, q(Δp) = K_v·sign(Δp)·√|Δp|: for s ≥ 0 the supply feeds A (Q_A = s·q(p_s − p_A)) and B
drains to the return (Q_B = −s·q(p_B − p_t)); for s < 0 the reverse. With the leakage Q_L = C_L·(p_A − p_B)
across the piston, the extension x = L − L_min and the chamber volumes V_A = V_0 + A_A·x, V_B = V_0 + A_B·(stroke − x):

    dp_A/dt = β/V_A·(Q_A − Q_L − A_A·ẋ)        dp_B/dt = β/V_B·(Q_B + Q_L + A_B·ẋ)

Powers (W, per leg): hydraulic in p_s·Q_s − p_t·Q_t (the pump's flow in, the return's out) = the valve's
throttling Σ Δp·Q over its lands + the leakage's C_L·(p_A − p_B)² + the oil's compression p_A·V_A·ṗ_A/β +
p_B·V_B·ṗ_B/β + the mechanical F_h·ẋ to the leg, at every instant (``powers``).

Stepping (``HydraulicActuation.advance``): the state is integrated over the plant step that ends at the stop with
classic RK4 in ``SUBSTEPS`` sub-steps (error O((h/n)⁴) for the pressures under the held leg velocity), the leg's
velocity at the stop held over the step and its extension moving with it; the force of the end state is held over
the next step (the pressures see the plant's velocity one step late at most: an O(h) coupling error).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg import expm

from stewart_drake.design.hydraulic import HydraulicParameters

SUBSTEPS = 4  # RK4 sub-steps of the pressures per plant step


def orifice(p: HydraulicParameters, dp) -> np.ndarray:
    """q(Δp) = K_v·sign(Δp)·√|Δp| (m³/s per unit opening) of pressure drops ``dp`` Pa."""
    dp = np.asarray(dp, dtype=float)
    return p.valve_flow_gain * np.sign(dp) * np.sqrt(np.abs(dp))


def cylinder_force(p: HydraulicParameters, state) -> np.ndarray:
    """``(..., 6)`` F_h = A_A·p_A − A_B·p_B (N) of ``state`` (3, ..., 6)."""
    return p.piston_area * state[0] - p.rod_area * state[1]


def volumes(p: HydraulicParameters, extension) -> tuple[np.ndarray, np.ndarray]:
    """``(V_A, V_B)`` m³ at ``extension`` x (m, clipped to the stroke)."""
    x = np.clip(np.asarray(extension, dtype=float), 0.0, p.stroke)
    return p.dead_volume + p.piston_area * x, p.dead_volume + p.rod_area * (p.stroke - x)


def flows(p: HydraulicParameters, state) -> dict:
    """The valve's and the piston's flows (m³/s) at ``state``: ``A`` and ``B`` into the chambers, ``supply`` from
    the pump, ``return`` to the tank, ``leak`` from A to B, and ``throttle`` the valve's Σ Δp·Q (W)."""
    pa, pb, s = state[0], state[1], state[2]
    ps, pt = p.supply_pressure, p.return_pressure
    sp, sn = np.maximum(s, 0.0), np.minimum(s, 0.0)
    sa, bt, at, sb = ps - pa, pb - pt, pa - pt, ps - pb  # the four lands' drops
    qsa, qbt, qat, qsb = orifice(p, sa), orifice(p, bt), orifice(p, at), orifice(p, sb)
    return {
        "A": sp * qsa + sn * qat,
        "B": -sp * qbt - sn * qsb,
        "supply": sp * qsa - sn * qsb,
        "return": sp * qbt - sn * qat,
        "leak": p.leakage * (pa - pb),
        "throttle": sp * (sa * qsa + bt * qbt) - sn * (at * qat + sb * qsb),
    }


def feed(p: HydraulicParameters, rate) -> np.ndarray:
    """``(..., 6)`` the velocity compensation's spool opening for piston velocities ``rate`` m/s."""
    v = np.asarray(rate, dtype=float)
    area = np.where(v > 0, p.piston_area, p.rod_area)
    return area * v / (p.valve_flow_gain * math.sqrt((p.supply_pressure - p.return_pressure) / 2))


def derivative(p: HydraulicParameters, state, u, extension, rate) -> np.ndarray:
    """d(state)/dt ``(3, ..., 6)`` at ``state`` under force command ``u`` N, the legs at ``extension`` m moving
    at ``rate`` m/s."""
    va, vb = volumes(p, extension)
    f = flows(p, state)
    v = np.asarray(rate, dtype=float)
    s_cmd = np.clip(p.force_gain * (np.asarray(u, dtype=float) - cylinder_force(p, state)) + feed(p, v), -1.0, 1.0)
    return np.stack(
        [
            p.bulk_modulus / va * (f["A"] - f["leak"] - p.piston_area * v),
            p.bulk_modulus / vb * (f["B"] + f["leak"] + p.rod_area * v),
            (s_cmd - state[2]) / p.valve_time_constant,
        ]
    )


def powers(p: HydraulicParameters, state, extension, rate) -> dict:
    """The power flows (W): ``hydraulic`` in, ``throttle`` (the valve), ``leakage``, ``compression`` (into the
    oil) and ``mechanical`` (F_h·ẋ to the leg); hydraulic = throttle + leakage + compression + mechanical."""
    va, vb = volumes(p, extension)
    f = flows(p, state)
    v = np.asarray(rate, dtype=float)
    pa, pb = state[0], state[1]
    net_a = f["A"] - f["leak"] - p.piston_area * v  # the flows that compress the oil (V·ṗ/β)
    net_b = f["B"] + f["leak"] + p.rod_area * v
    return {
        "hydraulic": p.supply_pressure * f["supply"] - p.return_pressure * f["return"],
        "throttle": f["throttle"],
        "leakage": f["leak"] * (pa - pb),
        "compression": pa * net_a + pb * net_b,
        "mechanical": cylinder_force(p, state) * v,
    }


class HydraulicActuation:
    """The six legs' cylinders stepped at the plant step ``step`` s, the legs' shortest length ``L_min`` m."""

    has_lag = True  # the loop steps it at every plant step

    def __init__(self, params: HydraulicParameters, step: float, L_min: float):
        self.params, self.h, self.L_min = params, float(step), float(L_min)

    def start(self, hold_forces, lengths, rates) -> tuple[np.ndarray, np.ndarray]:
        """``(state, force)``: holding ``hold_forces`` (6, N) at rest with the spool centred, at the pressures a
        leaking piston settles to (equal drops across the two open lands: p_A + p_B = p_s + p_t) that hold it."""
        p = self.params
        total = p.supply_pressure + p.return_pressure
        pa = (np.asarray(hold_forces, dtype=float) + p.rod_area * total) / (p.piston_area + p.rod_area)
        pb = total - pa
        state = np.stack([pa, pb, np.zeros(6)])
        return state, cylinder_force(p, state)

    def advance(self, state, u, lengths, rates) -> tuple[np.ndarray, np.ndarray, dict]:
        """The plant step ending at the legs' ``lengths`` (6, m) and ``rates`` (6, m/s), under the held command
        ``u`` (6, N): ``(state, force to hold (6, N), powers (W) at the step's end)``."""
        p, v = self.params, np.asarray(rates, dtype=float)
        x_end = np.asarray(lengths, dtype=float) - self.L_min
        dt = self.h / SUBSTEPS
        x = x_end - v * self.h
        for _ in range(SUBSTEPS):
            k1 = derivative(p, state, u, x, v)
            k2 = derivative(p, state + 0.5 * dt * k1, u, x + 0.5 * dt * v, v)
            k3 = derivative(p, state + 0.5 * dt * k2, u, x + 0.5 * dt * v, v)
            k4 = derivative(p, state + dt * k3, u, x + dt * v, v)
            state = state + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
            x = x + dt * v
        return state, cylinder_force(p, state), powers(p, state, x_end, v)


def linearisation(p: HydraulicParameters, state, extension: float, rate: float) -> tuple[np.ndarray, np.ndarray]:
    """One leg's cylinder linearised at ``state`` (3,) (spool ≠ 0, unsaturated, the pressures inside
    (p_t, p_s)), ``extension`` m and ``rate`` m/s: d(state)/dt ≈ A·δstate + B·(δu, δẋ, δx). Returns ``(A (3, 3),
    B (3, 3))``; the force is δF = (A_A, −A_B, 0)·δstate."""
    pa, pb, s = (float(v) for v in state)
    ps, pt, kv, beta = p.supply_pressure, p.return_pressure, p.valve_flow_gain, p.bulk_modulus
    va, vb = (float(v) for v in volumes(p, extension))
    dq = lambda dp: kv / (2 * math.sqrt(abs(dp)))  # noqa: E731 -- ∂q/∂Δp of one land
    if s > 0:
        qa_pa, qa_s = -s * dq(ps - pa), float(orifice(p, ps - pa))
        qb_pb, qb_s = -s * dq(pb - pt), -float(orifice(p, pb - pt))
    else:
        qa_pa, qa_s = s * dq(pa - pt), float(orifice(p, pa - pt))
        qb_pb, qb_s = s * dq(ps - pb), -float(orifice(p, ps - pb))
    f = flows(p, np.array([[pa], [pb], [s]]))
    net_a = float(f["A"][0] - f["leak"][0]) - p.piston_area * rate
    net_b = float(f["B"][0] + f["leak"][0]) + p.rod_area * rate
    cl, k, tau = p.leakage, p.force_gain, p.valve_time_constant
    A = np.array(
        [
            [beta / va * (qa_pa - cl), beta / va * cl, beta / va * qa_s],
            [beta / vb * cl, beta / vb * (qb_pb - cl), beta / vb * qb_s],
            [-k * p.piston_area / tau, k * p.rod_area / tau, -1 / tau],
        ]
    )
    B = np.array(
        [
            [0.0, -beta / va * p.piston_area, -beta * p.piston_area / va**2 * net_a],
            [0.0, beta / vb * p.rod_area, beta * p.rod_area / vb**2 * net_b],
            [k / tau, float(feed(p, 1.0 if rate > 0 else -1.0)) * (1 if rate > 0 else -1) / tau, 0.0],
        ]
    )
    return A, B


def steady_demand(p: HydraulicParameters, force, velocity) -> dict:
    """What the cylinders need, the oil incompressible, to apply ``force`` (..., 6) N while moving at ``velocity``
    (..., 6) m/s: the meter-in land feeds A_A·ẋ (extending; A_B·|ẋ| retracting) at p_s − A²·z and the meter-out
    land passes the other side's flow at p_t + A²·z, z = (ẋ/(s·K_v))² from the force balance. Returns ``spool``
    (the opening, > 1: beyond the valve; inf: beyond the supply), ``p_A``, ``p_B`` (Pa), ``supply_flow`` (m³/s)
    and the force limits at the supply, ``max_extending`` and ``max_retracting`` (N, the latter < 0)."""
    F, v = np.asarray(force, dtype=float), np.asarray(velocity, dtype=float)
    aa, ab, ps, pt = p.piston_area, p.rod_area, p.supply_pressure, p.return_pressure
    ext, ret = aa * ps - ab * pt, aa * pt - ab * ps  # the forces at full pressure either way
    extending = v >= 0
    z = np.where(extending, ext - F, F - ret) / (aa**3 + ab**3)
    p_a = np.where(extending, ps - aa**2 * z, pt + aa**2 * z)
    p_b = np.where(extending, pt + ab**2 * z, ps - ab**2 * z)
    with np.errstate(divide="ignore", invalid="ignore"):
        spool = np.where(z > 0, np.abs(v) / (p.valve_flow_gain * np.sqrt(np.maximum(z, 0.0))), np.inf)
    spool = np.where((v == 0) & (z > 0), 0.0, spool)
    return {
        "spool": spool,
        "p_A": p_a,
        "p_B": p_b,
        "supply_flow": np.where(extending, aa * v, -ab * v),
        "max_extending": ext,
        "max_retracting": ret,
    }


@dataclass(frozen=True)
class SmallSignal:
    """The six cylinders linearised at rest holding forces, as the loop steps them every plant step: per leg
    a' = ``E``·a + ``G_u``·u + ``G_v``·L̇ over the step (a = (p_A, p_B, s), L̇ the leg's velocity at the step's
    end, held) and the force ``c``·a' held over the next: ``E`` (6, 3, 3), ``G_u`` and ``G_v`` (6, 3), ``c`` (3,)."""

    E: np.ndarray
    G_u: np.ndarray
    G_v: np.ndarray
    c: np.ndarray


def small_signal(p: HydraulicParameters, hold_forces, lengths, L_min: float, step: float) -> SmallSignal:
    """``SmallSignal`` of the cylinders holding ``hold_forces`` (6,) N at rest at ``lengths`` (6,) m
    (``HydraulicActuation.start``'s pressures, with the spool s_eq open just enough to feed the leakage). The
    valve's gain about a centred spool differs on its two sides (q(p_s − p_A) opening to the supply, q(p_A − p_t)
    to the return), and so does the velocity compensation's (A_A, A_B); their means are the fundamental of a
    sinusoidal spool's flow (the describing function), the gains used here; at ±|s_eq| the lands' pressure
    terms hold the chambers' pressure level (without them it is a neutral mode). The step's map over ``step`` s
    is exact for the linear model (zero-order hold, ``scipy.linalg.expm``)."""
    act = HydraulicActuation(p, step, L_min)
    state, _ = act.start(np.asarray(hold_forces, dtype=float).reshape(6), lengths, np.zeros(6))
    x = np.asarray(lengths, dtype=float).reshape(6) - L_min
    E, G_u, G_v = np.empty((6, 3, 3)), np.empty((6, 3)), np.empty((6, 3))
    pa, pb = state[0], state[1]
    leak = p.leakage * (pa - pb)
    s_eq = leak / np.where(leak > 0, orifice(p, p.supply_pressure - pa), orifice(p, pa - p.return_pressure))
    for leg in range(6):
        st = np.r_[state[:2, leg], s_eq[leg]]
        lin = [linearisation(p, st, x[leg], side) for side in (1e-300, -1e-300)]
        A = lin[0][0]  # the valve on the side that feeds the leakage
        B = 0.5 * (lin[0][1] + lin[1][1])[:, :2]  # (u, ẋ): the compensation's mean; the volumes' term is 0 at rest
        n = 5
        Z = np.zeros((n, n))
        Z[:3, :3], Z[:3, 3:] = A * step, B * step
        X = expm(Z)
        E[leg], G_u[leg], G_v[leg] = X[:3, :3], X[:3, 3], X[:3, 4]
    return SmallSignal(E, G_u, G_v, np.array([p.piston_area, -p.rod_area, 0.0]))
