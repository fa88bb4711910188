"""Workspace of a Stewart platform: which poses every limit allows (SPEC §5, seed 001).

Plain numpy, batched over leading dimensions; no Drake. Metres and radians throughout.

Limits (``Limits``), each a signed *margin* per pose (>= 0 inside, the unit of the limit):
- ``stroke``      every leg length in [L_min, L_max] (metres);
- ``base_joint``  the angle between each leg and its base joint's neutral axis <= ``base_cone`` (rad);
- ``top_joint``   the same at the plate joint, neutral axis fixed in the plate (rad);
- ``collision``   legs as cylinders of diameter ``leg_diameter`` along the joint-to-joint segment: the
                  distance between every pair of leg axes >= the diameter (metres);
- ``dexterity``   the Jacobian condition number (``kinematics.condition_number``) <= ``max_condition``.

Main entry points:
- ``classify`` / ``limit_margins``: any ``(..., 6)`` poses.
- ``constant_orientation_workspace``: the positions reachable at one orientation, on a grid swept in
  x-slabs of bounded size (optionally on an executor: processes, or Dask via ``workspace_dask``);
  extents refined by local zooming, volume with an error bound, boundary points, the three views.
- ``stroke_volume_columns``: an independent, semi-analytic volume for the stroke limits alone.
- ``orientation_limits``: the largest rotation about X, Y, Z each way from a position, about the top
  origin or a given centre, with the final leg lengths and the limiting leg.
- ``dexterity_map``: condition number on a plane of positions.
- ``gruebler_mobility`` / ``stewart_mobility``: Grübler's count (seed 001: m = 6).
- ``count_reachable``: a chunked sweep over a 6-D grid of poses.

Translation enters the inverse kinematics additively: l_i(p, R) = p + l_i(0, R). At constant
orientation we take l_i(0, R) from ``kinematics.leg_vectors`` once and add the grid positions; the
tests check this against ``kinematics.leg_lengths`` node by node.
"""

from __future__ import annotations

import dataclasses
import math
import os
import sys
from concurrent.futures import Executor, ProcessPoolExecutor
from dataclasses import dataclass, field

import numpy as np

from .errors import StewartError
from .geometry import Platform
from .kinematics import condition_number, leg_lengths, leg_vectors
from .rotations import check_convention, rotation_matrix

LIMIT_NAMES = ("stroke", "base_joint", "top_joint", "collision", "dexterity")
LIMIT_UNITS = {"stroke": "m", "base_joint": "rad", "top_joint": "rad", "collision": "m", "dexterity": "1"}
AXES = ("x", "y", "z")
# Largest grid the sweep accepts (nodes); beyond this the resolution is surely a unit mistake.
MAX_GRID_NODES = 5e10
_BLOCK = 4096  # poses per block in the collision kernel


class WorkspaceError(StewartError):
    """A workspace request that cannot be answered (bad resolution, start pose outside the limits, ...)."""


# ----------------------------------------------------------------------------------------------
# Limits and per-pose margins.


@dataclass(frozen=True)
class Limits:
    """Which limits bound the workspace. ``None`` switches a limit off.

    stroke        bool           leg lengths within the platform's [L_min, L_max]
    base_cone     float | None   max angle (rad) between a leg and its base joint axis
    top_cone      float | None   max angle (rad) between a leg and its plate joint axis
    base_axes     (6, 3) | None  neutral axis of each base joint in B (default +Z, the base normal)
    top_axes      (6, 3) | None  neutral axis of each plate joint in T (default +Z, the plate normal)
    leg_diameter  float | None   leg cylinder diameter (m) for leg-leg collision
    max_condition float | None   Jacobian condition-number bound (dexterity)
    """

    stroke: bool = True
    base_cone: float | None = None
    top_cone: float | None = None
    base_axes: np.ndarray | None = None
    top_axes: np.ndarray | None = None
    leg_diameter: float | None = None
    max_condition: float | None = None

    def __post_init__(self):
        for name in ("base_cone", "top_cone"):
            v = getattr(self, name)
            if v is not None and not (0 < v <= math.pi):
                raise WorkspaceError(f"Limits.{name} must be an angle in (0, pi] rad, got {v}")
        if self.leg_diameter is not None and not (np.isfinite(self.leg_diameter) and self.leg_diameter > 0):
            raise WorkspaceError(f"Limits.leg_diameter must be a positive length in metres, got {self.leg_diameter}")
        if self.max_condition is not None and not (self.max_condition > 1):
            raise WorkspaceError(f"Limits.max_condition must be > 1, got {self.max_condition}")
        for name in ("base_axes", "top_axes"):
            v = getattr(self, name)
            if v is None:
                continue
            a = np.array(v, dtype=float)
            n = np.linalg.norm(a, axis=-1) if a.shape == (6, 3) else None
            if n is None or not np.all(n > 1e-12):
                raise WorkspaceError(f"Limits.{name} must be six non-zero 3-vectors, shape (6, 3), got {np.shape(v)}")
            object.__setattr__(self, name, a / n[:, None])

    @property
    def active(self) -> tuple[str, ...]:
        """Names of the limits switched on, in ``LIMIT_NAMES`` order."""
        on = {
            "stroke": self.stroke,
            "base_joint": self.base_cone is not None,
            "top_joint": self.top_cone is not None,
            "collision": self.leg_diameter is not None,
            "dexterity": self.max_condition is not None,
        }
        return tuple(n for n in LIMIT_NAMES if on[n])


