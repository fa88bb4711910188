"""Loading a platform: a built-in preset by name, or a platform YAML file."""

from __future__ import annotations

from pathlib import Path

from stewart_drake.core import geometry
from stewart_drake.core.geometry import Platform
from stewart_drake.spec import Machine, load_machine
from stewart_drake.spec.load import is_machine_file


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


def nominal_geometry(source: str | Path | Platform | Machine) -> Platform:
    """The platform whose geometry the calibration functions plan, measure and identify: a preset, a platform
    file or a ``Platform`` as `load_platform` reads it; a ``Machine`` or a machine file, its platform without the
    payload (a calibrated platform file must not carry the payload into the plate, where the machine adds it
    again)."""
    if isinstance(source, Machine):
        return source.platform
    if is_machine_file(source):
        return load_machine(source).platform
    return load_platform(source)


def presets() -> list[str]:
    """The names of the built-in platform presets.

    Returns:
        The preset names, each accepted by `load_platform`.
    """
    return list(geometry.PRESETS)
