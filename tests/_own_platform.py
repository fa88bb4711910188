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


# The platform part of the 210 kg machine as its user wrote it (examples/newcomer-210kg.yaml adds the
# payload, the controller and the number format).
NEWCOMER_PLATFORM = """\
name: newcomer-6dof-sim
length_unit: mm
radial:
  base_radius: 650.0
  base_angles_deg: [278.0, 22.0, 38.0, 142.0, 158.0, 262.0]
  top_radius: 450.0
  top_angles_deg: [318.0, 342.0, 78.0, 102.0, 198.0, 222.0]
stroke: [550.0, 850.0]
rotation_centre: [0.0, 0.0, 0.0]
plate: {mass: 60.0, com: [0.0, 0.0, 50.0], inertia: [3750000.0, 3750000.0, 7500000.0, 0, 0, 0]}
legs: {cylinder_mass: 4.0, piston_mass: 2.0, max_force: 4000.0, max_speed: 500.0, stiffness: 20000.0}
"""
