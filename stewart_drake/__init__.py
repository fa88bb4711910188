"""stewart-drake: model and verify Stewart platforms and their fixed-point controllers with Drake.

The maths core (geometry, rotations, kinematics, ...) is plain numpy and imports no Drake; the
modules that build Drake models and systems import pydrake when they are imported.
"""

__version__ = "0.1.0"
