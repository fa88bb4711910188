"""An independent volume for the stroke limits alone: exact z-intervals of every (x, y) column,
integrated on an (x, y) grid; a cross-check of the grid sweep's volume.
"""

from __future__ import annotations

import numpy as np

from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_vectors
from stewart_drake.core.sanity import plate_floor
from stewart_drake.workspace.grid import default_bounds
from stewart_drake.workspace.limits import check_orientation


def stroke_column_lengths(
    platform: Platform, x, y, orientation=(0.0, 0.0, 0.0), convention: str = "utn", z_bounds=(0.0, np.inf)
) -> np.ndarray:
    """``(...)`` length (m) of the set of z in ``z_bounds`` with every leg within stroke, for columns at
    ``x``, ``y`` (broadcast, metres). Per leg, L_min² <= ρ² + (z - c_z)² <= L_max² is one or two
    z-intervals; their intersection is measured exactly between sorted interval end points."""
    l0 = leg_vectors(platform, np.r_[0.0, 0.0, 0.0, check_orientation(orientation)], convention)
    x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
    rho2 = (x[..., None] + l0[:, 0]) ** 2 + (y[..., None] + l0[:, 1]) ** 2  # (..., 6)
    reach = np.all(rho2 <= platform.L_max**2, axis=-1)
    out = np.zeros(x.shape)
    # a column some leg cannot reach has length exactly 0 (no z passes that leg): only the others are measured
    out[reach] = _column_lengths(platform, rho2[reach], l0, z_bounds)
    return out


def _column_lengths(platform: Platform, rho2, l0, z_bounds) -> np.ndarray:
    """``(m,)`` the column lengths of ``stroke_column_lengths`` from each column's squared horizontal leg
    distances ``rho2`` (m, 6) (m²)."""
    a = np.sqrt(np.maximum(platform.L_min**2 - rho2, 0.0))
    b = np.sqrt(np.maximum(platform.L_max**2 - rho2, 0.0))
    cz = -l0[:, 2]
    z0, z1 = z_bounds
    ends = np.concatenate(
        [cz - b, cz - a, cz + a, cz + b, np.broadcast_to([z0, min(z1, 1e9)], rho2.shape[:-1] + (2,))], -1
    )
    ends = np.sort(np.clip(ends, z0, min(z1, 1e9)), axis=-1)
    mid = 0.5 * (ends[..., 1:] + ends[..., :-1])  # (..., 25)
    # every leg reaches the piece around mid: |mid - c_z| within [a, b], one leg at a time over (..., 25) arrays
    # (the same comparisons as over one (..., 25, 6) array, at half the cost)
    ok = np.ones(mid.shape, bool)
    dz, t = np.empty(mid.shape), np.empty(mid.shape, bool)
    for i in range(len(cz)):
        np.abs(np.subtract(mid, cz[i], out=dz), out=dz)
        ok &= np.greater_equal(dz, a[..., i, None], out=t)
        ok &= np.less_equal(dz, b[..., i, None], out=t)
    return np.sum(np.where(ok, ends[..., 1:] - ends[..., :-1], 0.0), axis=-1)


def stroke_volume_columns(
    platform: Platform,
    resolution: float,
    orientation=(0.0, 0.0, 0.0),
    convention: str = "utn",
    z_floor: float | None = None,
) -> float:
    """Volume (m³) of the stroke workspace above ``z_floor`` (default ``sanity.plate_floor``: every plate
    anchor above the base): exact column lengths integrated by the midpoint rule on an (x, y) grid of
    step ``resolution`` (error O(h^1.5) from the rim)."""
    if z_floor is None:
        z_floor = plate_floor(platform, check_orientation(orientation), convention)
    b = default_bounds(platform, orientation, convention, z_floor)
    h = float(resolution)
    xs = np.arange(b[0, 0] + h / 2, b[0, 1], h)
    ys = np.arange(b[1, 0] + h / 2, b[1, 1], h)
    total = 0.0
    for i in range(0, len(xs), max(1, 20000 // len(ys))):
        X, Y = np.meshgrid(xs[i : i + max(1, 20000 // len(ys))], ys, indexing="ij")
        total += stroke_column_lengths(platform, X, Y, orientation, convention, (z_floor, np.inf)).sum()
    return float(total * h * h)
