"""The electric screw actuator of a leg as a plain law, vectorised over the six legs (``(..., 6)`` arrays).

A servo motor turns a ball or roller screw of ``lead`` m per revolution: motor angle θ = ρ·L with
ρ = 2π/lead (rad/m). The drive turns the controller's force command u (N) into a current command
i* = clip(u / k_F, ±``max_current``) with k_F = ρ·Kt (the force per ampere of a screw at rest); the
current follows i* through the current loop, a first-order lag of ``current_time_constant`` τ_i (0: none),
di/dt = (i* − i)/τ_i. The motor torque Kt·i reaches the leg through the screw:

    F = ρ·Kt·i·η^tanh(sign(i)·L̇/v_s) − F_c·tanh(L̇/v_s) − b·L̇          (N, > 0 extends the leg)

η^(+1) = η while the motor drives the load, η^(−1) = 1/η while the load drives the motor (back-driving: the
screw's losses then reduce the torque the motor feels), blended over v_s = ``FRICTION_SPEED``, as is the
Coulomb friction F_c (a force the loop holds over a plant step must not flip sign with the velocity's
rounding; both blends dissipate at every velocity). The rotor's inertia J moves with the leg: it is the
reflected mass m_eff = J·ρ² of the prismatic joint, which the plant carries (Drake's reflected inertia,
``drake.actuator_systems.set_reflected_inertia``), not this law.

Powers (W, per leg): electrical in P_e = R·i² + Kt·ω·i (copper loss plus the back-EMF's share, ω = ρ·L̇), the
shaft's Kt·i·ω, the screw's loss Kt·i·ω − F_s·L̇, the friction's F_f·L̇ and the mechanical output F·L̇ to the
leg: P_e = copper + screw + friction + mechanical at every instant (``powers``).

Stepping (``step``): the current is advanced exactly under the held current command (zero-order hold: the
lag's exp(−h/τ_i)), and the force of the new current at the leg's velocity at the step's start is held over
the plant step (the plant input is constant over a step): the force lags the velocity by up to one step, an
error of O(h·|dF/dL̇|·|L̈|) in the force.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from stewart_drake.design.screw import ScrewParameters

FRICTION_SPEED = 0.01  # m/s: the velocity over which Coulomb friction and the screw's efficiency change sign


class ScrewActuation:
    """The six legs' screw actuators stepped at the plant step ``step`` s: state the currents ``(6,)`` A."""

    has_lag = True  # the loop steps it at every plant step

    def __init__(self, params: ScrewParameters, step: float):
        self.params, self.h = params, float(step)
        tau = params.current_time_constant
        self.a = math.exp(-self.h / tau) if tau > 0 else 0.0

    def initial_current(self, hold_forces) -> np.ndarray:
        """``(6,)`` the currents (A) of a drive holding ``hold_forces`` (6, N) at rest."""
        return current_command(self.params, hold_forces)

    def start(self, hold_forces, lengths, rates) -> tuple[np.ndarray, np.ndarray]:
        """``(currents, force)``: the drive holding ``hold_forces`` (6, N), the legs at ``rates`` (6, m/s)
        (``lengths`` unused: the screw's force does not depend on them)."""
        i = self.initial_current(hold_forces)
        return i, leg_force(self.params, i, rates)

    def advance(self, current, u, lengths, rates) -> tuple[np.ndarray, np.ndarray, dict]:
        """The plant step at a stop under the held command ``u`` (6, N), the legs moving at ``rates`` (6, m/s)
        there: ``(currents, force to hold over the next step (6, N), powers (W) over it)``."""
        i = self.step(current, u)
        return i, leg_force(self.params, i, rates), powers(self.params, i, rates)

    def step(self, current, u) -> np.ndarray:
        """``(6,)`` the currents after a plant step from ``current`` under the held command ``u`` (6, N)."""
        return self.a * current + (1 - self.a) * current_command(self.params, u)


def current_command(p: ScrewParameters, u) -> np.ndarray:
    """``(..., 6)`` the drive's current command i* (A) of force commands ``u`` (N): u/k_F within ±max_current."""
    return np.clip(np.asarray(u, dtype=float) / p.force_per_amp, -p.max_current, p.max_current)


def efficiency_factor(p: ScrewParameters, current, velocity) -> np.ndarray:
    """``(..., 6)`` η^tanh(sign(i)·L̇/v_s): η driving, 1/η back-driven (see the module's docstring)."""
    return p.efficiency ** np.tanh(np.sign(current) * np.asarray(velocity, dtype=float) / FRICTION_SPEED)


def friction_force(p: ScrewParameters, velocity) -> np.ndarray:
    """``(..., 6)`` F_f = F_c·tanh(L̇/v_s) + b·L̇ (N, opposing the velocity ``velocity`` m/s)."""
    v = np.asarray(velocity, dtype=float)
    return p.coulomb_friction * np.tanh(v / FRICTION_SPEED) + p.viscous_friction * v


def leg_force(p: ScrewParameters, current, velocity) -> np.ndarray:
    """``(..., 6)`` the force on the leg (N) of motor currents ``current`` (A) at leg velocities ``velocity``
    (m/s): the screw's ρ·Kt·i·η^… less friction."""
    i = np.asarray(current, dtype=float)
    return p.ratio * p.torque_constant * i * efficiency_factor(p, i, velocity) - friction_force(p, velocity)


