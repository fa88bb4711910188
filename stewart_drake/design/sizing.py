"""Actuator sizing along a trajectory: per-leg force, speed, acceleration, power and stroke, their
peaks (when and where), RMS force, and the check against the actuator limits of the platform file.

Leg kinematics from the plate's rigid-body motion (``dynamics.plate_motion``): with r_i = R (p_TTi − p_TC)
and l_i = p_BC + r_i − p_BBi,

    l̇_i = v_C + ω × r_i,   l̈_i = a_C + ω̇ × r_i + ω × (ω × r_i),
    L̇_i = u_i · l̇_i,        L̈_i = u_i · l̈_i + (|l̇_i|² − L̇_i²) / L_i.

Forces are the verified inverse dynamics (``dynamics.leg_forces`` or ``leg_forces_with_legs``); power is
the actuator's mechanical power F_i L̇_i (W, > 0 when the actuator drives the plate).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stewart_drake.core.argcheck import first_index
from stewart_drake.core.dynamics import G_EARTH, harmonic_trajectory, leg_forces, leg_forces_with_legs, plate_motion
from stewart_drake.core.geometry import Platform
from stewart_drake.errors import GeometryError

QUANTITIES = ("force", "speed", "power", "length")  # order in which violations are reported
UNITS = {"force": "N", "speed": "m/s", "power": "W", "length": "m"}


def leg_motion(platform: Platform, q, qd, qdd, convention: str = "utn") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(L, L̇, L̈)`` each ``(..., 6)`` (m, m/s, m/s²) for ``(..., 6)`` q, q̇, q̈ (see the module docstring)."""
    mo = plate_motion(platform, q, qd, qdd, convention)
    q, qd, qdd = (np.broadcast_to(np.asarray(a, dtype=float), mo["R"].shape[:-2] + (6,)) for a in (q, qd, qdd))
    w, wd = mo["omega"][..., None, :], mo["omega_dot"][..., None, :]
    a_C = qdd[..., None, :3] + 0.0  # q̈'s translation part is the rotation centre's acceleration
    r = np.einsum("...ij,kj->...ki", mo["R"], platform.top_anchors_per_leg - platform.rotation_centre)
    l = q[..., None, :3] + r - platform.base_anchors
    ld = qd[..., None, :3] + np.cross(w, r)
    ldd = a_C + np.cross(wd, r) + np.cross(w, np.cross(w, r))
    L = np.linalg.norm(l, axis=-1)
    u = l / L[..., None]
    Ld = np.sum(u * ld, -1)
    Ldd = np.sum(u * ldd, -1) + (np.sum(ld * ld, -1) - Ld**2) / L
    return L, Ld, Ldd


@dataclass(frozen=True)
class TrajectorySizing:
    """Per-sample leg quantities along a trajectory: ``t`` (n,) s, ``q`` (n, 6) poses (m, rad), and
    ``(n, 6)`` arrays ``force`` (N), ``length`` (m), ``speed`` (m/s, signed L̇), ``accel`` (m/s², L̈),
    ``power`` (W, F L̇)."""

    t: np.ndarray
    q: np.ndarray
    force: np.ndarray
    length: np.ndarray
    speed: np.ndarray
    accel: np.ndarray
    power: np.ndarray

    def legs(self) -> list[dict]:
        """Six dicts (legs 1..6): peaks with the sample index, time and pose where they occur."""
        out = []
        n = len(self.t)
        for i in range(6):
            d = {"leg": i + 1}
            for key, arr in (
                ("force", self.force),
                ("speed", self.speed),
                ("accel", self.accel),
                ("power", self.power),
            ):
                k = int(np.argmax(np.abs(arr[:, i])))
                d[key] = {
                    "peak": float(abs(arr[k, i])),
                    "value": float(arr[k, i]),
                    "index": k,
                    "t": float(self.t[k]),
                    "pose": self.q[k],
                }
            d["rms_force"] = float(np.sqrt(np.mean(self.force[:, i] ** 2))) if n else 0.0
            d["min_length"] = float(self.length[:, i].min())
            d["max_length"] = float(self.length[:, i].max())
            out.append(d)
        return out


