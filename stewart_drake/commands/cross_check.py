"""``stewart-drake cross-check``: the platform's kinematics and inverse dynamics in Pinocchio and MuJoCo against
the closed forms."""

from __future__ import annotations

import stewart_drake as sd
from stewart_drake.commands._common import add_platform_arg, platform_from_args, print_json
from stewart_drake.engines.cross_check import ENGINES, RELEASE_DURATION


def register(sub) -> None:
    p = sub.add_parser(
        "cross-check", help="the platform's kinematics and leg forces in Pinocchio and MuJoCo against the closed forms"
    )
    add_platform_arg(p)
    p.add_argument(
        "--engine",
        action="append",
        choices=ENGINES,
        help="an engine to check with (repeatable; default: every installed one)",
    )
    p.add_argument("--poses", type=int, default=1000, help="seeded poses for the kinematics (default 1000)")
    p.add_argument("--samples", type=int, default=13, help="samples of each trajectory for the dynamics (default 13)")
    p.add_argument("--seed", type=int, default=0, help="the poses' seed (default 0)")
    p.add_argument(
        "--no-simulation",
        action="store_true",
        help="skip the forward simulations (open loop, passive release, the float-law loop against Drake's)",
    )
    p.add_argument("--json", action="store_true", help="JSON output (SI units)")
    p.set_defaults(func=run)


def run(args) -> int:
    platform = platform_from_args(args)
    r = sd.cross_check(
        platform,
        engines=args.engine,
        poses=args.poses,
        samples=args.samples,
        seed=args.seed,
        simulate=not args.no_simulation,
    )
    if args.json:
        print_json(r.to_dict())
    else:
        print(f"platform {r.platform}: closed forms against {', '.join(r.engines)}")
        for name, e in r.engines.items():
            if not e["available"]:
                print(f"  {name}: skipped ({e['reason']})")
                continue
            k = e["kinematics"]
            print(
                f"  {name} {e['version']}: kinematics at {k['poses']} poses: closure residual {k['closure_residual_m']:.2e} m,"
                f" leg length error {k['leg_length_error_m']:.2e} m (tolerance {k['tolerance_m']:.1e} m)"
                f" {'ok' if k['ok'] else 'DISAGREES'}"
            )
            for t, d in e["dynamics"].items():
                print(
                    f"    leg forces, {t} ({d['samples']} samples, max {d['max_force_n']:.4g} N): error {d['max_error_n']:.2e} N"
                    f" = {d['relative_error']:.1e} relative (tolerance {d['tolerance_relative']:.1e}, κ = {d['condition']:.3g})"
                    f" {'ok' if d['ok'] else 'DISAGREES'}"
                )
            m = e["modes"]
            print(
                f"    mass matrix in task space at {m['poses']} poses: {m['mass_matrix_relative_error']:.1e} relative,"
                f" natural frequencies {m['frequency_relative_error']:.1e} relative (tolerance"
                f" {m['tolerance_relative']:.1e}) {'ok' if m['ok'] else 'DISAGREES'}; at home "
                + ", ".join(f"{f:.4g}" for f in m["frequencies_hz"])
                + " Hz"
            )
            _print_simulation(e)
        print("verdict: " + ("every engine agrees" if r.ok else "an engine disagrees with the closed forms"))
    return 0 if r.ok else 1


def _print_simulation(e: dict) -> None:
    ol, rel = e.get("open_loop"), e.get("passive_release")
    if ol is None:
        return
    if "bound_m" in ol:
        print(
            f"    open loop (closed-form forces, 0.5 s): plate error {ol['position_error_m'] * 1e3:.3g} mm"
            f" (bound {ol['bound_m'] * 1e3:.2g} mm), closure gap {ol['constraint_m'] * 1e3:.2g} mm"
            f" {'ok' if ol['ok'] else 'DISAGREES'}"
        )
    else:
        per = ", ".join(
            f"{tau * 1e3:g} ms: {g * 1e3:.3g} mm / {p * 1e3:.3g} mm"
            for tau, g, p in zip(ol["solref_s"], ol["constraint_m"], ol["position_error_m"])
        )
        print(
            f"    open loop (closed-form forces, 0.5 s), solref time constant: closure stretch / plate error {per}"
            f" {'shrinks' if ol['ok'] else 'DOES NOT SHRINK'}"
        )
    print(
        f"    passive release from home ({RELEASE_DURATION:g} s): energy drift {rel['energy_drift_j']:.2e} J of"
        f" {rel['energy_exchanged_j']:.3g} J exchanged, closure gap {rel['constraint_m'] * 1e3:.2g} mm"
    )
    loop = e.get("drake_loop")
    if loop is None:
        return
    if loop["ok"] is None:
        print(f"    float-law loop against Drake's: not run ({loop['reason']})")
        return
    f = loop["fine"]
    print(
        f"    float-law loop against Drake's ({loop['duration_s']:g} s of the seed): plate {loop['position_m'] * 1e3:.3g} mm,"
        f" legs {loop['length_m'] * 1e3:.3g} mm apart with the {loop['sensor_resolution_m'] * 1e6:g} µm sensor; with a"
        f" fine one {f['position_m'][0] * 1e3:.3g} mm at {f['plant_step_s'][0] * 1e3:g} ms, × {loop['step_ratio']:.3f}"
        f" at half the step (bound {loop['bound_m'] * 1e3:.2g} mm) {'ok' if loop['ok'] else 'DISAGREES'}"
    )
