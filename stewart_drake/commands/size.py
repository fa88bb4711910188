"""``stewart-drake size``: actuator sizing for a motion program, a trajectory or a duty envelope."""

from __future__ import annotations

import sys

import numpy as np

from stewart_drake.commands._common import add_platform_arg, platform_from_args, print_json
from stewart_drake.commands._design import add_payload_args, platform_with_payload
from stewart_drake.commands.dynamics import read_trajectory_csv
from stewart_drake.core.dynamics import seed_trajectory
from stewart_drake.core.rotations import CONVENTIONS
from stewart_drake.core.sanity import check_poses
from stewart_drake.design.envelope import envelope_sizing, load_envelope
from stewart_drake.design.sizing import (
    UNITS,
    first_violation,
    limits_of,
    rotating_trajectory,
    size_trajectory,
    with_peak,
)
from stewart_drake.errors import OptionError
from stewart_drake.script import ScriptError, run_program
from stewart_drake.script.source import read_program

MAX_LISTED = 10_000  # envelope poses whose allowed accelerations are listed in the JSON
MAX_SAMPLES = 10_000_000  # samples of a seed/rotating trajectory (--t-end / --dt)
AXES = ("x", "y", "z", "roll", "pitch", "yaw")


def register(sub) -> None:
    p = sub.add_parser("size", help="actuator sizing: peak/RMS force, speed, acceleration, power and stroke per leg")
    add_platform_arg(p, default="utn-dynamic")
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--program", metavar="P.stw", help="a motion program (sampled at --rate)")
    src.add_argument(
        "--trajectory",
        metavar="seed|rotating|FILE.csv",
        help="'seed' (px = -0.1 m, py = 0.1 sin 2t m, pz = 0.7 m), 'rotating' (15° sin 2t about z, 5° sin 3t about x at "
        "pz = 0.7 m), or a CSV as for `dynamics` (t + 6 pose columns, or t, q, q̇, q̈)",
    )
    src.add_argument(
        "--envelope", metavar="FILE.yaml", help="a duty envelope: poses + Cartesian velocity and acceleration bounds"
    )
    add_payload_args(p, "in --length-unit")
    p.add_argument("--rate", type=float, default=100.0, help="--program: samples per second (default 100)")
    p.add_argument("--t-end", type=float, default=4.0, help="seed/rotating: duration in s (default 4)")
    p.add_argument("--dt", type=float, default=0.001, help="seed/rotating: time step in s (default 0.001)")
    p.add_argument(
        "--convention",
        choices=list(CONVENTIONS),
        default="utn",
        help="Euler convention of program/CSV angles (default utn)",
    )
    p.add_argument(
        "--length-unit", choices=["m", "mm"], default="m", help="CSV positions and --payload-com (default m)"
    )
    p.add_argument("--angle-unit", choices=["rad", "deg", "pi"], default="rad", help="CSV angles (default rad)")
    p.add_argument(
        "--smooth",
        type=float,
        default=None,
        metavar="TOL",
        help="differentiate a CSV through a smoothing spline within TOL (RMS, in the file's units) of its samples: "
        "for files rounded so coarsely that their second differences are noise (refused without it)",
    )
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=run)


def _trajectory(args, platform):
    if args.program is not None:
        if not (np.isfinite(args.rate) and args.rate > 0):
            raise OptionError(OptionError.POSITIVE.format(option="--rate", unit="samples per second", value=args.rate))
        tr = run_program(
            read_program(args.program), args.program, platform, rate=args.rate, convention=args.convention
        ).trajectory
        return args.program, tr.t, tr.q, tr.qd, tr.qdd, args.convention
    if args.trajectory in ("seed", "rotating"):
        if not (np.isfinite(args.dt) and args.dt > 0 and np.isfinite(args.t_end) and args.t_end >= 0):
            raise OptionError(OptionError.DT.format(dt=args.dt, t_end=args.t_end))
        n = int(np.floor(args.t_end / args.dt + 0.5)) + 1
        if n > MAX_SAMPLES:
            raise OptionError(OptionError.TOO_MANY_SAMPLES.format(n=n, limit=MAX_SAMPLES))
        t = np.arange(n) * args.dt
        q, qd, qdd = (seed_trajectory if args.trajectory == "seed" else rotating_trajectory)(t)
        return args.trajectory, t, q, qd, qdd, "utn"
    t, q, qd, qdd = read_trajectory_csv(args.trajectory, args.length_unit, args.angle_unit, args.smooth)
    return args.trajectory, t, q, qd, qdd, args.convention


