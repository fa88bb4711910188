"""Drawings of a platform (``plot_platform``): the figure a person looks for first — which joint is which and
how the legs pair them."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from stewart_drake.core.geometry import Platform
from stewart_drake.core.sanity import check_poses
from stewart_drake.design.drawings import platform_figure
from stewart_drake.errors import SHAPE, ShapeError

if TYPE_CHECKING:  # annotations only: matplotlib is loaded when the figure is drawn
    from matplotlib.figure import Figure


def plot_platform(platform: Platform, pose: ArrayLike | None = None) -> Figure:
    """A top view and a side view of ``platform`` with its joints numbered by leg, each leg in its own colour and
    the base frame's axes.

    Args:
        platform: the platform.
        pose: ``(6,)`` pose, m and rad (default home).

    Returns:
        A matplotlib ``Figure``.

    Raises:
        StewartError: a pose that is not six finite numbers, or far outside the platform (a unit mistake);
            ``PhysicalLimitError`` when it puts the plate below the base.
    """
    if pose is not None:
        arr = check_poses(platform, _six(pose))
        pose = arr[0]
    return platform_figure(platform, pose)


def _six(pose: ArrayLike):
    arr = np.asarray(pose)
    if arr.shape != (6,) or not np.issubdtype(arr.dtype, np.number) or np.iscomplexobj(arr):
        raise ShapeError(
            SHAPE.format(name="pose", shape="(6,) real numbers", got=arr.shape if arr.ndim else repr(pose))
        )
    return arr.astype(float)