def segment_distances(P1, Q1, P2, Q2) -> np.ndarray:
    """``(...)`` shortest distance between segments P1Q1 and P2Q2 (``(..., 3)`` each, metres).

    Clamped closest-point parameters (Ericson, *Real-Time Collision Detection* §5.1.9); parallel
    segments take s = 0. Segments must have non-zero length.
    """
    P1, Q1, P2, Q2 = (np.moveaxis(v, -1, 0) for v in np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (P1, Q1, P2, Q2))))
    d1, d2, r = Q1 - P1, Q2 - P2, P1 - P2  # (3, ...) components first: cheaper than einsum on a length-3 axis

    def dot(u, v):
        return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]

    a, e, b, c, f = dot(d1, d1), dot(d2, d2), dot(d1, d2), dot(d1, r), dot(d2, r)
    denom = a * e - b * b
    parallel = denom <= 1e-12 * a * e
    s = np.where(parallel, 0.0, np.clip((b * f - c * e) / np.where(parallel, 1.0, denom), 0.0, 1.0))
    t = (b * s + f) / e
    s = np.where(t < 0, np.clip(-c / a, 0.0, 1.0), np.where(t > 1, np.clip((b - c) / a, 0.0, 1.0), s))
    t = np.clip(t, 0.0, 1.0)
    gap = r + s * d1 - t * d2
    return np.sqrt(dot(gap, gap))


def leg_pairs(platform: Platform) -> np.ndarray:
    """``(k, 2)`` leg index pairs (0-based) that can collide: every pair not sharing a joint."""
    pairs = []
    for i in range(6):
        for j in range(i + 1, 6):
            same_top = platform.leg_top[i] == platform.leg_top[j]
            same_base = np.linalg.norm(platform.base_anchors[i] - platform.base_anchors[j]) < 1e-9
            if not (same_top or same_base):
                pairs.append((i, j))
    return np.array(pairs, dtype=np.intp).reshape(-1, 2)


def raw_margins(platform: Platform, l, R, limits: Limits, poses=None, convention: str = "utn") -> dict:
    """Per-element margins ``{name: (..., k)}`` (>= 0 inside) from leg vectors ``l`` ``(..., 6, 3)`` and
    plate rotations ``R`` ``(..., 3, 3)`` (or one ``(3, 3)``): k = 6 legs (stroke, joints), the rows of
    ``leg_pairs`` (collision), or 1 (dexterity, which needs ``poses``)."""
    out = {}
    L = np.sqrt(np.einsum("...k,...k->...", l, l))
    if limits.stroke:
        out["stroke"] = np.minimum(L - platform.L_min, platform.L_max - L)
    if limits.base_cone is not None or limits.top_cone is not None:
        u = l / L[..., None]
        if limits.base_cone is not None:
            axes = limits.base_axes if limits.base_axes is not None else np.array([0.0, 0.0, 1.0])
            ang = np.arccos(np.clip(np.einsum("...ik,...ik->...i", u, np.broadcast_to(axes, u.shape)), -1, 1))
            out["base_joint"] = limits.base_cone - ang
        if limits.top_cone is not None:
            axes_T = limits.top_axes if limits.top_axes is not None else np.tile([0.0, 0.0, 1.0], (6, 1))
            n = np.einsum("...jk,ik->...ij", R, axes_T)  # (..., 6, 3) plate joint axes in B
            ang = np.arccos(np.clip(np.einsum("...ik,...ik->...i", u, n), -1, 1))
            out["top_joint"] = limits.top_cone - ang
    if limits.leg_diameter is not None:
        pairs = leg_pairs(platform)
        if len(pairs):
            B = platform.base_anchors
            P = (B + l).reshape(-1, 6, 3)  # plate anchors in B
            d = np.empty((len(P), len(pairs)))
            for k in range(0, len(P), _BLOCK):  # blocks that stay in cache: ~6x faster than one pass
                Pk = P[k : k + _BLOCK]
                d[k : k + _BLOCK] = segment_distances(B[pairs[:, 0]], Pk[:, pairs[:, 0]], B[pairs[:, 1]], Pk[:, pairs[:, 1]])
            out["collision"] = d.reshape(L.shape[:-1] + (len(pairs),)) - limits.leg_diameter
        else:
            out["collision"] = np.full(L.shape[:-1] + (1,), np.inf)
    if limits.max_condition is not None:
        if poses is None:
            raise WorkspaceError("the dexterity limit needs the poses themselves")
        out["dexterity"] = (limits.max_condition - condition_number(platform, poses, convention))[..., None]
    return out


