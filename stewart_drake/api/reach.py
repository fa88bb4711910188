"""``workspace``: the constant-orientation workspace (extents, volume with bounds, boundary), the rotation
limits from home and the mobility of a platform."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from stewart_drake.api.result import Result
from stewart_drake.core.argcheck import as_flag, as_int, as_real, check_shape, param
from stewart_drake.core.geometry import Platform, check_platform
from stewart_drake.core.leg_bodies import leg_dimensions
from stewart_drake.core.rotations import check_convention
from stewart_drake.core.sanity import check_centre, check_finite
from stewart_drake.errors import ArgumentError, OptionError
from stewart_drake.system.processes import check_workers
from stewart_drake.workspace import (
    AXES,
    Limits,
    Workspace,
    constant_orientation_workspace,
    orientation_limits,
    stewart_mobility,
)

LIMIT_CHOICES = ("stroke", "joints", "collision", "dexterity")


@dataclass(repr=False)
class WorkspaceResult(Result):
    """A platform's workspace (``workspace``).

    Attributes:
        summary: extents (``x_range``, ... m), volume (m³) with its bounds, the limits' effects, rotation
            limits (deg and per limit), rotation centre and mobility (the dict ``stewart-drake workspace --json``
            prints).
        grid: the computed grid (``boundary`` (n, 3) m, ``volume``, ``volume_bounds``, ...).
        rotation_limits: the rotation limits from home, one per axis and sign (``angle`` rad, what binds).
    """

    summary: dict
    grid: Workspace
    rotation_limits: list

    @property
    def volume(self) -> float:
        """The workspace volume, m³."""
        return float(self.grid.volume)

    def _fields(self) -> dict:
        return self.summary


def parse_limits(limits, platform: Platform, joint_cone: float, leg_diameter: float | None, max_condition: float):
    """A ``workspace.Limits`` from a comma-separated list or a sequence of limit names (``LIMIT_CHOICES``)."""
    if isinstance(limits, str):
        names = [n.strip() for n in limits.split(",") if n.strip()]
    elif isinstance(limits, (list, tuple)):
        names = list(limits)
    else:
        raise ArgumentError(
            ArgumentError.NOT_TEXT.format(name=param("limits"), what="limit names", value=repr(limits)[:80])
        )
    unknown = [n for n in names if not isinstance(n, str) or n not in LIMIT_CHOICES]
    if unknown:
        raise OptionError(
            OptionError.UNKNOWN_LIMIT.format(option=param("limits"), value=unknown[0], valid=", ".join(LIMIT_CHOICES))
        )
    joint_cone = as_real(joint_cone, param("joint_cone"))
    max_condition = as_real(max_condition, param("max_condition"))
    leg_diameter = None if leg_diameter is None else as_real(leg_diameter, param("leg_diameter"))
    kw = {}
    if "joints" in names:
        kw["base_cone"] = kw["top_cone"] = joint_cone
    if "collision" in names:
        if leg_diameter is None:
            leg_diameter = 2 * leg_dimensions(platform)["cylinder_radius"]
        kw["leg_diameter"] = leg_diameter
    if "dexterity" in names:
        kw["max_condition"] = max_condition
    return Limits(**kw)


def workspace(
    platform: Platform,
    orientation: ArrayLike = (0.0, 0.0, 0.0),
    resolution: float = 0.01,
    limits: str | Sequence[str] = "stroke",
    *,
    convention: str = "utn",
    joint_cone: float = math.radians(45.0),
    leg_diameter: float | None = None,
    max_condition: float = 100.0,
    centre: ArrayLike | None = None,
    workers: int = 1,
    progress: bool = False,
) -> WorkspaceResult:
    """The constant-orientation workspace, the rotation limits from home and the mobility of a platform.

    Args:
        platform: the platform.
        orientation: ``(3,)`` the plate's fixed orientation, rad.
        resolution: grid step, m.
        limits: the limits that bound it: ``"stroke"``, ``"joints"``, ``"collision"``, ``"dexterity"`` (a
            comma-separated string or a list).
        convention: Euler convention of ``orientation``.
        joint_cone: the joints' cone half-angle, rad (``"joints"``).
        leg_diameter: legs' diameter, m (``"collision"``; default the model's cylinder).
        max_condition: the largest condition number allowed (``"dexterity"``).
        centre: ``(3,)`` the rotation centre for the rotation limits, m in the plate frame (default the
            platform's).
        workers: worker processes for the sweep.
        progress: show a progress bar.

    Returns:
        The summary, the grid and the rotation limits.

    Raises:
        StewartError: bad options (a resolution too fine for memory, an unknown limit, ...).
    """
    return solve_workspace(
        platform, orientation, resolution, limits, convention, joint_cone, leg_diameter, max_condition, centre,
        workers, progress, orientation_shown=None,
    )  # fmt: skip


def solve_workspace(
    platform, orientation, resolution, limits, convention, joint_cone, leg_diameter, max_condition, centre, workers,
    progress, orientation_shown,
) -> WorkspaceResult:  # fmt: skip
    """``workspace`` with the orientation as the user wrote it (``orientation_shown``) for its finiteness check."""
    check_platform(platform)
    check_convention(convention)
    resolution = as_real(resolution, param("resolution"))
    if not (resolution > 0 and math.isfinite(resolution)):
        raise OptionError(OptionError.POSITIVE.format(option=param("resolution"), unit="metres", value=resolution))
    if centre is not None:
        centre = check_centre(platform, centre)
    orientation = check_shape(orientation, param("orientation"), (3,))
    check_finite(orientation if orientation_shown is None else orientation_shown, param("orientation"))
    workers = as_int(workers, param("workers"))
    check_workers(param("workers"), workers)  # the one rule for worker counts (system.processes)
    progress = as_flag(progress, param("progress"))
    lim = parse_limits(limits, platform, joint_cone, leg_diameter, max_condition)
    w = constant_orientation_workspace(
        platform, orientation, resolution, lim, convention, workers=workers, progress=progress
    )
    rot = orientation_limits(platform, centre=centre, limits=lim)
    result = {"platform": platform.name, "orientation_deg": np.degrees(orientation).tolist(), "convention": convention}
    result.update(w.summary())
    result["rotation_limits_deg"] = {
        a: {("+" if r.sign > 0 else "-"): math.degrees(r.angle) for r in rot if r.axis == a} for a in AXES
    }
    result["rotation_limits"] = [r.as_dict() for r in rot]
    result["rotation_centre_m"] = list(platform.rotation_centre if centre is None else centre)
    result["mobility"] = stewart_mobility("SPS")["m"]
    return WorkspaceResult(result, w, rot)
