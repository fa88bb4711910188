"""An electric screw actuator's parameters (``control.screw`` is its law): what a data sheet gives, their
defaults sized from the leg's force limit, and the derived gains of the screw."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

RPM = 2 * math.pi / 60  # rad/s per rev/min


@dataclass(frozen=True)
class ScrewParameters:
    """One leg's screw actuator (the six are alike), SI: ``lead`` m/rev, ``torque_constant`` Kt N·m/A (= the
    back-EMF constant V·s/rad), ``rotor_inertia`` J kg·m², ``efficiency`` η (0, 1], ``coulomb_friction`` N,
    ``viscous_friction`` N·s/m, ``max_current`` A (the drive's peak), ``rated_current`` A (the motor's
    continuous, RMS), ``max_motor_speed`` rad/s, ``current_time_constant`` s (0: an ideal current loop),
    ``winding_resistance`` Ω, ``encoder_counts`` per motor revolution (None: the legs' own length sensor)."""

    lead: float
    torque_constant: float
    rotor_inertia: float
    efficiency: float
    coulomb_friction: float
    viscous_friction: float
    max_current: float
    rated_current: float
    max_motor_speed: float
    current_time_constant: float
    winding_resistance: float
    encoder_counts: int | None = None

    @classmethod
    def defaults(cls, max_force: float, **given) -> ScrewParameters:
        """Parameters of a screw actuator sized for ``max_force`` N, ``given`` (non-None) replacing them: a
        10 mm lead, η 0.9, Kt 0.5 N·m/A, the current limit that gives ``max_force`` at rest (i_max =
        F_max/(ρ·Kt)), a rated current of a third of it, a low-inertia servo's rotor (J = 1e-5 kg·m² per N·m
        of the peak torque F_max·lead/2π), 3000 rpm, a 0.2 ms current loop, 1 Ω, Coulomb friction 1 % of F_max and
        viscous friction 1 % of F_max at 0.1 m/s. The current limit, rotor and friction scale with the force
        (a larger machine has a larger motor); the rest are a typical catalogue servo's."""
        g = {k: v for k, v in given.items() if v is not None}
        lead = float(g.get("lead", 0.01))
        eta = float(g.get("efficiency", 0.9))
        kt = float(g.get("torque_constant", 0.5))
        peak_torque = max_force * lead / (2 * math.pi)
        i_max = float(g.get("max_current", peak_torque / kt))
        base = cls(
            lead=lead,
            torque_constant=kt,
            rotor_inertia=1e-5 * peak_torque,
            efficiency=eta,
            coulomb_friction=0.01 * max_force,
            viscous_friction=0.1 * max_force,
            max_current=i_max,
            rated_current=i_max / 3,
            max_motor_speed=3000 * RPM,
            current_time_constant=2e-4,
            winding_resistance=1.0,
        )
        names = {f.name for f in fields(cls)}
        return replace(base, **{k: v for k, v in g.items() if k in names})

    @property
    def ratio(self) -> float:
        """ρ = 2π/lead: motor radians per metre of leg travel."""
        return 2 * math.pi / self.lead

    @property
    def reflected_mass(self) -> float:
        """m_eff = J·ρ² (kg): the rotor's inertia as a mass on the leg."""
        return self.rotor_inertia * self.ratio**2

    @property
    def force_per_amp(self) -> float:
        """k_F = ρ·Kt (N/A): the leg force per ampere at rest (η× that while the motor drives the leg, 1/η×
        while the leg drives the motor)."""
        return self.ratio * self.torque_constant

    @property
    def max_force(self) -> float:
        """The force at the current limit at rest (N): k_F·i_max."""
        return self.force_per_amp * self.max_current

    @property
    def encoder_resolution(self) -> float | None:
        """Leg travel per encoder count (m), None without a motor encoder."""
        return None if self.encoder_counts is None else self.lead / self.encoder_counts