def _margins_from_legs(platform: Platform, l, R, limits: Limits, poses=None, convention="utn") -> dict:
    """``{name: (margin (...), index (...))}``: the worst element of each ``raw_margins`` entry; index is
    the worst leg (0-based) or, for collision, the worst row of ``leg_pairs``."""
    return {n: (m.min(axis=-1), m.argmin(axis=-1)) for n, m in raw_margins(platform, l, R, limits, poses, convention).items()}


def limit_margins(platform: Platform, poses, limits: Limits = Limits(), convention: str = "utn") -> dict:
    """Signed margins of ``(..., 6)`` poses to each active limit: ``{name: (margin (...), index (...))}``;
    a pose is inside where every margin is >= 0. Units in ``LIMIT_UNITS``; ``index`` as in
    ``_margins_from_legs`` (worst leg, 0-based, or worst row of ``leg_pairs``)."""
    check_convention(convention)
    q = np.asarray(poses, dtype=float)
    l = leg_vectors(platform, q, convention)
    R = rotation_matrix(q[..., 3:], convention)
    return _margins_from_legs(platform, l, R, limits, q, convention)


def classify(platform: Platform, poses, limits: Limits = Limits(), convention: str = "utn") -> np.ndarray:
    """``(...)`` True where a ``(..., 6)`` pose satisfies every active limit."""
    margins = limit_margins(platform, poses, limits, convention)
    inside = np.ones(np.shape(poses)[:-1], bool)
    for m, _ in margins.values():
        inside &= m >= 0
    return inside


def _check_orientation(orientation) -> np.ndarray:
    o = np.asarray(orientation, dtype=float)
    if o.shape != (3,) or not np.all(np.isfinite(o)):
        raise WorkspaceError(f"orientation must be 3 finite angles (rad) about X, Y, Z, got {np.asarray(orientation).tolist()}")
    return o


# ----------------------------------------------------------------------------------------------
# Constant-orientation workspace on a grid, swept in x-slabs.


@dataclass(frozen=True)
class _GridSpec:
    """Everything a slab worker needs (small and picklable)."""

    platform: Platform
    orientation: np.ndarray
    convention: str
    limits: Limits
    offsets: np.ndarray  # (6, 3) l_i(0, R): leg vectors with the rotation centre at the origin
    R: np.ndarray  # (3, 3)
    axes: tuple  # three 1-D arrays of node coordinates


def _grid_spec(platform, orientation, convention, limits, axes) -> _GridSpec:
    o = _check_orientation(orientation)
    l0 = leg_vectors(platform, np.r_[0.0, 0.0, 0.0, o], convention)
    return _GridSpec(platform, o, convention, limits, l0, rotation_matrix(o, convention), tuple(axes))


def _inside_block(spec: _GridSpec, xs, ys, zs) -> tuple[np.ndarray, dict]:
    """Classify the grid block xs × ys × zs: ``(inside, removed)`` where ``removed``
    counts, per optional limit, the stroke-feasible nodes it rejects in each x-plane ``(nx,)``.
    ``inside`` is bool ``(nx, ny, nz)``."""
    p = spec.platform
    shape = (len(xs), len(ys), len(zs))
    ok = np.ones(shape, bool)
    lo2, hi2 = p.L_min**2, p.L_max**2
    if spec.limits.stroke:
        for i in range(6):
            c = spec.offsets[i]
            d2 = ((xs + c[0]) ** 2)[:, None, None] + ((ys + c[1]) ** 2)[None, :, None] + ((zs + c[2]) ** 2)[None, None, :]
            ok &= (d2 >= lo2) & (d2 <= hi2)
    removed = {}
    others = [n for n in spec.limits.active if n != "stroke"]
    if others:
        idx = np.nonzero(ok)
        pos = np.stack([xs[idx[0]], ys[idx[1]], zs[idx[2]]], -1)
        l = pos[:, None, :] + spec.offsets
        poses = np.concatenate([pos, np.broadcast_to(spec.orientation, pos.shape)], -1)
        margins = _margins_from_legs(p, l, spec.R, dataclasses.replace(spec.limits, stroke=False), poses, spec.convention)
        keep = np.ones(len(pos), bool)
        for name in others:
            bad = margins[name][0] < 0
            removed[name] = np.bincount(idx[0][bad], minlength=shape[0])
            keep &= ~bad
        ok[idx] = keep
    return ok, removed