def current_derivative(p: ScrewParameters, current, u) -> np.ndarray:
    """``(..., 6)`` di/dt (A/s) of the current loop at ``current`` A under force command ``u`` N."""
    return (current_command(p, u) - np.asarray(current, dtype=float)) / p.current_time_constant


def powers(p: ScrewParameters, current, velocity) -> dict:
    """The power flows (W) at currents ``current`` (..., 6) A and leg velocities ``velocity`` (..., 6) m/s:
    ``electrical`` in (R·i² + Kt·ω·i), ``copper`` (R·i²), ``screw`` (the screw's loss), ``friction`` and
    ``mechanical`` (F·L̇ to the leg); electrical = copper + screw + friction + mechanical."""
    i, v = np.asarray(current, dtype=float), np.asarray(velocity, dtype=float)
    shaft = p.torque_constant * i * p.ratio * v
    screw_out = p.ratio * p.torque_constant * i * efficiency_factor(p, i, v) * v
    friction = friction_force(p, v) * v
    copper = p.winding_resistance * i**2
    return {
        "electrical": copper + shaft,
        "copper": copper,
        "screw": shaft - screw_out,
        "friction": friction,
        "mechanical": screw_out - friction,
    }


def linearisation(p: ScrewParameters, current: float, velocity: float) -> tuple[float, float, float, float]:
    """One leg's actuator linearised at ``current`` A and leg velocity ``velocity`` m/s, the current
    loop unsaturated: di/dt = a·δi + b·δu, δF = c·δi + d·δL̇. Returns ``(a, b, c, d)``: a = −1/τ_i (1/s),
    b = 1/(τ_i·k_F) (A/(N·s)), c = ∂F/∂i (N/A), d = ∂F/∂L̇ (N·s/m, < 0: the friction's and the screw's
    damping). τ_i = 0 has no current state: then a = −inf, b = inf (i = u/k_F)."""
    tau, s = p.current_time_constant, math.copysign(1.0, current)
    w = s * velocity / FRICTION_SPEED
    eta_w = p.efficiency ** math.tanh(w)
    sech2 = 1 - math.tanh(w) ** 2
    c = p.ratio * p.torque_constant * eta_w
    d_eff = p.ratio * p.torque_constant * current * eta_w * math.log(p.efficiency) * sech2 * s / FRICTION_SPEED
    d_fric = p.coulomb_friction * (1 - math.tanh(velocity / FRICTION_SPEED) ** 2) / FRICTION_SPEED
    d = d_eff - d_fric - p.viscous_friction
    if tau > 0:
        return -1 / tau, 1 / (tau * p.force_per_amp), c, d
    return -math.inf, math.inf, c, d


def motor_demand(p: ScrewParameters, force, velocity, acceleration) -> dict:
    """What the motors must give for the legs to apply ``force`` (..., 6) N (the inverse dynamics') while
    moving at ``velocity`` m/s and accelerating at ``acceleration`` m/s² (each (..., 6)): the screw force
    F_s = F + m_eff·L̈ + F_f(L̇) (the rotor accelerated and the friction overcome) from the current
    i = F_s/(ρ·Kt·η^tanh(sign(F_s)·L̇/v_s)) (``leg_force`` inverted). Returns ``current`` A, ``torque`` Kt·i N·m
    and ``speed`` ρ·L̇ rad/s."""
    v, a = np.asarray(velocity, dtype=float), np.asarray(acceleration, dtype=float)
    screw_force = np.asarray(force, dtype=float) + p.reflected_mass * a + friction_force(p, v)
    current = screw_force / (p.ratio * p.torque_constant * efficiency_factor(p, screw_force, v))
    return {"current": current, "torque": p.torque_constant * current, "speed": p.ratio * v}


@dataclass(frozen=True)
class SmallSignal:
    """The six screw actuators linearised at rest holding forces, as the loop steps them every ``step`` s:
    at each plant step i ← ``a``·i + ``beta``·u, then F = ``c``·i + ``d``·L̇ held over the step; ``reflected_mass``
    (kg) rides on each leg. ``d`` (6,) N·s/m: at rest the blended Coulomb friction and efficiency damp
    (−F_c/v_s, and ρ·Kt·|i|·ln η/v_s with the holding current)."""

    a: float
    beta: float
    c: float
    d: np.ndarray
    reflected_mass: float


def small_signal(p: ScrewParameters, hold_forces, step: float) -> SmallSignal:
    """``SmallSignal`` of the screws holding ``hold_forces`` (6,) N at rest, stepped every ``step`` s
    (``linearisation`` at L̇ = 0 of each leg's holding current, its current loop discretised exactly)."""
    act = ScrewActuation(p, step)
    currents = act.initial_current(np.asarray(hold_forces, dtype=float).reshape(6))
    lin = [linearisation(p, float(i), 0.0) for i in currents]
    return SmallSignal(act.a, (1 - act.a) / p.force_per_amp, lin[0][2], np.array([x[3] for x in lin]), p.reflected_mass)
