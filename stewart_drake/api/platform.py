"""Loading a platform: a built-in preset by name, or a platform YAML file."""

from __future__ import annotations

from pathlib import Path

from stewart_drake.core import geometry
from stewart_drake.core.geometry import Platform


def load_platform(name_or_path: str | Path | Platform) -> Platform:
    """A platform from a preset name (see `presets`) or a platform YAML file, validated.

    Args:
        name_or_path: a preset name such as ``"utn-dynamic"``, a path to a YAML platform file, or a
            ``Platform`` (returned as it is).

    Returns:
        The platform, in SI units (metres, kilograms).

    Raises:
        StewartError: an unknown name, or a file that is not a valid platform (the message names the file,
            line and field).
    """
    return geometry.load_platform(name_or_path)


def presets() -> list[str]:
    """The names of the built-in platform presets.

    Returns:
        The preset names, each accepted by `load_platform`.
    """
    return list(geometry.PRESETS)
