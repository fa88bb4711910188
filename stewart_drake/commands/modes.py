"""``stewart-drake modes``: natural frequencies and mode shapes about the static equilibrium at a pose
(legs as springs and dampers), analytic, optionally checked against Drake's linearisation."""

from __future__ import annotations

import sys

import numpy as np

from stewart_drake.api.design import check_modes_options, modes_at, require_analysable
from stewart_drake.commands._common import print_json
from stewart_drake.commands.stiffness import NAMES, add_pose_args, load


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
    ld = load(args, check_pose=False)
    check_modes_options(args.leg_damping, args.sample_rate)
    require_analysable(ld)
    r = modes_at(ld, args.leg_damping, args.sample_rate, args.drake)
    out = r.to_dict() | {"pose": args.pose}
    if r.drake is not None:  # after the controller's numbers, as before
        out["drake"] = out.pop("drake")
    m, k, legs, f1 = r, r.leg_stiffness, r.legs, float(r.frequencies_hz[0])
    delay = r.controller["loop_delay_s"]
    for w in r.warnings:
        print(f"stewart-drake modes: warning: {w}", file=sys.stderr)
    if args.json:
        print_json(out)
        return _report(r.limits)
    print(
        f"platform {r.platform}, pose {args.pose}; legs {'with' if legs else 'without'} mass, k = {k[0]:.6g} N/m, c = {args.leg_damping} N·s/m"
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
    return _report(r.limits)


def _report(limits: list[str]) -> int:
    """Each limit on stderr; exit 1 if there is one (the modes above are still shown)."""
    for m in limits:
        print(f"stewart-drake modes: {m}", file=sys.stderr)
    return 1 if limits else 0
