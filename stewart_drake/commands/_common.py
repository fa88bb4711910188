"""Argument helpers shared by the subcommands (units, platform, pose, JSON output)."""

from __future__ import annotations

import json
import sys

import numpy as np

from ..geometry import PRESETS, Platform, load_platform
from ..rotations import ANGLE_UNITS, CONVENTIONS, LENGTH_UNITS


def add_platform_arg(parser, default: str | None = "utn-kinematic") -> None:
    parser.add_argument(
        "--platform",
        default=default,
        metavar="NAME|FILE",
        help=f"a preset ({', '.join(PRESETS)}) or a platform YAML file (default: {default})",
    )


def add_unit_args(parser, length_default: str = "mm", angle_default: str = "deg") -> None:
    parser.add_argument("--length-unit", choices=list(LENGTH_UNITS), default=length_default, help=f"default {length_default}")
    parser.add_argument("--angle-unit", choices=list(ANGLE_UNITS), default=angle_default, help=f"default {angle_default} ('pi': a fraction of pi)")
    parser.add_argument("--convention", choices=list(CONVENTIONS), default="utn", help="Euler convention (default utn: Ry·Rx·Rz)")


def platform_from_args(args) -> Platform:
    return load_platform(args.platform)


def print_json(obj) -> None:
    json.dump(obj, sys.stdout, indent=2, default=_jsonable)
    sys.stdout.write("\n")


def _jsonable(x):
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, np.generic):
        return x.item()
    raise TypeError(f"not JSON serialisable: {type(x).__name__}")
