"""``size``: actuator sizing (peak and RMS force, speed, acceleration, power, stroke per leg) for a motion
program, a trajectory or a duty envelope, against the platform's actuator limits; for a machine with screw
actuators along a trajectory, the motors' peak torque, speed and current and RMS current against the motor's
limits too (``control.screw.motor_demand``), and for hydraulic cylinders the valve's opening, the pressures
and the supply flow against the valve and the supply (``control.hydraulic.steady_demand``)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from stewart_drake.api.design import carrying
from stewart_drake.api.dynamics import read_trajectory_csv, trajectory_rates
from stewart_drake.api.result import Result
from stewart_drake.control.hydraulic import steady_demand
from stewart_drake.control.screw import motor_demand
from stewart_drake.core.argcheck import as_flag, as_real, check_path, param
from stewart_drake.core.dynamics import seed_trajectory
from stewart_drake.core.geometry import Platform, check_platform
from stewart_drake.core.rotations import check_convention
from stewart_drake.core.sanity import check_poses
from stewart_drake.core.trajectory import Trajectory
from stewart_drake.design.envelope import envelope_sizing, load_envelope
from stewart_drake.design.hydraulic import HydraulicParameters
from stewart_drake.design.screw import ScrewParameters
from stewart_drake.design.sizing import (
    UNITS,
    TrajectorySizing,
    first_violation,
    limits_of,
    rotating_trajectory,
    size_trajectory,
    with_peak,
)
from stewart_drake.errors import API_SIZE_SOURCE, OptionError
from stewart_drake.script import run_program
from stewart_drake.script.source import read_program
from stewart_drake.spec.machine import Machine

MAX_LISTED = 10_000  # envelope poses whose allowed accelerations are listed in the JSON
MAX_SAMPLES = 10_000_000  # samples of a seed/rotating trajectory (t_end / dt)
AXES = ("x", "y", "z", "roll", "pitch", "yaw")


@dataclass(repr=False)
class SizingResult(Result):
    """Actuator sizing (``size``).

    Attributes:
        summary: per leg (peak and RMS force N, speed m/s, acceleration m/s², power W, length range m, with
            when or where each peak occurs), the set's worst, the limits and the first violation (the dict
            ``stewart-drake size --json`` prints).
        violation: the first limit exceeded (``quantity``, ``leg``, ``value``, ``limit``) and the peak the
            table shows for that quantity (``peak_leg``, ``peak``, ``peak_limit``), or None.
        where: where the violation first occurs, as text ("at t = 1.2 s", an envelope pose).
        peak_where: where the peak occurs, as text.
    """

    summary: dict
    violation: dict | None
    where: str
    peak_where: str = ""
    actuator_violation: dict | None = None

    @property
    def ok(self) -> bool:
        """Every leg (and a screw's motor, a cylinder's valve and supply) within its limits."""
        return self.violation is None and self.actuator_violation is None

    def violation_message(self) -> str | None:
        """The violation as one line: the worst excess (the peak the table shows) and where the limit is first
        exceeded; or None."""
        v = self.violation
        if v is None:
            m = self.actuator_violation
            if m is None:
                return None
            return (
                f"leg {m['leg']} {m['what']} {m['quantity']} peaks at {m['value']:.6g} {m['unit']}, beyond "
                + (f"actuators.{m['limit_name']} {m['limit']:.6g} {m['unit']}" if m["unit"] != "× full" else
                   f"a fully open valve (actuators.{m['limit_name']})")
                + ("" if m["t_s"] is None else f" at t = {m['t_s']:.4f} s")
            )  # fmt: skip
        qty = v["quantity"]
        name = "stroke" if qty == "length" else f"legs.max_{qty}"
        u = UNITS[qty]
        return (
            f"leg {v['peak_leg']} {qty} peaks at {v['peak']:.6g} {u}, beyond {name} {v['peak_limit']:.6g} {u} "
            f"{self.peak_where}; first exceeded by leg {v['leg']} ({v['value']:.6g} {u}) {self.where}"
        )

    def _fields(self) -> dict:
        return self.summary


def size(
    platform: Platform | Machine,
    trajectory: str | Path | Trajectory | None = None,
    *,
    program: str | None = None,
    envelope: str | None = None,
    legs: bool = False,
    payload: float = 0.0,
    payload_com: ArrayLike = (0.0, 0.0, 0.0),
    gravity: float = 9.81,
    rate: float = 100.0,
    t_end: float = 4.0,
    dt: float = 0.001,
    convention: str = "utn",
    length_unit: str = "m",
    angle_unit: str = "rad",
    smooth: float | None = None,
) -> SizingResult:
    """Actuator sizing for one source of motion: a trajectory, a motion program or a duty envelope.

    Args:
        platform: the platform (its ``legs`` limits are checked), or a machine: its platform, and with
            ``actuators.model: screw`` its motors (``hydraulic``: its valves and supply) sized along a trajectory
            or program too.
        trajectory: ``"seed"``, ``"rotating"``, a CSV file (as for `inverse_dynamics`) or a `Trajectory` with
            samples or exact rates.
        program: a motion program (``.stw``), sampled at ``rate``.
        envelope: a duty envelope YAML file (poses with Cartesian velocity and acceleration bounds).
        legs: include the legs' masses.
        payload: a point mass carried by the plate, kg.
        payload_com: ``(3,)`` its position in the plate frame, m.
        gravity: m/s².
        rate: a program's samples per second.
        t_end: the seed's or rotating reference's duration, s.
        dt: their time step, s.
        convention: Euler convention of a program's or CSV's angles.
        length_unit: a CSV's length unit.
        angle_unit: a CSV's angle unit.
        smooth: differentiate a 7-column CSV through a smoothing spline within this RMS tolerance (the file's
            units); without it, a file rounded so coarsely that its second differences are noise is refused.

    Returns:
        The sizing and the first violation of a limit.

    Raises:
        StewartError: not exactly one source, bad options or samples.
    """
    actuators = None
    if isinstance(platform, Machine):
        actuators, platform = sized_actuators(platform), platform.platform
    check_platform(platform)
    check_convention(convention)
    legs = as_flag(legs, "legs")
    smooth = None if smooth is None else as_real(smooth, "smooth")
    for name, value in (("program", program), ("envelope", envelope)):
        if value is not None:
            check_path(value, name)
    if trajectory is not None and not isinstance(trajectory, Trajectory):
        check_path(trajectory, "trajectory")
    sources = [s for s in (trajectory, program, envelope) if s is not None]
    if len(sources) != 1:
        raise OptionError(API_SIZE_SOURCE.format(given=len(sources)))
    loaded, p_TP = carrying(platform, payload, payload_com, gravity)
    return size_loaded(
        platform, loaded, p_TP, trajectory, program, envelope, legs, payload, gravity, rate, t_end, dt, convention,
        length_unit, angle_unit, smooth=smooth, actuators=actuators,
    )  # fmt: skip


def size_loaded(
    base, platform, p_TP, trajectory, program, envelope, legs, payload, gravity, rate, t_end, dt, convention,
    length_unit, angle_unit, envelope_shown=None, smooth=None, actuators=None,
) -> SizingResult:  # fmt: skip
    """``size`` of a platform already carrying its payload (``base``: as loaded, for its name); ``actuators``:
    the machine's ``ScrewParameters`` or ``HydraulicParameters`` (``sized_actuators``; None: the legs' limits
    only)."""
    header = {
        "platform": base.name,
        "legs_model": bool(legs),
        "payload_kg": payload,
        "payload_com_m": p_TP,
        "gravity": gravity,
    }
    if envelope is not None:
        return _envelope(platform, header, bool(legs), str(envelope), gravity)
    source, t, q, qd, qdd, convention = _samples(
        platform, trajectory, program, rate, t_end, dt, convention, length_unit, angle_unit, smooth
    )
    from_csv = program is None and not isinstance(trajectory, Trajectory) and trajectory not in ("seed", "rotating")
    check_poses(platform, q, convention, what=f"the {source} trajectory", times=t)  # finite, near, above the base
    s = size_trajectory(platform, t, q, qd, qdd, convention, legs, gravity)
    limits = limits_of(platform)
    peaks = {"force": s.force, "speed": s.speed, "power": s.power, "length": s.length}
    viol = with_peak(first_violation(limits, peaks), limits, peaks)
    legs_json = [
        {
            "leg": r["leg"],
            "peak_force_n": r["force"]["peak"],
            "peak_force_t_s": r["force"]["t"],
            "peak_force_pose": r["force"]["pose"],
            "rms_force_n": r["rms_force"],
            "peak_speed_m_s": r["speed"]["peak"],
            "peak_speed_t_s": r["speed"]["t"],
            "peak_speed_pose": r["speed"]["pose"],
            "peak_accel_m_s2": r["accel"]["peak"],
            "peak_accel_t_s": r["accel"]["t"],
            "peak_accel_pose": r["accel"]["pose"],
            "peak_power_w": r["power"]["peak"],
            "peak_power_t_s": r["power"]["t"],
            "peak_power_pose": r["power"]["pose"],
            "min_length_m": r["min_length"],
            "max_length_m": r["max_length"],
        }
        for r in s.legs()
    ]
    if viol is not None:
        viol = dict(viol, t_s=float(t[viol["index"]]), pose=q[viol["index"]], peak_t_s=float(t[viol["peak_index"]]))
    out = dict(
        header,
        source=source,
        read_units={"length": length_unit, "angle": angle_unit} if from_csv else None,
        samples=len(t),
        duration_s=float(t[-1] - t[0]) if len(t) else 0.0,
        convention=convention,
        legs=legs_json,
        set=set_summary(legs_json),
        limits=limits,
        violation=viol,
    )
    act_viol = None
    if isinstance(actuators, ScrewParameters):
        out["motor"], act_viol = motor_sizing(actuators, s)
    elif isinstance(actuators, HydraulicParameters):
        out["hydraulic"], act_viol = hydraulic_sizing(actuators, s)
    if viol is None:
        return SizingResult(out, None, "", actuator_violation=act_viol)
    return SizingResult(
        out, viol, f"at t = {viol['t_s']:.4f} s", f"at t = {viol['peak_t_s']:.4f} s", actuator_violation=act_viol
    )


def sized_actuators(machine: Machine) -> ScrewParameters | HydraulicParameters | None:
    """The parameters of ``machine``'s actuators that ``size`` checks beyond the legs' limits (None: a lag)."""
    a = machine.actuators
    if a.model == "screw":
        return a.screw(machine.platform.legs.max_force)
    if a.model == "hydraulic":
        return a.hydraulic(machine.platform)
    return None


def _worst(checks, t) -> dict | None:
    """The largest excess of ``checks`` — (quantity, (n, 6) or (6,) values, limit, limit's field, unit, what) —
    as a violation (``quantity``, ``leg``, ``value``, ``limit``, ``limit_name``, ``unit``, ``what``, ``t_s``:
    None for a value over the whole run), or None."""
    worst = None
    for qty, values, limit, field, unit, what in checks:
        peak = values if values.ndim == 1 else values.max(axis=0)
        leg = int(np.argmax(peak / limit))
        ratio = float(peak[leg] / limit)
        if ratio > 1 and (worst is None or ratio > worst[0]):
            t_s = None if values.ndim == 1 else float(t[int(np.argmax(values[:, leg]))])
            worst = (ratio, {"quantity": qty, "leg": leg + 1, "value": float(peak[leg]), "limit": float(limit),
                             "limit_name": field, "unit": unit, "what": what, "t_s": t_s})  # fmt: skip
    return None if worst is None else worst[1]


def hydraulic_sizing(hyd: HydraulicParameters, s: TrajectorySizing) -> tuple[dict, dict | None]:
    """The cylinders along the sized trajectory ``s``, the oil taken as incompressible: per leg the peak valve
    opening (1: fully open), the peak chamber pressures and supply flow with their times; the six legs' peak
    total supply flow; the force limits at the supply; and the worst excess (the opening beyond 1:
    ``valve_flow_gain``; a force beyond what the supply holds: ``supply_pressure``), or None."""
    d = steady_demand(hyd, s.force, s.speed)
    t = s.t
    legs = []
    for leg in range(6):
        row = {"leg": leg + 1}
        for name, arr in (("spool", d["spool"]), ("p_A_pa", d["p_A"]), ("p_B_pa", d["p_B"]),
                          ("supply_flow_m3_s", d["supply_flow"])):  # fmt: skip
            k = int(np.argmax(arr[:, leg]))
            row[f"peak_{name}"], row[f"peak_{name}_t_s"] = float(arr[k, leg]), float(t[k])
        legs.append(row)
    # the supply pressure that would hold the force (the other chamber at the return's)
    aa, ab, pt = hyd.piston_area, hyd.rod_area, hyd.return_pressure
    need = np.where(s.force >= 0, (s.force + ab * pt) / aa, (aa * pt - s.force) / ab)
    spool = np.where(np.isinf(d["spool"]), 0.0, d["spool"])  # beyond the supply: the pressure's violation
    # a force beyond the supply first: the valve's opening grows without bound on the way there
    worst = _worst([("pressure needed", need, hyd.supply_pressure, "supply_pressure", "Pa", "cylinder")], t)
    worst = worst or _worst([("opening", spool, 1.0, "valve_flow_gain", "× full", "valve")], t)
    summary = {
        "legs": legs,
        "total_supply_flow_m3_s": float(np.maximum(d["supply_flow"], 0).sum(axis=1).max()),
        "limits": {
            "supply_pressure": hyd.supply_pressure,
            "max_extending_force_n": float(d["max_extending"]),
            "max_retracting_force_n": float(d["max_retracting"]),
        },
        "violation": worst,
    }
    return summary, worst


# motor quantity -> (the demand's array, the limit's field, unit)
MOTOR_LIMITS = {
    "current": ("max_current", "A"),
    "speed": ("max_motor_speed", "rad/s"),
    "rms_current": ("rated_current", "A"),
}


def motor_sizing(screw: ScrewParameters, s: TrajectorySizing) -> tuple[dict, dict | None]:
    """The screw actuators' motors along the sized trajectory ``s``: per leg the peak |current| (A), |torque|
    (N·m) and |speed| (rad/s) with their times, the RMS current over the run (trapezoid over ``s.t``), the
    limits (``max_current``, ``max_motor_speed``, ``rated_current``) and the screw's derived numbers; and the
    worst excess of a limit (``quantity``, ``leg``, ``value``, ``limit``, ``limit_name``, ``unit``, ``t_s``),
    or None."""
    d = motor_demand(screw, s.force, s.speed, s.accel)
    t, i = s.t, np.abs(d["current"])
    span = float(t[-1] - t[0]) if len(t) > 1 else 0.0
    rms = np.sqrt(np.trapezoid(i**2, t, axis=0) / span) if span > 0 else i.max(axis=0)
    peaks = {"current": i, "speed": np.abs(d["speed"])}
    legs = []
    for leg in range(6):
        row = {"leg": leg + 1, "rms_current_a": float(rms[leg])}
        for name, arr, unit in (
            ("current", i, "a"),
            ("torque", np.abs(d["torque"]), "nm"),
            ("speed", peaks["speed"], "rad_s"),
        ):
            k = int(np.argmax(arr[:, leg]))
            row[f"peak_{name}_{unit}"], row[f"peak_{name}_t_s"] = float(arr[k, leg]), float(t[k])
        legs.append(row)
    checks = [
        (qty, rms if qty == "rms_current" else peaks[qty], getattr(screw, field), field, unit, "motor")
        for qty, (field, unit) in MOTOR_LIMITS.items()
    ]
    worst = _worst(checks, t)
    summary = {
        "legs": legs,
        "limits": {field: getattr(screw, field) for field, _ in MOTOR_LIMITS.values()},
        "screw": {
            "lead_m": screw.lead,
            "reflected_mass_kg": screw.reflected_mass,
            "force_per_amp_n_a": screw.force_per_amp,
            "torque_constant_nm_a": screw.torque_constant,
        },
        "violation": worst,
    }
    return summary, worst


def _samples(platform, trajectory, program, rate, t_end, dt, convention, length_unit, angle_unit, smooth=None):
    """``(source name, t, q, q̇, q̈, convention)`` of the motion to size."""
    if program is not None:
        rate = as_real(rate, param("rate"))
        if not (np.isfinite(rate) and rate > 0):
            raise OptionError(OptionError.POSITIVE.format(option=param("rate"), unit="samples per second", value=rate))
        tr = run_program(read_program(program), program, platform, rate=rate, convention=convention).trajectory
        return program, tr.t, tr.q, tr.qd, tr.qdd, convention
    if isinstance(trajectory, Trajectory):
        if trajectory.t is not None:
            return trajectory.name, trajectory.t, trajectory.q, trajectory.qd, trajectory.qdd, "utn"
        t = _times(t_end if trajectory.duration is None else trajectory.duration, dt)
        return (trajectory.name, t, *trajectory_rates(trajectory, t), "utn")
    if trajectory in ("seed", "rotating"):
        t = _times(t_end, dt)
        q, qd, qdd = (seed_trajectory if trajectory == "seed" else rotating_trajectory)(t)
        return trajectory, t, q, qd, qdd, "utn"
    t, q, qd, qdd = read_trajectory_csv(str(trajectory), length_unit, angle_unit, smooth)
    return str(trajectory), t, q, qd, qdd, convention


def _times(t_end: float, dt: float) -> np.ndarray:
    names = {"dt_name": param("dt"), "t_end_name": param("t_end")}
    t_end, dt = as_real(t_end, names["t_end_name"]), as_real(dt, names["dt_name"])
    if not (np.isfinite(dt) and dt > 0 and np.isfinite(t_end) and t_end >= 0):
        raise OptionError(OptionError.DT.format(dt=dt, t_end=t_end, **names))
    n = np.floor(t_end / dt + 0.5) + 1
    if n > MAX_SAMPLES:
        raise OptionError(OptionError.TOO_MANY_SAMPLES.format(n=f"{n:.3g}", limit=MAX_SAMPLES, **names))
    n = int(n)
    return np.arange(n) * dt


def set_summary(legs_json) -> dict:
    """The set's worst leg for each quantity, and its length range."""
    out = {}
    for key in ("peak_force_n", "rms_force_n", "peak_speed_m_s", "peak_accel_m_s2", "peak_power_w"):
        vals = [r[key] for r in legs_json]
        if any(v is None for v in vals):
            continue
        i = int(np.argmax(vals))
        out[key] = {"value": vals[i], "leg": i + 1}
    out["min_length_m"] = min(r["min_length_m"] for r in legs_json)
    out["max_length_m"] = max(r["max_length_m"] for r in legs_json)
    return out


def _envelope(platform, header, legs: bool, path: str, gravity: float) -> SizingResult:
    env = load_envelope(path)
    # a pose outside the stroke is a result outside limits (a violation, the table shown), not bad input
    es = envelope_sizing(platform, env, legs=legs, gravity=gravity, stroke=False)
    legs_json = []
    for i in range(6):
        w = es.worst[i]
        ks = int(np.argmax(es.peak_speed[:, i]))
        ka = int(np.argmax(es.peak_accel[:, i]))
        kp = int(np.argmax(es.peak_power[:, i]))
        legs_json.append(
            {
                "leg": i + 1,
                "peak_force_n": w["peak"],
                "peak_force_pose": w["pose"],
                "peak_force_pose_index": w["index"],
                "peak_force_accel": w["accel"],
                "peak_force_velocity": w["velocity"],
                "rms_force_n": None,
                "peak_speed_m_s": float(es.peak_speed[ks, i]),
                "peak_speed_pose": env.poses[ks],
                "peak_accel_m_s2": float(es.peak_accel[ka, i]),
                "peak_accel_pose": env.poses[ka],
                "peak_power_w": float(es.peak_power[kp, i]),
                "peak_power_pose": env.poses[kp],
                "min_length_m": float(es.length[:, i].min()),
                "max_length_m": float(es.length[:, i].max()),
            }
        )
    limits = limits_of(platform)
    peaks = {"force": es.peak_force, "speed": es.peak_speed, "power": es.peak_power, "length": es.length}
    viol = with_peak(first_violation(limits, peaks), limits, peaks)
    if viol is not None:
        viol = dict(
            viol, pose_index=viol["index"], pose=env.poses[viol["index"]], peak_pose=env.poses[viol["peak_index"]]
        )
    allowed = {
        "axes": list(AXES),
        "units": ["m/s²"] * 3 + ["rad/s²"] * 3,
        "min_over_poses": es.allowed_accel.min(axis=0),
    }
    if len(env.poses) <= MAX_LISTED:
        allowed["per_pose"] = es.allowed_accel
    out = dict(
        header,
        source=path,
        poses=len(env.poses),
        convention=env.convention,
        v_max=env.v_max,
        a_max=env.a_max,
        legs=legs_json,
        set=set_summary(legs_json),
        limits=limits,
        violation=viol,
        allowed_acceleration=allowed,
        bounds={
            "peak_force_n": "exact worst case",
            "peak_speed_m_s": "exact worst case",
            "peak_accel_m_s2": "upper bound",
            "peak_power_w": "upper bound (peak |F| x peak |L̇|)",
            "rms_force_n": "undefined for an envelope",
        },
    )
    if viol is None:
        return SizingResult(out, None, "")
    note = " (power over an envelope is an upper bound: peak |F| x peak |L̇|)" if viol["quantity"] == "power" else ""
    return SizingResult(
        out, viol, f"at envelope {env.shown(viol['index'])}", f"at envelope {env.shown(viol['peak_index'])}{note}"
    )
