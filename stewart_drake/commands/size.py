"""``stewart-drake size``: actuator sizing for a motion program, a trajectory or a duty envelope."""

from __future__ import annotations

import sys

import numpy as np

from stewart_drake.api.design import carrying
from stewart_drake.api.sizing import AXES, size_loaded, sized_actuators
from stewart_drake.commands._common import add_platform_arg, platform_machine, print_json
from stewart_drake.commands._design import add_payload_args, design_platform
from stewart_drake.core.rotations import CONVENTIONS, length_scale
from stewart_drake.script import ScriptError


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


def run(args) -> int:
    base = design_platform(args)
    machine = platform_machine(args)
    actuators = None if machine is None else sized_actuators(machine)
    k = length_scale(args.length_unit)
    platform, p_TP = carrying(
        base,
        args.payload,
        np.asarray(args.payload_com, dtype=float) * k,
        args.gravity,
        shown_com=args.payload_com,
        unit=args.length_unit,
    )
    try:
        r = size_loaded(
            base, platform, p_TP, args.trajectory, args.program, args.envelope, args.legs == "on", args.payload,
            args.gravity, args.rate, args.t_end, args.dt, args.convention, args.length_unit, args.angle_unit,
            smooth=args.smooth, actuators=actuators,
        )  # fmt: skip
    except ScriptError as e:
        print(e.render(), file=sys.stderr)
        return 2
    out = r.to_dict()
    if args.json:
        print_json(out)
    elif args.envelope is not None:
        print(
            f"platform {platform.name}, envelope {args.envelope}: {out['poses']} poses, legs model {args.legs}, payload {args.payload} kg"
        )
        _print_table(out["legs"], with_times=False)
        a, units = out["allowed_acceleration"]["min_over_poses"], out["allowed_acceleration"]["units"]
        print(
            "largest acceleration per axis the actuators allow at every pose (others zero, worst velocity): "
            + ", ".join(f"{n} {v:.4g} {u}" for n, v, u in zip(AXES, a, units))
        )
    else:
        print(
            f"platform {base.name}, {out['source']}"
            + (f" (read in {args.length_unit} and {args.angle_unit})" if out["read_units"] else "")
            + f": {out['samples']} samples over {out['duration_s']:.3f} s, legs model {args.legs}, payload {args.payload} kg"
        )
        _print_table(out["legs"], with_times=True)
    if not args.json and "motor" in out:
        _print_motor_table(out["motor"])
    elif not args.json and "hydraulic" in out:
        _print_hydraulic_table(out["hydraulic"])
    elif not args.json and actuators is not None:
        print(f"{machine.actuators.model} actuators: sized along a trajectory or program (not over an envelope)")
    if not r.ok:
        print(f"stewart-drake size: {r.violation_message()}", file=sys.stderr)
        return 1
    return 0


def _print_motor_table(motor: dict) -> None:
    lim, sc = motor["limits"], motor["screw"]
    print(
        f"screw actuators: lead {sc['lead_m'] * 1e3:g} mm, rotor {sc['reflected_mass_kg']:.4g} kg on each leg; motor "
        f"limits {lim['max_current']:.4g} A peak, {lim['rated_current']:.4g} A RMS, "
        f"{lim['max_motor_speed'] * 60 / (2 * np.pi):.5g} rpm"
    )
    print(f"{'leg':>3} {'peak|i| A':>10} {'RMS i A':>9} {'peak|τ| N·m':>12} {'peak rpm':>9}")
    for r in motor["legs"]:
        rpm = r["peak_speed_rad_s"] * 60 / (2 * np.pi)
        print(
            f"{r['leg']:3d} {r['peak_current_a']:10.4g} {r['rms_current_a']:9.4g} {r['peak_torque_nm']:12.4g} {rpm:9.5g}"
        )


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


def _print_hydraulic_table(hyd: dict) -> None:
    lim = hyd["limits"]
    print(
        f"hydraulic cylinders: supply {lim['supply_pressure'] / 1e5:.4g} bar, forces {lim['max_extending_force_n']:.5g} N "
        f"extending, {-lim['max_retracting_force_n']:.5g} N retracting; peak total supply flow "
        f"{hyd['total_supply_flow_m3_s'] * 6e4:.4g} L/min"
    )
    print(f"{'leg':>3} {'spool':>7} {'p_A bar':>8} {'p_B bar':>8} {'Q L/min':>8}")
    for r in hyd["legs"]:
        print(
            f"{r['leg']:3d} {r['peak_spool']:7.3g} {r['peak_p_A_pa'] / 1e5:8.4g} {r['peak_p_B_pa'] / 1e5:8.4g} "
            f"{r['peak_supply_flow_m3_s'] * 6e4:8.4g}"
        )
