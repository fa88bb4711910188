"""``stewart-drake dsp-ik``: the six integer leg lengths the seed's DSP56800E firmware (tp17.C)
computes for a pose, bit-exactly, with the float IK beside them."""

from __future__ import annotations

import sys

from stewart_drake.api.dsp import FLOAT_GEOMETRY_MM, dsp_ik_firmware, firmware_pose
from stewart_drake.commands._common import print_json
from stewart_drake.firmware.engine import ENGINES
from stewart_drake.fixedpoint.tp17 import TP17_GEOMETRY_MM

ANGLE_UNITS = ("pi", "deg", "rad")


def register(sub) -> None:
    p = sub.add_parser(
        "dsp-ik", help="leg lengths as the DSP56800E firmware computes them (integer mm), with the float IK"
    )
    p.add_argument(
        "--pose",
        nargs=6,
        type=float,
        required=True,
        metavar=("PX", "PY", "PZ", "A", "B", "G"),
        help="position in mm (truncated to whole mm, as the firmware stores it) and the angles alpha, beta, gamma",
    )
    p.add_argument(
        "--angle-unit",
        choices=ANGLE_UNITS,
        default="pi",
        help="unit of A B G: 'pi' = a fraction of pi as the firmware takes them (0.1 = 18°, the default), 'deg', 'rad'",
    )
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")
    p.add_argument(
        "--trace",
        action="store_true",
        help="also print the firmware's intermediate words (sin/cos, matrix, plate joints)",
    )
    p.add_argument(
        "--engine",
        choices=ENGINES,
        default="python",
        help="python: the numpy emulation (default); c: tp17.C compiled for the host against the C intrinsics",
    )
    p.set_defaults(func=run)


def run(args) -> int:
    q = firmware_pose(args.pose, args.angle_unit, what="--pose")
    res = dsp_ik_firmware(q, engine=args.engine, trace=args.trace)
    dsp, flt, flags = res.dsp_words, res.float_lengths * 1e3, res.flags
    fp = res.firmware_pose
    out = {
        "pose": {
            "px_mm": int(fp[0]),
            "py_mm": int(fp[1]),
            "pz_mm": int(fp[2]),
            "alpha_pi": float(fp[3]),
            "beta_pi": float(fp[4]),
            "gamma_pi": float(fp[5]),
            "angle_words": res.angle_words,
        },
        "geometry_mm": {"firmware": dict(TP17_GEOMETRY_MM), "float": dict(FLOAT_GEOMETRY_MM)},
        "engine": res.engine,
        "dsp_lengths_mm": dsp.tolist(),
        "float_lengths_mm": [round(float(v), 4) for v in flt],
        "difference_mm": [round(float(v), 4) for v in dsp - flt],
        "saturations": res.saturations,
        "flags": flags,
    }
    if res.trace is not None:
        out["trace"] = res.trace
    if args.json:
        print_json(out)
        return _flagged(flags)
    p = out["pose"]
    print(
        f"pose: px={p['px_mm']} py={p['py_mm']} pz={p['pz_mm']} mm; alpha={p['alpha_pi']:g}π beta={p['beta_pi']:g}π "
        f"gamma={p['gamma_pi']:g}π (FRAC16 words {p['angle_words']})"
    )
    print("firmware geometry a=612 b=925 d=150 mm (float IK: a=612.5)")
    print(f"{'leg':>4} {'DSP mm':>8} {'float mm':>10} {'DSP-float':>10}")
    for i in range(6):
        print(f"{i + 1:>4} {dsp[i]:>8d} {flt[i]:>10.3f} {dsp[i] - flt[i]:>+10.3f}")
    if args.trace:
        for k, v in out["trace"].items():
            print(f"{k}: {v}")
    return _flagged(flags)


def _flagged(flags: list[str]) -> int:
    """Each flag on stderr; exit 1 when there is one (a result outside limits, still shown), else 0."""
    for f in flags:
        print(f"stewart-drake dsp-ik: {f}", file=sys.stderr)
    return 1 if flags else 0
