"""A platform of the engine tests' own: irregular radial joints, an offset rotation centre, a plate whose centre of
mass is off every axis and whose inertia has products (each a place where a frame convention would show)."""

from pathlib import Path

from stewart_drake.core.geometry import load_platform
from tests._own_platform import OWN_RADIAL

OWN = OWN_RADIAL.replace("name: own-radial", "name: engines-own") + (
    "plate: {mass: 7.5, com: [12.0, -8.0, 25.0], inertia: [0.21, 0.17, 0.33, 0.012, -0.008, 0.005]}\n"
    "legs: {cylinder_mass: 0.9, piston_mass: 0.4, cylinder_radius: 20.0, max_force: 2000.0}\n"
)


def own_platform(folder: Path):
    """``OWN`` written to ``folder/engines-own.yaml`` and loaded as a user's file is."""
    path = folder / "engines-own.yaml"
    path.write_text(OWN)
    return load_platform(str(path))
