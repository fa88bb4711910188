"""The constant-orientation workspace: positions reachable at one orientation on a grid swept in
x-slabs of bounded size (optionally on an executor), with the volume and its error bound, refined
extents, boundary points and the three views (``Workspace``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from stewart_drake.core.argcheck import param
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_vectors
from stewart_drake.core.rotations import check_convention
from stewart_drake.core.sanity import human_bytes, memory_budget, plate_floor
from stewart_drake.workspace.executors import run_tasks
from stewart_drake.workspace.extents import extents_from_views, refine_extents
from stewart_drake.workspace.limits import Limits, WorkspaceError, check_orientation

if TYPE_CHECKING:  # an annotation only: concurrent.futures is imported by the sweep that uses an executor
    from concurrent.futures import Executor
from stewart_drake.workspace.slabs import grid_spec, slab_task

# Largest grid the sweep accepts (nodes): ~10 min of the stroke kernel at ~5e7 nodes/s on one core.
MAX_GRID_NODES = 3e10
# Bytes per node of the three views and the boundary points (which scale with the grid's faces, not its
# volume) and per node of the two x-planes a slab holds at least; see ``grid_memory``.
BYTES_PER_FACE_NODE = 40
BYTES_PER_PLANE_NODE = 120


def _node_counts(bounds, h) -> tuple:
    """Nodes per axis ``grid_axes`` would make, computed without allocating them."""
    return tuple(math.ceil(hi / h) - math.floor(lo / h) + 3 for lo, hi in bounds)


def grid_memory(bounds, h) -> tuple[float, float]:
    """``(nodes, bytes)`` a sweep at step ``h`` over ``bounds`` would need (views, boundary points, the
    smallest slab), estimated before anything is allocated."""
    nx, ny, nz = (float(n) for n in _node_counts(bounds, h))
    faces = nx * ny + ny * nz + nx * nz
    return nx * ny * nz, BYTES_PER_FACE_NODE * faces + BYTES_PER_PLANE_NODE * ny * nz + 24 * (nx + ny + nz)


def check_grid_size(bounds, h) -> None:
    """``WorkspaceError`` naming the resolution, the node count, the memory and the finest resolution
    this machine can hold when the grid is too large (memory budget or ``MAX_GRID_NODES``)."""
    nodes, need = grid_memory(bounds, h)
    budget = memory_budget()
    if need <= budget and nodes <= MAX_GRID_NODES:
        return
    # memory scales as 1/h² (faces), time as 1/h³ (nodes): the finest step that fits both
    h_min = max(h * math.sqrt(need / budget), h * (nodes / MAX_GRID_NODES) ** (1 / 3))
    why = human_bytes(need) if need > budget else WorkspaceError.GRID_NODES.format(limit=MAX_GRID_NODES)
    raise WorkspaceError(
        WorkspaceError.GRID_TOO_LARGE.format(
            h=h, nodes=nodes, why=why, h_min_mm=h_min * 1e3, option=param("resolution")
        )
    )


@dataclass
class Workspace:
    """A constant-orientation workspace (metres).

    orientation (3,) rad; resolution h (m); axes: node coordinates along x, y, z;
    extents (3, 2) [min, max] per axis: feasible extreme points (refined) or grid-node values;
    extent_error (m): how much farther out any true extreme can lie, from the grid bracket; volume, volume_error (m³; the true volume lies in [volume_bounds]) assuming the grid
    resolves the boundary (no feature thinner than one cell); volume_change_2h: |V(h) - V(2h)| from
    every other node, a convergence indicator (much smaller than the bound on smooth workspaces);
    top (nx, ny), front (nx, nz), side (ny, nz) bool: the views (projections along z, y, x);
    boundary (m, 3) float32 points: inside nodes with an outside neighbour;
    removed_m3: volume the stroke-feasible set loses to each optional limit (binding where > 0);
    touches_bounds: inside nodes on the grid's outer faces (the box clipped the workspace).
    """

    orientation: np.ndarray
    limits: Limits
    resolution: float
    axes: tuple
    extents: np.ndarray
    extent_error: float
    volume: float
    volume_error: float
    volume_bounds: tuple
    volume_change_2h: float
    inside_nodes: int
    top: np.ndarray
    front: np.ndarray
    side: np.ndarray
    boundary: np.ndarray
    removed_m3: dict = field(default_factory=dict)
    touches_bounds: bool = False

    @property
    def binding(self) -> list[str]:
        """Optional limits that remove part of the stroke workspace (stroke itself always binds)."""
        return [n for n, v in self.removed_m3.items() if v > 0]

    def summary(self) -> dict:
        """A JSON-ready dict (metres, m³)."""
        return {
            "orientation_rad": self.orientation.tolist(),
            "resolution_m": self.resolution,
            "limits": list(self.limits.active),
            "x_range": self.extents[0].tolist(),
            "y_range": self.extents[1].tolist(),
            "z_range": self.extents[2].tolist(),
            "extent_error_m": self.extent_error,
            "volume_m3": self.volume,
            "volume_error_m3": self.volume_error,
            "volume_bounds_m3": list(self.volume_bounds),
            "volume_change_2h_m3": self.volume_change_2h,
            "removed_by_limit_m3": dict(self.removed_m3),
            "binding_limits": self.binding,
            "touches_bounds": self.touches_bounds,
        }


def default_bounds(
    platform: Platform, orientation=(0.0, 0.0, 0.0), convention: str = "utn", z_floor: float | None = None
) -> np.ndarray:
    """``(3, 2)`` a box that holds the whole stroke workspace: the intersection of the six balls'
    bounding boxes (|p + l_i(0)| <= L_max), cut below at ``z_floor`` (default ``sanity.plate_floor``:
    every plate anchor above the base plane, which excludes the mirror-image workspace under the base)."""
    o = check_orientation(orientation)
    l0 = leg_vectors(platform, np.r_[0.0, 0.0, 0.0, o], convention)
    lo = np.max(-l0 - platform.L_max, axis=0)
    hi = np.min(-l0 + platform.L_max, axis=0)
    lo[2] = max(lo[2], plate_floor(platform, o, convention) if z_floor is None else z_floor)
    if np.any(hi <= lo):
        raise WorkspaceError(WorkspaceError.EMPTY_STROKE.format(orientation=np.asarray(orientation).tolist()))
    return np.stack([lo, hi], -1)


def grid_axes(bounds, h) -> tuple:
    """Three 1-D arrays of node coordinates (m), multiples of the step ``h`` covering ``(3, 2)`` bounds
    with one node beyond each side (outside the workspace by construction)."""
    axes = []
    for lo, hi in bounds:
        k0, k1 = math.floor(lo / h) - 1, math.ceil(hi / h) + 1  # one node beyond each side: outside
        axes.append(np.arange(k0, k1 + 1) * h)
    return tuple(axes)


def constant_orientation_workspace(
    platform: Platform,
    orientation=(0.0, 0.0, 0.0),
    resolution: float = 0.01,
    limits: Limits = Limits(),
    convention: str = "utn",
    bounds=None,
    refine: bool = True,
    chunk_nodes: int = 1 << 21,
    workers: int = 1,
    executor: Executor | None = None,
    progress: bool = False,
) -> Workspace:
    """The positions p (of the pose's rotation centre) reachable at ``orientation`` (3,) rad.

    Grid nodes at multiples of ``resolution`` h (m) over ``bounds`` ((3, 2) m, default
    ``default_bounds``), swept in x-slabs of about ``chunk_nodes`` nodes (memory ~ 10 bytes per
    node of a slab, plus the views and the boundary points). Volume: node count × h³; its bound
    comes from the cells with mixed corners. Extents are refined (``refine``) by a constrained
    optimisation from the extreme nodes. ``workers`` > 1 runs slabs on a process pool; ``executor`` takes any
    ``concurrent.futures.Executor`` (e.g. a Dask client's, see ``workspace_dask``).
    """
    check_convention(convention)
    h = float(resolution)
    if not (np.isfinite(h) and h > 0):
        raise WorkspaceError(WorkspaceError.RESOLUTION.format(value=resolution))
    b = default_bounds(platform, orientation, convention) if bounds is None else np.asarray(bounds, dtype=float)
    if b.shape != (3, 2) or not np.all(b[:, 1] > b[:, 0]):
        raise WorkspaceError(WorkspaceError.BOUNDS.format(value=np.asarray(bounds).tolist()))
    check_grid_size(b, h)
    axes = grid_axes(b, h)
    spec = grid_spec(platform, orientation, convention, limits, axes)
    nx, ny, nz = (len(a) for a in axes)
    per = max(2, int(chunk_nodes) // (ny * nz))  # a slab re-evaluates one plane each side: keep >= 2
    tasks = [(spec, i, min(i + per, nx)) for i in range(0, nx, per)]
    top, front, side = np.zeros((nx, ny), bool), np.zeros((nx, nz), bool), np.zeros((ny, nz), bool)
    inside = full = mixed = inside_2h = 0
    removed: dict = {n: 0 for n in limits.active if n != "stroke"}
    edge = False
    boundaries = []
    for r in run_tasks(slab_task, tasks, executor, workers, progress, "workspace slabs"):
        i0 = r["i0"]
        k = len(r["top"])
        top[i0 : i0 + k], front[i0 : i0 + k] = r["top"], r["front"]
        side |= r["side"]
        inside, full, mixed = inside + r["inside"], full + r["full"], mixed + r["mixed"]
        inside_2h += r["inside_2h"]
        for n, v in r["removed"].items():
            removed[n] += v
        edge |= r["edge"]
        boundaries.append(r["boundary"])
    bnd_idx = np.concatenate(boundaries)
    if inside == 0:
        raise WorkspaceError(
            WorkspaceError.NOTHING_REACHABLE.format(
                orientation=spec.orientation.tolist(), limits=list(limits.active), h=h
            )
        )
    boundary = np.stack([axes[k][bnd_idx[:, k]] for k in range(3)], -1).astype(np.float32)
    h3 = h**3
    vol = inside * h3
    v_lo, v_hi = full * h3, (full + mixed) * h3
    extents, ext_err = extents_from_views(axes, top, front, side, h)
    if refine:
        extents, ext_err = refine_extents(spec, extents, top, front, side, h)
    return Workspace(
        orientation=spec.orientation,
        limits=limits,
        resolution=h,
        axes=axes,
        extents=extents,
        extent_error=ext_err,
        volume=vol,
        volume_error=max(vol - v_lo, v_hi - vol),
        volume_bounds=(v_lo, v_hi),
        volume_change_2h=abs(vol - inside_2h * 8 * h3),
        inside_nodes=inside,
        top=top,
        front=front,
        side=side,
        boundary=boundary,
        removed_m3={n: v * h3 for n, v in removed.items()},
        touches_bounds=edge,
    )