def run(args) -> int:
    base = platform_from_args(args)
    platform, p_TP = platform_with_payload(base, args, args.length_unit)
    legs = args.legs == "on"
    header = {
        "platform": base.name,
        "legs_model": legs,
        "payload_kg": args.payload,
        "payload_com_m": p_TP,
        "gravity": args.gravity,
    }
    if args.envelope is not None:
        return _run_envelope(args, platform, header, legs)
    try:
        source, t, q, qd, qdd, convention = _trajectory(args, platform)
    except ScriptError as e:
        print(e.render(), file=sys.stderr)
        return 2
    check_poses(platform, q, convention, what=f"the {source} trajectory", times=t)  # finite, near, above the base
    s = size_trajectory(platform, t, q, qd, qdd, convention, legs, args.gravity)
    limits = limits_of(platform)
    peaks = {"force": s.force, "speed": s.speed, "power": s.power, "length": s.length}
    viol = with_peak(first_violation(limits, peaks), limits, peaks)
    rows = s.legs()
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
        for r in rows
    ]
    if viol is not None:
        viol = dict(viol, t_s=float(t[viol["index"]]), pose=q[viol["index"]], peak_t_s=float(t[viol["peak_index"]]))
    out = dict(
        header,
        source=source,
        read_units=None
        if args.trajectory in ("seed", "rotating") or args.program
        else {"length": args.length_unit, "angle": args.angle_unit},
        samples=len(t),
        duration_s=float(t[-1] - t[0]) if len(t) else 0.0,
        convention=convention,
        legs=legs_json,
        set=_set_summary(legs_json),
        limits=limits,
        violation=viol,
    )
    if args.json:
        print_json(out)
    else:
        print(
            f"platform {base.name}, {source}"
            + (f" (read in {args.length_unit} and {args.angle_unit})" if out["read_units"] else "")
            + f": {len(t)} samples over {out['duration_s']:.3f} s, legs model {args.legs}, payload {args.payload} kg"
        )
        _print_table(legs_json, with_times=True)
    if viol is None:
        return 0
    return _report_violation(viol, f"at t = {viol['t_s']:.4f} s", f"at t = {viol['peak_t_s']:.4f} s")


def _set_summary(legs_json) -> dict:
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


def _print_table(legs_json, with_times: bool) -> None:
    print(
        f"{'leg':>3} {'peak|F| N':>10} {'RMS F N':>9} {'|L̇| m/s':>9} {'|L̈| m/s²':>10} {'|P| W':>9} {'L min mm':>9} {'L max mm':>9}"
        + ("   t(peak F) s" if with_times else "")
    )
    for r in legs_json:
        rms = "—" if r["rms_force_n"] is None else f"{r['rms_force_n']:9.3f}"
        print(
            f"{r['leg']:3d} {r['peak_force_n']:10.3f} {rms:>9} {r['peak_speed_m_s']:9.4f} {r['peak_accel_m_s2']:10.4f} {r['peak_power_w']:9.3f} "
            f"{r['min_length_m'] * 1e3:9.2f} {r['max_length_m'] * 1e3:9.2f}"
            + (f"   {r['peak_force_t_s']:.4f}" if with_times else "")
        )


def _report_violation(viol, first_where: str, peak_where: str) -> int:
    """The worst excess (the peak the table shows) and where the limit is first exceeded; exit 1."""
    qty = viol["quantity"]
    name = "stroke" if qty == "length" else f"legs.max_{qty}"
    u = UNITS[qty]
    print(
        f"stewart-drake size: leg {viol['peak_leg']} {qty} peaks at {viol['peak']:.6g} {u}, beyond {name} "
        f"{viol['peak_limit']:.6g} {u} {peak_where}; first exceeded by leg {viol['leg']} ({viol['value']:.6g} {u}) "
        f"{first_where}",
        file=sys.stderr,
    )
    return 1


def _run_envelope(args, platform, header, legs) -> int:
    env = load_envelope(args.envelope)
    # a pose outside the stroke is a result outside limits (exit 1, the table shown), not bad input
    es = envelope_sizing(platform, env, legs=legs, gravity=args.gravity, stroke=False)
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
        source=args.envelope,
        poses=len(env.poses),
        convention=env.convention,
        v_max=env.v_max,
        a_max=env.a_max,
        legs=legs_json,
        set=_set_summary(legs_json),
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
    if args.json:
        print_json(out)
    else:
        print(
            f"platform {platform.name}, envelope {args.envelope}: {len(env.poses)} poses, legs model {args.legs}, payload {args.payload} kg"
        )
        _print_table(legs_json, with_times=False)
        a = allowed["min_over_poses"]
        print(
            "largest acceleration per axis the actuators allow at every pose (others zero, worst velocity): "
            + ", ".join(f"{n} {v:.4g} {u}" for n, v, u in zip(AXES, a, allowed["units"]))
        )
    if viol is None:
        return 0
    note = " (power over an envelope is an upper bound: peak |F| x peak |L̇|)" if viol["quantity"] == "power" else ""
    return _report_violation(
        viol, f"at envelope {env.shown(viol['index'])}", f"at envelope {env.shown(viol['peak_index'])}{note}"
    )