def _slab_task(spec: _GridSpec, i0: int, i1: int) -> dict:
    """Sweep the owned x-planes i0..i1-1 (and one neighbour plane each side for cells and boundary)."""
    x, y, z = spec.axes
    lo, hi = max(i0 - 1, 0), min(i1 + 1, len(x))
    m, removed_all = _inside_block(spec, x[lo:hi], y, z)
    own = slice(i0 - lo, i1 - lo)
    mo = m[own]
    # cells between owned plane p and p+1
    c_hi = min(i1, len(x) - 1)
    cells = m[i0 - lo : c_hi - lo + 1].astype(np.int8)
    full = mixed = 0
    if len(cells) >= 2:
        s = cells[:-1] + cells[1:]
        s = s[:, :-1] + s[:, 1:]
        s = s[..., :-1] + s[..., 1:]
        full, mixed = int(np.count_nonzero(s == 8)), int(np.count_nonzero((s > 0) & (s < 8)))
    # boundary: inside nodes with an outside (or off-grid) face neighbour
    pad = np.pad(m, 1, constant_values=False)
    nb = pad[:-2, 1:-1, 1:-1] & pad[2:, 1:-1, 1:-1] & pad[1:-1, :-2, 1:-1] & pad[1:-1, 2:, 1:-1] & pad[1:-1, 1:-1, :-2] & pad[1:-1, 1:-1, 2:]
    bnd = np.argwhere(mo & ~nb[own]).astype(np.int32)
    bnd[:, 0] += i0
    return {
        "i0": i0,
        "inside": int(np.count_nonzero(mo)),
        "full": full,
        "mixed": mixed,
        "top": mo.any(axis=2),
        "front": mo.any(axis=1),
        "side": mo.any(axis=0),
        "boundary": bnd,
        "removed": {n: int(v[own].sum()) for n, v in removed_all.items()},
        "edge": bool((i0 == 0 and mo[0].any()) or (i1 == len(x) and mo[-1].any()) or mo[:, [0, -1], :].any() or mo[:, :, [0, -1]].any()),
        "inside_2h": int(np.count_nonzero(mo[(np.arange(i0, i1) % 2) == 0][:, ::2, ::2])),
    }


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


def default_bounds(platform: Platform, orientation=(0.0, 0.0, 0.0), convention: str = "utn", z_floor: float = 0.0) -> np.ndarray:
    """``(3, 2)`` a box that holds the whole stroke workspace: the intersection of the six balls'
    bounding boxes (|p + l_i(0)| <= L_max), cut below at ``z_floor`` (default: the rotation centre
    above the base plane, which excludes the mirror-image workspace under the base)."""
    l0 = leg_vectors(platform, np.r_[0.0, 0.0, 0.0, _check_orientation(orientation)], convention)
    lo = np.max(-l0 - platform.L_max, axis=0)
    hi = np.min(-l0 + platform.L_max, axis=0)
    lo[2] = max(lo[2], z_floor)
    if np.any(hi <= lo):
        raise WorkspaceError(f"the stroke workspace at orientation {np.asarray(orientation).tolist()} rad is empty (no common point of the legs' reach)")
    return np.stack([lo, hi], -1)


def _grid_axes(bounds, h) -> tuple:
    axes = []
    for lo, hi in bounds:
        k0, k1 = math.floor(lo / h) - 1, math.ceil(hi / h) + 1  # one node beyond each side: outside
        axes.append(np.arange(k0, k1 + 1) * h)
    return tuple(axes)


def _run_tasks(fn, tasks, executor, workers, progress, desc):
    """Yield ``fn(*task)`` for every task, in order: in-process, on a process pool of ``workers``, or on a
    given ``concurrent.futures.Executor``. A generator, so that callers merge results as they come
    and memory stays bounded by the slab, not by the number of slabs. Progress with tqdm on stderr."""
    from tqdm import tqdm

    bar = tqdm(total=len(tasks), desc=desc, disable=not progress, file=sys.stderr, leave=False)
    try:
        if executor is None and workers > 1 and len(tasks) > 1:
            import multiprocessing

            with ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn")) as ex:
                yield from _drain(ex, fn, tasks, bar, window=4 * workers)
        elif executor is not None:
            if not isinstance(executor, Executor) and not hasattr(executor, "submit"):
                raise WorkspaceError(f"executor must be a concurrent.futures.Executor (or have submit), got {type(executor).__name__}")
            yield from _drain(executor, fn, tasks, bar, window=None)
        else:
            for t in tasks:
                yield fn(*t)
                bar.update()
    finally:
        bar.close()


