"""A radial platform of our own (not a preset: irregular joint angles, an offset rotation centre), shared by the
real-time FK tests and the firmware FK tests, which check the same kinematics on it."""

from pathlib import Path

from stewart_drake.core.geometry import Platform, load_platform

OWN_RADIAL = """
name: own-radial
length_unit: mm
radial:
  base_radius: 500.0
  base_angles_deg: [280.0, 20.0, 40.0, 140.0, 160.0, 260.0]
  top_radius: 300.0
  top_angles_deg: [310.0, 350.0, 70.0, 110.0, 190.0, 230.0]
stroke: [450.0, 850.0]
rotation_centre: [10.0, -20.0, 30.0]
"""


def own_radial(folder: Path) -> Platform:
    """``OWN_RADIAL`` written to ``folder/own.yaml`` and loaded as a user's file is."""
    path = folder / "own.yaml"
    path.write_text(OWN_RADIAL)
    return load_platform(str(path))
