"""Workspace of a Stewart platform: which poses every limit allows (seed 001), in plain numpy
(no Drake), metres and radians. Modules: ``limits`` (limits and per-pose margins, ``classify``), ``grid``
(the constant-orientation workspace, swept in x-slabs by ``slabs``, extents refined by ``extents``, tasks
run by ``executors``), ``columns`` (exact stroke volume), ``orientation`` (rotation limits), ``maps``
(dexterity map, 6-D reachable count), ``mobility`` (Grübler) and ``views`` (figures); every public name
is re-exported here.
"""

from stewart_drake.workspace.columns import stroke_column_lengths, stroke_volume_columns
from stewart_drake.workspace.executors import default_workers
from stewart_drake.workspace.grid import MAX_GRID_NODES, Workspace, constant_orientation_workspace, default_bounds
from stewart_drake.workspace.limits import (
    AXES,
    LIMIT_NAMES,
    LIMIT_UNITS,
    Limits,
    WorkspaceError,
    classify,
    leg_pairs,
    limit_margins,
    raw_margins,
    segment_distances,
)
from stewart_drake.workspace.maps import count_reachable, dexterity_map
from stewart_drake.workspace.mobility import STEWART_JOINTS, gruebler_mobility, stewart_mobility
from stewart_drake.workspace.orientation import RotationLimit, orientation_limits
from stewart_drake.workspace.views import view_figures

__all__ = [
    "AXES",
    "LIMIT_NAMES",
    "LIMIT_UNITS",
    "MAX_GRID_NODES",
    "STEWART_JOINTS",
    "Limits",
    "RotationLimit",
    "Workspace",
    "WorkspaceError",
    "classify",
    "constant_orientation_workspace",
    "count_reachable",
    "default_bounds",
    "default_workers",
    "dexterity_map",
    "gruebler_mobility",
    "leg_pairs",
    "limit_margins",
    "orientation_limits",
    "raw_margins",
    "segment_distances",
    "stewart_mobility",
    "stroke_column_lengths",
    "stroke_volume_columns",
    "view_figures",
]