def _drain(executor, fn, tasks, bar, window):
    """Submit tasks (at most ``window`` in flight, None: all) and yield results in order."""
    from collections import deque

    pending, it = deque(), iter(tasks)
    for t in it if window is None else (next(it, None) for _ in range(window)):
        if t is not None:
            pending.append(executor.submit(fn, *t))
    while pending:
        res = pending.popleft().result()
        nxt = next(it, None)
        if nxt is not None:
            pending.append(executor.submit(fn, *nxt))
        bar.update()
        yield res


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
        raise WorkspaceError(f"resolution must be a positive number of metres, got {resolution}")
    b = default_bounds(platform, orientation, convention) if bounds is None else np.asarray(bounds, dtype=float)
    if b.shape != (3, 2) or not np.all(b[:, 1] > b[:, 0]):
        raise WorkspaceError(f"bounds must be [[xmin, xmax], [ymin, ymax], [zmin, zmax]] metres with min < max, got {np.asarray(bounds).tolist()}")
    axes = _grid_axes(b, h)
    n_nodes = math.prod(len(a) for a in axes)
    if n_nodes > MAX_GRID_NODES:
        raise WorkspaceError(f"resolution {h} m gives {n_nodes:.3g} grid nodes (> {MAX_GRID_NODES:.0e}); is it in metres?")
    spec = _grid_spec(platform, orientation, convention, limits, axes)
    nx, ny, nz = (len(a) for a in axes)
    per = max(2, int(chunk_nodes) // (ny * nz))  # a slab re-evaluates one plane each side: keep >= 2
    tasks = [(spec, i, min(i + per, nx)) for i in range(0, nx, per)]
    top, front, side = np.zeros((nx, ny), bool), np.zeros((nx, nz), bool), np.zeros((ny, nz), bool)
    inside = full = mixed = inside_2h = 0
    removed: dict = {n: 0 for n in limits.active if n != "stroke"}
    edge = False
    boundaries = []
    for r in _run_tasks(_slab_task, tasks, executor, workers, progress, "workspace slabs"):
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
        raise WorkspaceError(f"no reachable position at orientation {spec.orientation.tolist()} rad with limits {list(limits.active)} at resolution {h} m")
    boundary = np.stack([axes[k][bnd_idx[:, k]] for k in range(3)], -1).astype(np.float32)
    h3 = h**3
    vol = inside * h3
    v_lo, v_hi = full * h3, (full + mixed) * h3
    extents, ext_err = _extents_from_views(axes, top, front, side, h)
    if refine:
        extents, ext_err = _refine_extents(spec, extents, top, front, side, h)
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


def _extreme_indices(views) -> list:
    """Per axis: (min index, max index) of inside nodes, from the views."""
    top, front, side = views
    ix = np.flatnonzero(top.any(axis=1))
    iy = np.flatnonzero(top.any(axis=0))
    iz = np.flatnonzero(front.any(axis=0))
    return [(a[0], a[-1]) for a in (ix, iy, iz)]


def _extents_from_views(axes, top, front, side, h):
    """Grid-level extents: the true extreme lies within h beyond the extreme inside node."""
    ext = np.array([[axes[k][i0] - h / 2, axes[k][i1] + h / 2] for k, (i0, i1) in enumerate(_extreme_indices((top, front, side)))])
    return ext, h / 2


def _extreme_plane_nodes(axes, top, front, side, k, idx) -> np.ndarray:
    """``(m, 3)`` candidate inside nodes on the grid plane ``axes[k][idx]`` (from the two views that
    hold it; a node is a candidate when both views have it)."""
    if k == 0:
        plane = top[idx][:, None] & front[idx][None, :]
    elif k == 1:
        plane = top[:, idx][:, None] & side[idx][None, :]
    else:
        plane = front[:, idx][:, None] & side[:, idx][None, :]
    o1, o2 = [j for j in range(3) if j != k]
    r = np.argwhere(plane)
    pts = np.empty((len(r), 3))
    pts[:, k], pts[:, o1], pts[:, o2] = axes[k][idx], axes[o1][r[:, 0]], axes[o2][r[:, 1]]
    return pts


def _refine_extents(spec: _GridSpec, extents, top, front, side, h, feas_tol: float = 1e-9):
    """Each extreme found by a constrained optimisation (SLSQP on the per-leg margins, all smooth
    pieces) from the extreme grid node; kept only if the optimum is feasible (every margin >=
    -``feas_tol``) and at least as far out as the node. Returns (extents, error) where error is the
    largest gap between a refined extreme and its grid bracket's far end (node ± h): under the grid
    assumption (the boundary is resolved at h) the true extreme lies in that gap."""
    from scipy.optimize import minimize

    axes, o = spec.axes, spec.orientation
    out = extents.copy()
    gaps = []

    def margins(p):
        q = np.r_[p, o]
        l = leg_vectors(spec.platform, q, spec.convention)
        return np.concatenate([m.ravel() for m in raw_margins(spec.platform, l, spec.R, spec.limits, q, spec.convention).values()])

    for k, (i_lo, i_hi) in enumerate(_extreme_indices((top, front, side))):
        for side_i, (idx, sign) in enumerate(((i_lo, -1), (i_hi, 1))):
            node_c = axes[k][idx]
            best = node_c
            cands = [c for c in _extreme_plane_nodes(axes, top, front, side, k, idx) if margins(c).min() >= 0]
            if cands:
                cands = np.array(cands)
                start = cands[np.argmin(np.linalg.norm(cands - cands.mean(axis=0), axis=1))]
                res = minimize(lambda p: -sign * p[k], start, jac=lambda p: -sign * np.eye(3)[k], method="SLSQP",
                               constraints={"type": "ineq", "fun": margins}, options={"ftol": 1e-12, "maxiter": 200})
                if margins(res.x).min() >= -feas_tol and sign * res.x[k] >= sign * node_c:
                    best = float(res.x[k])
            out[k, side_i] = best
            gaps.append(max(0.0, sign * (node_c + sign * h - best)))
    return out, max(gaps)


# ----------------------------------------------------------------------------------------------
# An independent volume for the stroke limits alone: exact z-intervals per (x, y) column.


def stroke_column_lengths(platform: Platform, x, y, orientation=(0.0, 0.0, 0.0), convention: str = "utn", z_bounds=(0.0, np.inf)) -> np.ndarray:
    """``(...)`` length (m) of the set of z in ``z_bounds`` with every leg within stroke, for columns at
    ``x``, ``y`` (broadcast, metres). Per leg, L_min² <= ρ² + (z - c_z)² <= L_max² is one or two
    z-intervals; their intersection is measured exactly between sorted interval end points."""
    l0 = leg_vectors(platform, np.r_[0.0, 0.0, 0.0, _check_orientation(orientation)], convention)
    x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
    rho2 = (x[..., None] + l0[:, 0]) ** 2 + (y[..., None] + l0[:, 1]) ** 2  # (..., 6)
    a = np.sqrt(np.maximum(platform.L_min**2 - rho2, 0.0))
    b = np.sqrt(np.maximum(platform.L_max**2 - rho2, 0.0))
    reach = rho2 <= platform.L_max**2
    cz = -l0[:, 2]
    z0, z1 = z_bounds
    ends = np.concatenate([cz - b, cz - a, cz + a, cz + b, np.broadcast_to([z0, min(z1, 1e9)], x.shape + (2,))], -1)
    ends = np.sort(np.clip(ends, z0, min(z1, 1e9)), axis=-1)
    mid = 0.5 * (ends[..., 1:] + ends[..., :-1])  # (..., 25)
    dz = np.abs(mid[..., None] - cz)  # (..., 25, 6)
    ok = np.all(reach[..., None, :] & (dz >= a[..., None, :]) & (dz <= b[..., None, :]), axis=-1)
    return np.sum(np.where(ok, ends[..., 1:] - ends[..., :-1], 0.0), axis=-1)


def stroke_volume_columns(platform: Platform, resolution: float, orientation=(0.0, 0.0, 0.0), convention: str = "utn", z_floor: float = 0.0) -> float:
    """Volume (m³) of the stroke workspace above ``z_floor``: exact column lengths integrated by the
    midpoint rule on an (x, y) grid of step ``resolution`` (error O(h^1.5) from the rim)."""
    b = default_bounds(platform, orientation, convention, z_floor)
    h = float(resolution)
    xs = np.arange(b[0, 0] + h / 2, b[0, 1], h)
    ys = np.arange(b[1, 0] + h / 2, b[1, 1], h)
    total = 0.0
    for i in range(0, len(xs), max(1, 20000 // len(ys))):
        X, Y = np.meshgrid(xs[i : i + max(1, 20000 // len(ys))], ys, indexing="ij")
        total += stroke_column_lengths(platform, X, Y, orientation, convention, (z_floor, np.inf)).sum()
    return float(total * h * h)


# ----------------------------------------------------------------------------------------------
# Orientation limits.


@dataclass(frozen=True)
class RotationLimit:
    """The largest rotation about one base axis in one direction.

    axis 'x'|'y'|'z'; sign +1/-1; angle (rad, signed; = max_angle with ``reached`` False if no limit
    was met); lengths (6,) m at that angle; limit (name), leg (1-based) or pair (1-based legs, for
    collision); side 'min'|'max' for the stroke; at_limit: every leg (or pair) that crosses the
    limit just beyond the angle (symmetric platforms reach it with two legs at once)."""

    axis: str
    sign: int
    angle: float
    lengths: np.ndarray
    limit: str | None
    leg: int | None
    pair: tuple | None
    side: str | None
    reached: bool
    at_limit: tuple = ()

    def as_dict(self) -> dict:
        return {
            "axis": self.axis,
            "direction": "+" if self.sign > 0 else "-",
            "angle_deg": math.degrees(self.angle),
            "lengths_m": self.lengths.tolist(),
            "limit": self.limit,
            "leg": self.leg,
            "pair": list(self.pair) if self.pair else None,
            "side": self.side,
            "reached": self.reached,
            "at_limit": [list(a) if isinstance(a, tuple) else a for a in self.at_limit],
        }


def orientation_limits(
    platform: Platform,
    position=None,
    centre=None,
    limits: Limits = Limits(),
    max_angle: float = math.pi,
    step: float = math.radians(0.25),
    tol: float = 1e-10,
) -> list[RotationLimit]:
    """Rotate the plate from zero orientation at ``position`` (3,) m (the pose position, default the
    home pose: mid-stroke) about the base X, Y and Z axes through the plate point ``centre`` (p_TC,
    (3,) m in T; default the platform's rotation centre, i.e. the top origin), each way, until a
    limit is met. The first crossing is found by a scan of ``step`` rad, then bisected to ``tol``.
    Returns six ``RotationLimit`` (x+, x-, y+, y-, z+, z-)."""
    pos = platform.home_pose()[:3] if position is None else np.asarray(position, dtype=float)
    if pos.shape != (3,) or not np.all(np.isfinite(pos)):
        raise WorkspaceError(f"position must be 3 finite coordinates in metres, got {np.asarray(position).tolist()}")
    c = platform.rotation_centre if centre is None else np.asarray(centre, dtype=float)
    if c.shape != (3,) or not np.all(np.isfinite(c)):
        raise WorkspaceError(f"rotation centre must be 3 finite coordinates in metres (plate frame), got {np.asarray(centre).tolist()}")
    if not (0 < step < max_angle):
        raise WorkspaceError(f"step must be in (0, max_angle), got step = {step} rad, max_angle = {max_angle} rad")
    pivot = platform.replace(rotation_centre=c)
    p_C = pos - platform.rotation_centre + c  # zero orientation: the pivot point in B
    start = np.r_[p_C, 0.0, 0.0, 0.0]
    m0 = limit_margins(pivot, start, limits)
    bad = [n for n, (m, _) in m0.items() if m < 0]
    if bad:
        raise WorkspaceError(f"start pose {np.round(np.r_[pos, 0, 0, 0], 6).tolist()} is outside the {bad[0]} limit (margin {float(m0[bad[0]][0]):.4g} {LIMIT_UNITS[bad[0]]})")

    def poses(dirs, angles):  # dirs (k,) 0..5 -> axis, sign; angles (k, n) magnitudes
        q = np.broadcast_to(start, angles.shape + (6,)).copy()
        for d in range(6):
            sel = dirs == d
            q[sel, ..., 3 + d // 2] = (1 if d % 2 == 0 else -1) * angles[sel]
        return q

    def inside(q):
        ok = np.ones(q.shape[:-1], bool)
        for m, _ in limit_margins(pivot, q, limits).values():
            ok &= m >= 0
        return ok

    dirs = np.arange(6)
    scan = np.arange(1, math.ceil(max_angle / step) + 1) * step
    scan[-1] = max_angle
    ok = inside(poses(dirs, np.broadcast_to(scan, (6, len(scan)))))
    first_bad = np.where(ok.all(axis=1), -1, np.argmin(ok, axis=1))
    lo = np.where(first_bad > 0, scan[np.maximum(first_bad - 1, 0)], 0.0)
    lo = np.where(first_bad < 0, max_angle, lo)
    hi = np.where(first_bad >= 0, scan[np.maximum(first_bad, 0)], max_angle)
    while np.max(hi - lo) > tol:
        mid = 0.5 * (lo + hi)
        good = inside(poses(dirs, mid[:, None]))[:, 0]
        lo, hi = np.where(good, mid, lo), np.where(good, hi, mid)
    q_lo, q_hi = poses(dirs, lo[:, None])[:, 0], poses(dirs, hi[:, None])[:, 0]
    L = leg_lengths(pivot, q_lo)
    raw_hi = raw_margins(pivot, leg_vectors(pivot, q_hi), rotation_matrix(q_hi[:, 3:]), limits, q_hi)
    m_hi = {n: (m.min(axis=-1), m.argmin(axis=-1)) for n, m in raw_hi.items()}
    pairs = leg_pairs(platform)
    out = []
    for d in range(6):
        sign = 1 if d % 2 == 0 else -1
        reached = first_bad[d] >= 0
        name = leg = pair = side = None
        at_limit = ()
        if reached:
            name = min(m_hi, key=lambda n: m_hi[n][0][d])
            idx = int(m_hi[name][1][d])
            crossing = np.flatnonzero(raw_hi[name][d] < 0)
            if name == "collision":
                pair = (int(pairs[idx, 0]) + 1, int(pairs[idx, 1]) + 1)
                at_limit = tuple((int(pairs[j, 0]) + 1, int(pairs[j, 1]) + 1) for j in crossing)
            elif name != "dexterity":
                leg = idx + 1
                at_limit = tuple(int(j) + 1 for j in crossing)
            if name == "stroke":
                side = "max" if L[d, idx] > platform.stroke.mean() else "min"
        out.append(RotationLimit(AXES[d // 2], sign, sign * float(lo[d]), L[d], name, leg, pair, side, bool(reached), at_limit))
    return out


# ----------------------------------------------------------------------------------------------
# Dexterity map, mobility, and a 6-D sweep.


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
        raise WorkspaceError(f"plane must be 'xy', 'xz' or 'yz', got {plane!r}")
    o = _check_orientation(orientation)
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


def gruebler_mobility(n_links: int, joint_dofs, passive_dofs: int = 0, space_dof: int = 6) -> int:
    """Grübler's count m = λ (n - j - 1) + Σ f_i - I_f (seed 001, eq. 1): ``n_links`` links including
    base and top, ``joint_dofs`` the freedom of each of the j joints, ``passive_dofs`` I_f (idle
    freedoms such as a leg spinning about its own axis), ``space_dof`` λ (6 spatial, 3 planar)."""
    f = [int(x) for x in joint_dofs]
    if space_dof not in (3, 6):
        raise WorkspaceError(f"space_dof (lambda) must be 3 (planar) or 6 (spatial), got {space_dof}")
    if n_links < 1 or any(not 1 <= x <= space_dof for x in f):
        raise WorkspaceError(f"need n_links >= 1 and every joint freedom in 1..{space_dof}, got n = {n_links}, f = {f}")
    return space_dof * (n_links - len(f) - 1) + sum(f) - int(passive_dofs)


STEWART_JOINTS = {
    # (base joint freedom, leg joint freedom, top joint freedom, idle leg spins)
    "SPS": (3, 1, 3, 6),  # the paper's count: 12 spherical + 6 prismatic, I_f = 6
    "UPS": (2, 1, 3, 0),
    "UPU": (2, 1, 2, 0),
}


def stewart_mobility(kind: str = "SPS") -> dict:
    """Grübler's count for a 6-leg platform of joint type ``kind`` ('SPS', 'UPS', 'UPU'): 14 links
    (base, top, two per leg), 18 joints. Returns n, j, joint freedoms, I_f and m."""
    if kind not in STEWART_JOINTS:
        raise WorkspaceError(f"unknown leg type {kind!r}; expected one of {', '.join(STEWART_JOINTS)}")
    fb, fp, ft, idle = STEWART_JOINTS[kind]
    dofs = [fb] * 6 + [fp] * 6 + [ft] * 6
    return {"kind": kind, "n": 14, "j": 18, "sum_f": sum(dofs), "I_f": idle, "m": gruebler_mobility(14, dofs, idle)}


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
        raise WorkspaceError(f"grids must be six non-empty 1-D arrays (px, py, pz, a_x, a_y, a_z), got {len(grids)}")
    total = math.prod(len(g) for g in grids)
    tasks = [(platform, grids, limits, convention, s, min(s + chunk, total)) for s in range(0, total, chunk)]
    count, marginals = 0, [np.zeros(len(g), np.int64) for g in grids]
    for c, marg in _run_tasks(_count_task, tasks, executor, workers, progress, "6-D sweep"):
        count += c
        for k in range(6):
            marginals[k] += marg[k]
    return {"count": count, "total": total, "fraction": count / total, "marginals": marginals}


def default_workers() -> int:
    """Worker processes that pay off here: the CPUs this process may use (at most 8)."""
    try:
        n = len(os.sched_getaffinity(0))
    except AttributeError:
        n = os.cpu_count() or 1
    return max(1, min(n, 8))


# ----------------------------------------------------------------------------------------------
# Figures (matplotlib imported only here).


def view_figures(ws: Workspace, reference=None, title: str = "") -> dict:
    """The paper's views of a workspace: ``{"top": X–Y, "front": X–Z, "side": Y–Z, "3d": boundary}``
    matplotlib figures (axes in metres). ``reference``: optional (3, 2) extents drawn dashed (e.g. a
    paper's numbers)."""
    import matplotlib.pyplot as plt

    x, y, z = ws.axes
    views = {"top": (x, y, ws.top, 0, 1), "front": (x, z, ws.front, 0, 2), "side": (y, z, ws.side, 1, 2)}
    names = {"top": "top view X–Y", "front": "front view X–Z", "side": "side view Y–Z"}
    figs = {}
    for name, (u, v, mask, ku, kv) in views.items():
        fig, ax = plt.subplots(figsize=(4.6, 4.2))
        ax.contourf(u, v, mask.T.astype(float), levels=[0.5, 1.5], colors=["#9ecae1"])
        ax.contour(u, v, mask.T.astype(float), levels=[0.5], colors=["#08519c"], linewidths=1)
        ax.axvline(ws.extents[ku, 0], color="k", lw=0.6, ls=":")
        ax.axvline(ws.extents[ku, 1], color="k", lw=0.6, ls=":")
        ax.axhline(ws.extents[kv, 0], color="k", lw=0.6, ls=":")
        ax.axhline(ws.extents[kv, 1], color="k", lw=0.6, ls=":")
        if reference is not None:
            ref = np.asarray(reference, dtype=float)
            ax.plot(ref[ku][[0, 1, 1, 0, 0]], ref[kv][[0, 0, 1, 1, 0]], "r--", lw=1, label="paper extents")
            ax.legend(loc="upper right", fontsize=7)
        ax.set_xlabel(f"{AXES[ku].upper()} (m)")
        ax.set_ylabel(f"{AXES[kv].upper()} (m)")
        ax.set_aspect("equal")
        ax.set_title(f"{title} {names[name]}".strip(), fontsize=9)
        figs[name] = fig
    fig = plt.figure(figsize=(5.5, 4.8))
    ax = fig.add_subplot(projection="3d")
    pts = ws.boundary
    if len(pts) > 15000:
        pts = pts[np.random.default_rng(0).choice(len(pts), 15000, replace=False)]
    ax.scatter(pts[:, 0], pts[:, 1], pts[:, 2], c=pts[:, 2], s=1, cmap="viridis")
    ax.set_xlabel("X (m)")
    ax.set_ylabel("Y (m)")
    ax.set_zlabel("Z (m)")
    ax.set_title(f"{title} boundary (3D)".strip(), fontsize=9)
    figs["3d"] = fig
    return figs
