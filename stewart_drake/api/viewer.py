"""What the viewer shows for a pose, without a viewer: ``viewer_readout`` gives ``stewart-drake view``'s readout
(leg lengths, stroke margins, condition number, nearest reachable pose, assembly modes) as a result.

Imports pydrake (through ``drake.viewer``): ``import stewart_drake`` loads this module on first use of
``viewer_readout``."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from stewart_drake.api.kinematics import solve_ik
from stewart_drake.api.platform import load_platform
from stewart_drake.api.result import Result
from stewart_drake.core.argcheck import as_flag, check_shape
from stewart_drake.core.geometry import Platform
from stewart_drake.drake.viewer import Readout, readout

__all__ = ["viewer_readout", "ViewerReadout"]


@dataclass(repr=False)
class ViewerReadout(Result):
    """The viewer's readout of one pose (``viewer_readout``). ``to_dict()`` is ``stewart-drake view --json``'s
    (already SI).

    Attributes:
        pose: ``(6,)`` the pose (m, rad).
        lengths: ``(6,)`` leg lengths, m.
        margin: ``(6,)`` stroke margin of each leg (negative: beyond the stroke), m.
        condition: condition number of the scaled inverse Jacobian.
        sigma_min: its smallest singular value.
        reachable: every leg within its stroke and the pose non-singular.
        nearest: ``(6,)`` the last reachable pose on the straight line from home (the pose when reachable).
        fraction: how far along that line ``nearest`` lies (1 when reachable).
        modes: assembly modes found for these lengths (None when not counted).
        modes_near: of those, the ones near the pose (None when not counted).
        uniqueness_radius: no other assembly mode lies this close to the pose, m (a certified bound).
    """

    pose: np.ndarray
    lengths: np.ndarray
    margin: np.ndarray
    condition: float
    sigma_min: float
    reachable: bool
    nearest: np.ndarray
    fraction: float
    modes: int | None
    modes_near: int | None
    uniqueness_radius: float

    @property
    def ok(self) -> bool:
        """The pose is reachable (within the stroke, not singular)."""
        return self.reachable

    @classmethod
    def from_readout(cls, r: Readout) -> ViewerReadout:
        """The result of a viewer's ``Readout`` (what ``stewart-drake view --json`` prints)."""
        return cls(
            r.pose,
            r.lengths,
            r.margin,
            r.condition,
            r.sigma_min,
            r.reachable,
            r.nearest,
            r.fraction,
            r.modes,
            r.modes_near,
            r.uniqueness_radius,
        )

    def _fields(self) -> dict:
        return {
            "pose": self.pose,
            "lengths_m": self.lengths,
            "stroke_margin_m": self.margin,
            "condition": self.condition,
            "sigma_min": self.sigma_min,
            "reachable": self.reachable,
            "nearest_reachable_pose": self.nearest,
            "fraction_from_home": self.fraction,
            "assembly_modes": self.modes,
            "assembly_modes_near": self.modes_near,
            "uniqueness_radius_m": self.uniqueness_radius,
        }


def viewer_readout(
    platform: Platform | str | Path,
    pose: ArrayLike | None = None,
    *,
    convention: str = "utn",
    modes: bool = True,
) -> ViewerReadout:
    """The readout ``stewart-drake view`` shows for a pose, computed without opening a viewer.

    Args:
        platform: a ``Platform``, a preset name or a platform YAML file.
        pose: ``(6,)`` ``[px, py, pz, a, b, g]`` in metres and radians; None: home.
        convention: Euler convention of the angles (``"utn"`` or ``"zyx"``).
        modes: also count the assembly modes (a seeded multi-start search, ~0.1–0.5 s); False: ``--no-modes``.

    Returns:
        Leg lengths, stroke margins, conditioning, the nearest reachable pose and the assembly modes.

    Raises:
        StewartError: an unknown platform, a pose of the wrong shape, not finite or far outside the platform.
    """
    platform = load_platform(platform)
    q = platform.home_pose() if pose is None else check_shape(pose, "pose", (6,))
    modes = as_flag(modes, "modes")
    solve_ik(platform, q, convention)  # the pose checks of ik: shape, finite, within reach of the platform
    return ViewerReadout.from_readout(readout(platform, q, convention, modes))
