"""A hydraulic cylinder's parameters (``control.hydraulic`` is its law): what a data sheet gives, and their
defaults sized from the leg's force limit, stroke and speed."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace


@dataclass(frozen=True)
class HydraulicParameters:
    """One leg's servo-valve-driven differential cylinder (the six are alike), SI: ``piston_area`` A_A m² (the
    cap side, extending) and ``rod_area`` the annulus A_B m² (retracting), ``dead_volume`` m³ of each chamber
    at its end of stroke (hoses, manifold), ``stroke`` m (L_max − L_min), ``bulk_modulus`` β Pa (the oil's,
    hoses included), ``supply_pressure`` and ``return_pressure`` Pa, ``valve_flow_gain`` K_v m³/(s·√Pa) (the
    flow of a fully open land per √Δp), ``valve_time_constant`` s (the spool as a first-order lag; 0: ideal),
    ``leakage`` m³/(s·Pa) (across the piston), ``force_gain`` 1/N (the drive's force loop: spool command per
    newton of force error)."""

    piston_area: float
    rod_area: float
    dead_volume: float
    stroke: float
    bulk_modulus: float
    supply_pressure: float
    return_pressure: float
    valve_flow_gain: float
    valve_time_constant: float
    leakage: float
    force_gain: float

    @classmethod
    def defaults(cls, max_force: float, stroke: float, max_speed: float | None = None, **given) -> HydraulicParameters:
        """Parameters of a cylinder sized for ``max_force`` N over ``stroke`` m at ``max_speed`` m/s (None: 0.5),
        ``given`` (non-None) replacing them: 100 bar supply, tank at 0; the annulus gives ``max_force`` at 80 %
        of the supply (A_B = F_max/(0.8·p_s)) and the piston twice it (a 2:1 rod); dead volumes of half a
        chamber's swept volume; β = 1 GPa (oil and hoses); a valve that moves the piston at ``max_speed`` with
        half the supply across a land (K_v = A_A·v_max/√(p_s/2)) with a 1 ms spool; a leakage of
        1e-13 m³/(s·Pa); and a force loop with a 150 Hz pole at mid-stroke against a blocked piston (``force_gain``
        = 2π·50/k_F, k_F the force's rate per unit spool). Areas, volumes and valve scale with force, stroke and
        speed; pressures, β and the time constants are a typical industrial servo's."""
        g = {k: v for k, v in given.items() if v is not None}
        ps = float(g.get("supply_pressure", 10e6))
        rod = float(g.get("rod_area", max_force / (0.8 * ps)))
        piston = float(g.get("piston_area", 2 * rod))
        v_max = 0.5 if max_speed is None else float(max_speed)
        beta = float(g.get("bulk_modulus", 1e9))
        dead = float(g.get("dead_volume", 0.5 * piston * stroke))
        kv = float(g.get("valve_flow_gain", piston * v_max / math.sqrt(ps / 2)))
        # blocked piston at mid-stroke, spool s: dF/dt = β·(A_A/V_A + A_B/V_B)·K_v·√(p_s/2)·s
        k_f = beta * (piston / (dead + piston * stroke / 2) + rod / (dead + rod * stroke / 2)) * kv * math.sqrt(ps / 2)
        base = cls(
            piston_area=piston,
            rod_area=rod,
            dead_volume=dead,
            stroke=float(stroke),
            bulk_modulus=beta,
            supply_pressure=ps,
            return_pressure=0.0,
            valve_flow_gain=kv,
            valve_time_constant=1e-3,
            leakage=1e-13,
            force_gain=2 * math.pi * 150 / k_f,
        )
        names = {f.name for f in fields(cls)}
        return replace(base, **{k: v for k, v in g.items() if k in names})

    @property
    def max_force(self) -> float:
        """The extending force at the supply pressure with the annulus at the return's (N)."""
        return self.piston_area * self.supply_pressure - self.rod_area * self.return_pressure
