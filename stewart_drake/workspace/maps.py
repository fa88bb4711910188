"""Limits sampled beyond one orientation's grid: the Jacobian condition number on a plane of positions
(``dexterity_map``) and a chunked count of reachable poses on a 6-D grid (``count_reachable``).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import condition_number
from stewart_drake.workspace.executors import run_tasks
from stewart_drake.workspace.grid import default_bounds
from stewart_drake.workspace.limits import Limits, WorkspaceError, check_orientation, classify

if TYPE_CHECKING:  # an annotation only: concurrent.futures is imported by the sweep that uses an executor
    from concurrent.futures import Executor


def dexterity_map(
    platform: Platform,
    orientation=(0.0, 0.0, 0.0),
    plane: str = "xy",
    at: float | None = None,
    resolution: float = 0.01,
    limits: Limits = Limits(),
    convention: str = "utn",
    extent: float | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Jacobian condition number on a plane of positions: ``plane`` 'xy', 'xz' or 'yz' at the third
    coordinate ``at`` (m, default the home pose's). Returns ``(u (n,), v (m,), kappa (n, m))`` with
    NaN outside the workspace of ``limits``. ``extent``: half-width of the square (default from
    ``default_bounds``)."""
    if plane not in ("xy", "xz", "yz"):
        raise WorkspaceError(WorkspaceError.PLANE.format(value=plane))
    o = check_orientation(orientation)
    ku, kv = ("xyz".index(plane[0]), "xyz".index(plane[1]))
    kw = 3 - ku - kv
    fixed = platform.home_pose()[kw] if at is None else float(at)
    b = default_bounds(platform, o, convention)
    if extent is not None:
        b = np.array([[-extent, extent]] * 3) + platform.home_pose()[:3, None]
    u = np.arange(b[ku, 0], b[ku, 1] + resolution / 2, resolution)
    v = np.arange(b[kv, 0], b[kv, 1] + resolution / 2, resolution)
    U, V = np.meshgrid(u, v, indexing="ij")
    q = np.zeros(U.shape + (6,))
    q[..., ku], q[..., kv], q[..., kw], q[..., 3:] = U, V, fixed, o
    ok = classify(platform, q, limits, convention)
    kappa = np.full(U.shape, np.nan)
    kappa[ok] = condition_number(platform, q[ok], convention)
    return u, v, kappa


def _count_task(platform, grids, limits, convention, start, stop) -> tuple:
    shape = tuple(len(g) for g in grids)
    idx = np.unravel_index(np.arange(start, stop), shape)
    q = np.stack([g[i] for g, i in zip(grids, idx)], -1)
    ok = classify(platform, q, limits, convention)
    marg = [np.bincount(i[ok], minlength=n) for i, n in zip(idx, shape)]
    return int(ok.sum()), marg


def count_reachable(
    platform: Platform,
    grids,
    limits: Limits = Limits(),
    convention: str = "utn",
    chunk: int = 1 << 18,
    workers: int = 1,
    executor: Executor | None = None,
    progress: bool = False,
) -> dict:
    """Sweep the Cartesian product of six 1-D ``grids`` (px, py, pz m; a_x, a_y, a_z rad) in chunks
    of ``chunk`` poses (never materialising the product). Returns ``count`` (poses inside),
    ``total``, ``fraction`` and ``marginals`` (per coordinate, the count inside at each grid value)."""
    grids = [np.asarray(g, dtype=float).ravel() for g in grids]
    if len(grids) != 6 or any(len(g) == 0 for g in grids):
        raise WorkspaceError(WorkspaceError.GRIDS.format(n=len(grids)))
    total = math.prod(len(g) for g in grids)
    tasks = [(platform, grids, limits, convention, s, min(s + chunk, total)) for s in range(0, total, chunk)]
    count, marginals = 0, [np.zeros(len(g), np.int64) for g in grids]
    for c, marg in run_tasks(_count_task, tasks, executor, workers, progress, "6-D sweep"):
        count += c
        for k in range(6):
            marginals[k] += marg[k]
    return {"count": count, "total": total, "fraction": count / total, "marginals": marginals}
