"""``stewart-drake servo``: arm angles and PWM pulse widths of the RC-servo hexapod (seed 002)."""

from __future__ import annotations

import argparse

import numpy as np

from stewart_drake.api.servo import US, solve_servo
from stewart_drake.commands._common import print_json
from stewart_drake.core.rotations import ANGLE_UNITS, LENGTH_UNITS, angle_scale, length_scale
from stewart_drake.errors import OPTION_SERVO_POSE, ServoPoseError
from stewart_drake.mechanisms.servo import SERVO_PRESETS


def register(sub) -> None:
    p = sub.add_parser("servo", help="servo arm angles and pulse widths for a pose (RC-servo hexapod, seed 002)")
    p.add_argument(
        "--platform",
        default="hobby-servo",
        metavar="NAME|FILE",
        help=f"a servo hexapod preset ({', '.join(SERVO_PRESETS)}) or a servo hexapod YAML file (default hobby-servo)",
    )
    p.add_argument("--preset", dest="platform", help=argparse.SUPPRESS)  # the option's earlier name
    p.add_argument(
        "--pose",
        nargs=6,
        type=float,
        metavar=("X", "Y", "Z", "PHI", "THETA", "PSI"),
        help="platform pose, R = Rz(psi)·Ry(theta)·Rx(phi) (default: home)",
    )
    p.add_argument("--from-home", action="store_true", help="Z is the offset from the home height h0")
    p.add_argument(
        "--trim", nargs=6, type=float, metavar="W0", help="per-servo neutral pulses W0_i in µs (default 1500)"
    )
    p.add_argument("--length-unit", choices=list(LENGTH_UNITS), default="mm", help="default mm")
    p.add_argument("--angle-unit", choices=list(ANGLE_UNITS), default="deg", help="default deg")
    p.add_argument("--write-sdf", metavar="DIR", help="also write DIR/servo-hexapod.sdf")
    p.add_argument("--json", action="store_true", help="JSON output")
    p.set_defaults(func=run)


def run(args) -> int:
    k, ka = length_scale(args.length_unit), angle_scale(args.angle_unit)
    scale = np.r_[[k] * 3, [ka] * 3]
    if args.pose is not None and not np.all(np.isfinite(args.pose)):
        raise ServoPoseError(OPTION_SERVO_POSE.format(value=list(args.pose)))
    res = solve_servo(
        args.platform,
        None if args.pose is None else np.asarray(args.pose, dtype=float) * scale,
        from_home=args.from_home,
        trim_us=args.trim,
        write_sdf=args.write_sdf,
        what="--pose",
    )
    if res.sdf_file is not None and not args.json:
        print(res.sdf_file)
    if args.pose is not None:
        raw = list(args.pose)
    else:
        raw = (np.zeros(6) if args.from_home else res.pose / scale).tolist()
    violations = []
    for v in res.violations:
        d = {key: (float(np.degrees(x)) if key in ("angle", "limit", "excess") else x) for key, x in v.items()}
        violations.append({(f"{key}_deg" if key in ("angle", "limit", "excess") else key): x for key, x in d.items()})
    result = {
        "preset": res.platform,
        "pose": raw,
        "units": {"length": args.length_unit, "angle": args.angle_unit, "convention": "zyx"},
        "home_height": res.home_height / k,
        "alpha0_deg": np.degrees(res.home_angles).tolist(),
        "angles_deg": np.degrees(res.angles).tolist(),
        "pulse_us": (res.pulse / US).tolist(),
        "pulse_raw_us": (res.pulse_raw / US).tolist(),
        "ok": res.ok,
        "violations": violations,
    }
    if res.sdf_file is not None:
        result["sdf_file"] = str(res.sdf_file)
    if args.json:
        print_json(result)
    else:
        print(
            f"{res.platform}: h0 = {result['home_height']:.3f} {args.length_unit}, alpha0 = {result['alpha0_deg'][0]:.3f} deg"
        )
        print("servo   angle (deg)   pulse (us)")
        for i in range(6):
            print(f"{i + 1:5d}   {result['angles_deg'][i]:11.3f}   {result['pulse_us'][i]:10.1f}")
        for v in result["violations"]:
            if v["kind"] == "unreachable":
                print(f"servo {v['servo']}: unreachable (|L/sqrt(M^2+N^2)| = {abs(v['ratio']):.4f} > 1)")
            else:
                print(
                    f"servo {v['servo']}: travel limit, {v['angle_deg']:.3f} deg from home, {v['excess_deg']:.3f} deg beyond ±{abs(v['limit_deg']):.0f}"
                )
    return 0 if res.ok else 1
