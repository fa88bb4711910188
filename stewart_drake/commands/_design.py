"""Arguments shared by the design commands (size, stiffness, modes): legs, payload, gravity."""

from __future__ import annotations

import numpy as np

from stewart_drake.core.rotations import length_scale
from stewart_drake.design.payload import with_payload
from stewart_drake.errors import OptionError, PayloadError


def add_payload_args(parser, length_help: str) -> None:
    """``--legs``, ``--payload`` (kg), ``--payload-com`` (plate frame, unit per ``length_help``) and
    ``--gravity`` (m/s²)."""
    parser.add_argument(
        "--legs",
        choices=["on", "off"],
        default="off",
        help="include the legs' masses (cylinder + piston) (default off)",
    )
    parser.add_argument(
        "--payload", type=float, default=0.0, metavar="KG", help="a point mass carried by the plate (default 0)"
    )
    parser.add_argument(
        "--payload-com",
        nargs=3,
        type=float,
        default=[0.0, 0.0, 0.0],
        metavar=("X", "Y", "Z"),
        help=f"the payload's centre of mass in the plate frame T, {length_help} (default the T origin)",
    )
    parser.add_argument("--gravity", type=float, default=9.81, help="m/s² (default 9.81)")


def platform_with_payload(platform, args, length_unit: str):
    """The platform carrying ``--payload`` at ``--payload-com`` (in ``length_unit``); checks ``--gravity``."""
    if not (np.isfinite(args.gravity) and args.gravity >= 0):
        raise OptionError(OptionError.GRAVITY.format(option="--gravity", value=args.gravity))
    if args.payload_com[2] < 0:
        raise PayloadError(PayloadError.BELOW_PLATE.format(z=args.payload_com[2], unit=length_unit))
    p_TP = np.asarray(args.payload_com, dtype=float) * length_scale(length_unit)
    return with_payload(platform, args.payload, p_TP), p_TP
