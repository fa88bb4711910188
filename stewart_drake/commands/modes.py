"""``stewart-drake modes``: natural frequencies and mode shapes about the static equilibrium at a pose
(legs as springs and dampers), analytic, optionally checked against Drake's linearisation."""

from __future__ import annotations

import sys

import numpy as np

from stewart_drake.commands._common import print_json
from stewart_drake.commands.stiffness import NAMES, add_pose_args, prepare, require_analysable_pose
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.design.load_limits import (
    MAX_DAMPING_RATIO,
    damping_ratio_scale,
    rigid_body_limit_hz,
    unstable_direction,
)
from stewart_drake.errors import (
    OPTION_LEG_DAMPING,
    OPTION_LEG_DAMPING_RESOLVE,
    OPTION_SAMPLE_RATE,
    GeometryError,
    OptionError,
)


def register(sub) -> None:
    p = sub.add_parser(
        "modes", help="natural frequencies (Hz) and mode shapes at a pose; --drake checks them against Drake"
    )
    add_pose_args(p)
    p.add_argument(
        "--leg-damping", type=float, default=0.0, metavar="N·s/m", help="axial damping of every leg (default 0)"
    )
    p.add_argument(
        "--drake",
        action="store_true",
        help="also linearise the Drake plant (legs off: springs + Linearize; on: closed-loop plant)",
    )
    p.add_argument(
        "--sample-rate",
        type=float,
        default=1000.0,
        metavar="HZ",
        help="controller sample rate to compare with (default 1000, the DSP's)",
    )
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=run)