def size_trajectory(
    platform: Platform, t, q, qd, qdd, convention: str = "utn", legs: bool = False, gravity: float = G_EARTH
) -> TrajectorySizing:
    """Leg forces and motion along a trajectory: ``t`` (n,) s, ``q, q̇, q̈`` (n, 6) SI. ``legs`` adds the
    leg bodies' inertia and weight to the forces (``leg_forces_with_legs``)."""
    t = np.asarray(t, dtype=float)
    if legs:
        F = leg_forces_with_legs(platform, q, qd, qdd, convention, gravity=gravity)
    else:
        F = leg_forces(platform, q, qd, qdd, convention, gravity=gravity)
    L, Ld, Ldd = leg_motion(platform, q, qd, qdd, convention)
    return TrajectorySizing(t, np.asarray(q, dtype=float), F, L, Ld, Ldd, F * Ld)


def limits_of(platform: Platform) -> dict:
    """The actuator limits of ``platform.legs`` that are set: ``force`` N, ``speed`` m/s, ``power`` W and
    ``length`` (L_min, L_max) m."""
    lim = {"force": float(platform.legs.max_force), "length": (platform.L_min, platform.L_max)}
    for key, name in (("force", "max_force"), ("speed", "max_speed"), ("power", "max_power")):
        value = getattr(platform.legs, name)
        if value is None:
            continue
        if not (np.isfinite(value) and value > 0):
            raise GeometryError(GeometryError.LEG_LIMIT.format(name=platform.name, field=name, value=value))
        lim[key] = float(value)
    return lim


def first_violation(limits: dict, peaks: dict) -> dict | None:
    """The first limit violation, or None. ``peaks`` maps a quantity to ``(n, 6)`` magnitudes for
    ``force``/``speed``/``power`` and to ``(n, 6)`` lengths for ``length``, sample by sample; the first
    sample with any violation wins, then the order of ``QUANTITIES``, then the leg.

    Returns ``{"index", "leg" (1..6), "quantity", "value", "limit"}``."""
    best = None
    for qty in QUANTITIES:
        if qty not in limits or qty not in peaks:
            continue
        arr = np.asarray(peaks[qty])
        if qty == "length":
            lo, hi = limits["length"]
            bad = (arr < lo) | (arr > hi)
        else:
            bad = np.abs(arr) > limits[qty]
        if not bad.any():
            continue
        k, i = first_index(bad)
        if best is None or k < best["index"]:
            if qty == "length":
                limit = lo if arr[k, i] < lo else hi
            else:
                limit = limits[qty]
            best = {"index": k, "leg": i + 1, "quantity": qty, "value": float(arr[k, i]), "limit": float(limit)}
    return best


def with_peak(violation: dict | None, limits: dict, peaks: dict) -> dict | None:
    """``violation`` (of ``first_violation``) with the worst excess of its quantity over every sample and
    leg, the number a table of peaks shows: ``peak`` (the value), ``peak_leg`` (1..6), ``peak_index``,
    ``peak_limit`` (for lengths, the stroke end it passes)."""
    if violation is None:
        return None
    qty = violation["quantity"]
    arr = np.asarray(peaks[qty], dtype=float)
    if qty == "length":
        lo, hi = limits["length"]
        excess = np.maximum(lo - arr, arr - hi)
    else:
        excess = np.abs(arr) - limits[qty]
    k, i = np.unravel_index(int(np.argmax(excess)), excess.shape)
    limit = (lo if arr[k, i] < lo else hi) if qty == "length" else limits[qty]
    return dict(violation, peak=float(arr[k, i]), peak_leg=int(i) + 1, peak_index=int(k), peak_limit=float(limit))


ROTATING_AMPLITUDE = np.radians([0.0, 0.0, 0.0, 5.0, 0.0, 15.0])
ROTATING_OMEGA = np.array([0.0, 0.0, 0.0, 3.0, 0.0, 2.0])


def rotating_trajectory(t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(q, q̇, q̈)`` of ``simulation.ROTATING`` with exact derivatives: pz = 0.7 m, 5°·sin 3t about x,
    15°·sin 2t about z (utn convention); each ``t.shape + (6,)``."""
    return harmonic_trajectory(t, [0.0, 0.0, 0.7, 0.0, 0.0, 0.0], ROTATING_AMPLITUDE, ROTATING_OMEGA)
