"""Arguments shared by the design commands (size, stiffness, modes): legs, payload, gravity."""

from __future__ import annotations


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
