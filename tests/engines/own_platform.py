"""A platform of the engine tests' own: irregular radial joints, an offset rotation centre, a plate whose centre of
mass is off every axis and whose inertia has products (each a place where a frame convention would show)."""

from pathlib import Path

from stewart_drake.core.geometry import load_platform

OWN = """
name: engines-own
length_unit: mm
radial:
  base_radius: 500.0
  base_angles_deg: [280.0, 20.0, 40.0, 140.0, 160.0, 260.0]
  top_radius: 300.0
  top_angles_deg: [310.0, 350.0, 70.0, 110.0, 190.0, 230.0]
stroke: [450.0, 850.0]
rotation_centre: [10.0, -20.0, 30.0]
plate: {mass: 7.5, com: [12.0, -8.0, 25.0], inertia: [0.21, 0.17, 0.33, 0.012, -0.008, 0.005]}
legs: {cylinder_mass: 0.9, piston_mass: 0.4, cylinder_radius: 20.0, max_force: 2000.0}
"""


def own_platform(folder: Path):
    """``OWN`` written to ``folder/engines-own.yaml`` and loaded as a user's file is."""
    path = folder / "engines-own.yaml"
    path.write_text(OWN)
    return load_platform(str(path))
