"""``stewart-drake dsp-ik``: the six integer leg lengths the seed's DSP56800E firmware (tp17.C)
computes for a pose, bit-exactly, with the float IK beside them."""

from __future__ import annotations

import sys

import numpy as np

from stewart_drake.commands._common import print_json
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.rotations import angle_scale
from stewart_drake.core.sanity import above_base, below_base_message, plate_anchor_heights
from stewart_drake.errors import DspPoseError
from stewart_drake.firmware.engine import ENGINES, resolve_engine
from stewart_drake.firmware.host import tp17_leg_lengths_c
from stewart_drake.fixedpoint.q15 import SaturationCounter
from stewart_drake.fixedpoint.tp17 import TP17_GEOMETRY_MM, check_dsp_poses, tp17_error_stages, tp17_trace

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
    raw = np.asarray(args.pose, dtype=float)
    q = raw.copy()
    with np.errstate(over="ignore"):  # 1e308 deg is inf pi: refused just below as beyond ±180°
        q[3:] = raw[3:] * angle_scale(args.angle_unit) / np.pi  # -> fractions of pi
    for k, name in enumerate(("A", "B", "G")):
        if abs(q[3 + k]) > 1.0:
            raise DspPoseError(DspPoseError.ANGLE_OPTION.format(name=name, value=raw[3 + k], unit=args.angle_unit))
    check_dsp_poses(q)
    # the firmware's platform is utn-kinematic's (a = 612 vs 612.5 mm). An emulator shows what the firmware
    # computes: a pose whose plate dips below the base is computed, shown and flagged (exit 1), as ik does
    # for a pose outside the stroke
    # Any pose of the DSP's range (16-bit mm, one turn: ``check_dsp_poses``) is computed.
    kin = load_preset("utn-kinematic")
    pose_si = np.r_[np.trunc(q[:3]) * 1e-3, q[3:] * np.pi]
    flags = [] if above_base(kin, pose_si) else [below_base_message("--pose", plate_anchor_heights(kin, pose_si))]
    with SaturationCounter() as sat:
        tr = tp17_trace(q)
    if sat.total:
        flags.append(
            f"the firmware's arithmetic saturated ({dict(sat.counts)}); its lengths for this pose are clipped, not geometric"
        )
    res = tp17_error_stages(q)
    engine = resolve_engine(args.engine, "stewart-drake dsp-ik")
    dsp = tp17_leg_lengths_c(q) if engine == "c" else tr.lengths.astype(int)
    flt = res["float"]
    out = {
        "pose": {
            "px_mm": int(np.trunc(q[0])),
            "py_mm": int(np.trunc(q[1])),
            "pz_mm": int(np.trunc(q[2])),
            "alpha_pi": float(q[3]),
            "beta_pi": float(q[4]),
            "gamma_pi": float(q[5]),
            "angle_words": tr.angle_words.tolist(),
        },
        "geometry_mm": {"firmware": dict(TP17_GEOMETRY_MM), "float": {"a": 612.5, "b": 925, "d": 150}},
        "engine": engine,
        "dsp_lengths_mm": dsp.tolist(),
        "float_lengths_mm": [round(float(v), 4) for v in flt],
        "difference_mm": [round(float(v), 4) for v in dsp - flt],
        "saturations": dict(sat.counts),
        "flags": flags,
    }
    if args.trace:
        out["trace"] = {
            "sin_q15": tr.sin.tolist(),
            "cos_q15": tr.cos.tolist(),
            "R_q15": tr.R.tolist(),
            "plate_joints_T_mm": tr.top_T.tolist(),
            "plate_joints_B_mm": tr.top_B.tolist(),
            "leg_vectors_mm": tr.leg.tolist(),
            "L32": tr.L32.tolist(),
        }
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
