"""Arguments shared by the design commands (size, stiffness, modes): legs, payload, gravity."""

from __future__ import annotations

from stewart_drake.commands._common import platform_machine
from stewart_drake.core.geometry import Platform, load_platform
from stewart_drake.core.rotations import length_scale


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
        "--payload",
        type=float,
        default=None,
        metavar="KG",
        help="a point mass carried by the plate (default: a machine file's payload, else 0)",
    )
    parser.add_argument(
        "--payload-com",
        nargs=3,
        type=float,
        default=None,
        metavar=("X", "Y", "Z"),
        help=f"the payload's centre of mass in the plate frame T, {length_help} (default: a machine file's payload "
        "position, else the T origin)",
    )
    parser.add_argument("--gravity", type=float, default=9.81, help="m/s² (default 9.81)")


def design_platform(args) -> Platform:
    """The platform of ``--platform`` as written, with ``args.payload`` (kg) and ``args.payload_com`` (in
    ``--length-unit``) filled where they were left out: a machine file's ``payload``, else none."""
    machine = platform_machine(args)
    mass, com = (0.0, (0.0, 0.0, 0.0)) if machine is None else (machine.payload.mass, machine.payload.position)
    if args.payload is None:
        args.payload = float(mass)
    if args.payload_com is None:
        k = length_scale(args.length_unit)
        args.payload_com = [float(c) / k for c in com]
    return load_platform(args.platform) if machine is None else machine.platform