def run(args) -> int:
    # Deferred: these pull in scipy (~0.2 s) and cli.py imports every command module at start-up.
    from stewart_drake.design.modes import analytic_modes, damping_matrix, spatial_inertia, subspace_mac
    from stewart_drake.design.stiffness import stiffness_matrix

    platform, q, k, _ = prepare(args)
    if not (np.isfinite(args.leg_damping) and args.leg_damping >= 0):
        raise OptionError(OPTION_LEG_DAMPING.format(value=args.leg_damping))
    if not (np.isfinite(args.sample_rate) and args.sample_rate > 0):
        raise OptionError(OPTION_SAMPLE_RATE.format(value=args.sample_rate))
    require_analysable_pose(platform, q, args.convention)
    legs = args.legs == "on"
    K = stiffness_matrix(platform, q, k, args.convention, args.gravity, legs)
    M = spatial_inertia(platform, q, args.convention, legs)
    C = damping_matrix(platform, q, args.leg_damping, args.convention) if args.leg_damping > 0 else None
    if not np.linalg.eigvalsh(0.5 * (M + M.T))[0] > 0:  # a zero or singular inertia: LAPACK's "not positive definite"
        raise GeometryError(GeometryError.INERTIA_SINGULAR.format(name=platform.name, mass=platform.mass))
    zeta = damping_ratio_scale(K, M, C)
    if zeta > MAX_DAMPING_RATIO:
        raise OptionError(OPTION_LEG_DAMPING_RESOLVE.format(value=args.leg_damping, zeta=zeta, limit=MAX_DAMPING_RATIO))
    m = analytic_modes(K, M, C)
    f1 = float(m.frequencies_hz[0])
    T = 1.0 / args.sample_rate
    delay = 1.5 * T  # one sample of output delay + half a sample of zero-order hold
    out = {
        "platform": platform.name,
        "pose": args.pose,
        "legs_model": legs,
        "leg_stiffness_n_per_m": k,
        "leg_damping_ns_per_m": args.leg_damping,
        "frequencies_hz": m.frequencies_hz,
        "damping_ratio": m.damping_ratio,
        "mode_shapes": m.shapes.T.real if C is None else None,
        "controller": {
            "sample_rate_hz": args.sample_rate,
            "samples_per_lowest_period": args.sample_rate / f1 if f1 > 0 else None,
            "loop_delay_s": delay,
            "phase_lag_at_lowest_deg": 360.0 * f1 * delay,
        },
    }
    if args.drake:
        # Deferred: only this check needs Drake; cli.py imports every command module at start-up.
        from stewart_drake.drake.design_checks import drake_modes

        d = drake_modes(platform, q, k, args.leg_damping, args.convention, args.gravity, legs)
        md = d["modes"]
        out["drake"] = {
            "frequencies_hz": md.frequencies_hz,
            "damping_ratio": md.damping_ratio,
            "relative_difference": np.abs(md.frequencies_hz / m.frequencies_hz - 1),
            "mac": subspace_mac(m.shapes, md.shapes, m.frequencies_hz),
            "equilibrium_residual": d["residual"],
            "method": "closed-loop plant, reduced by finite differences" if legs else "spring plant, Drake Linearize",
        }
    v = unstable_direction(K)
    limits = (
        []
        if v is None
        else [
            "the loaded platform is unstable at this pose: its stiffness K is not positive definite, it falls away along "
            f"[{' '.join(f'{x:+.3f}' for x in v)}] (x y z m, rx ry rz rad); a mode of 0 Hz is that fall, not a frequency"
        ]
    )
    # beyond the legs' own axial resonance the rigid-plate model does not hold: a warning (the model's range,
    # not the platform's limit); a 1e-30 kg plate printed 1e18 Hz as if it were a result
    f_rigid = rigid_body_limit_hz(leg_lengths(platform, q, args.convention))
    warnings = []
    if m.frequencies_hz[-1] > f_rigid:
        warnings.append(
            f"mode 6 at {m.frequencies_hz[-1]:.4g} Hz is above the legs' own axial resonance (~{f_rigid:.4g} Hz, c/2L "
            f"for steel legs): the rigid-plate, massless-leg model does not hold there; check plate.mass "
            f"({platform.mass:g} kg), plate.inertia and the leg stiffness"
        )
    for w in warnings:
        print(f"stewart-drake modes: warning: {w}", file=sys.stderr)
    out["warnings"] = warnings
    out["limits"] = limits
    if args.json:
        print_json(out)
        return _report(limits)
    print(
        f"platform {platform.name}, pose {args.pose}; legs {'with' if legs else 'without'} mass, k = {k[0]:.6g} N/m, c = {args.leg_damping} N·s/m"
    )
    print(
        f"{'mode':>4} {'f (Hz)':>11} {'ζ':>8}  shape ["
        + " ".join(NAMES)
        + "] (largest component = 1)"
        + ("   Drake f (Hz)   MAC" if args.drake else "")
    )
    for i in range(6):
        s = m.shapes[:, i].real
        s = s / s[np.argmax(np.abs(s))]
        line = (
            f"{i + 1:4d} {m.frequencies_hz[i]:11.5f} {m.damping_ratio[i]:8.4f}  ["
            + " ".join(f"{v:+.3f}" for v in s)
            + "]"
        )
        if args.drake:
            line += f"   {out['drake']['frequencies_hz'][i]:12.6f}  {out['drake']['mac'][i]:.6f}"
        print(line)
    c = out["controller"]
    if c["samples_per_lowest_period"] is None:  # f1 = 0: nothing oscillates to be sampled
        print(f"lowest mode {f1:.4g} Hz: it does not oscillate (neutral or unstable at this leg stiffness)")
    else:
        print(
            f"lowest mode {f1:.4g} Hz: {c['samples_per_lowest_period']:.4g} controller samples per period at {args.sample_rate:g} Hz; "
            f"a {delay * 1e3:.3g} ms loop delay lags it by {c['phase_lag_at_lowest_deg']:.3g}°"
        )
    return _report(limits)


def _report(limits: list[str]) -> int:
    """Each limit on stderr; exit 1 if there is one (the modes above are still shown)."""
    for m in limits:
        print(f"stewart-drake modes: {m}", file=sys.stderr)
    return 1 if limits else 0
