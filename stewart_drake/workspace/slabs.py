"""The grid kernel of the constant-orientation workspace: a small picklable ``GridSpec`` and the
x-slab worker that classifies nodes, counts cells and finds boundary nodes. Translation enters the
inverse kinematics additively, l_i(p, R) = p + l_i(0, R), so l_i(0, R) comes from
``kinematics.leg_vectors`` once and the grid positions are added (the tests check this node by node).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import condition_above, inverse_jacobian, leg_vectors
from stewart_drake.core.rotations import rotation_matrix
from stewart_drake.core.sanity import plate_floor
from stewart_drake.system.memo import Memo, digest
from stewart_drake.workspace.limits import Limits, check_orientation, leg_axis_distances, leg_pairs, margins_from_legs


@dataclass(frozen=True)
class GridSpec:
    """Everything a slab worker needs (small and picklable)."""

    platform: Platform
    orientation: np.ndarray
    convention: str
    limits: Limits
    offsets: np.ndarray  # (6, 3) l_i(0, R): leg vectors with the rotation centre at the origin
    R: np.ndarray  # (3, 3)
    axes: tuple  # three 1-D arrays of node coordinates
    z_floor: float = -np.inf  # nodes count only above it (``sanity.plate_floor``: plate above the base)


def grid_spec(platform, orientation, convention, limits, axes) -> GridSpec:
    """The ``GridSpec`` of a constant-orientation sweep over the node ``axes`` (three 1-D arrays, m) at
    ``orientation`` (3,) rad."""
    o = check_orientation(orientation)
    l0 = leg_vectors(platform, np.r_[0.0, 0.0, 0.0, o], convention)
    return GridSpec(
        platform,
        o,
        convention,
        limits,
        l0,
        rotation_matrix(o, convention),
        tuple(axes),
        plate_floor(platform, o, convention),
    )


# m²: what the window adds to L_max² before it bounds a coordinate. A node outside the window has some leg with
# |l_i|² > L_max² + WINDOW_SLACK_M2 exactly, while rounding moves the kernel's |l_i|² by ~1e-15 m² at most: the
# kernel rejects it too. (The bounds' own rounding, ~1e-16 m, is far inside the 5e-13 m the slack adds to them.)
WINDOW_SLACK_M2 = 1e-12


def _reach(room: np.ndarray) -> np.ndarray | None:
    """Half-widths sqrt(room) of the legs' reach along one axis, or None when some leg cannot reach (room < 0)."""
    return None if np.any(room < 0) else np.sqrt(room)


def _min_square(lo: float, hi: float, c: np.ndarray) -> np.ndarray:
    """``(6,)`` the least (v + c_i)² over v in [lo, hi] (m²)."""
    a, b = lo + c, hi + c
    return np.where((a <= 0) & (b >= 0), 0.0, np.minimum(a * a, b * b))


def stroke_window(spec: GridSpec, xs, ys, zs) -> tuple[int, int, int, int]:
    """``(j0, j1, k0, k1)``: the nodes ys[j0:j1] × zs[k0:k1] of the block xs × ys × zs (ascending node coordinates,
    m) outside which no node has every leg within L_max: per leg, the block's least (x + c_x)² leaves
    (y + c_y)² ≤ L_max² + ``WINDOW_SLACK_M2`` − that, a y interval; the z interval likewise from the least x and
    y parts. Typically a fifth of the block or less, and empty (j0 = j1) when a leg cannot reach the block."""
    c = spec.offsets  # (6, 3) l_i(0, R): leg i is p + c_i
    top = spec.platform.L_max**2 + WINDOW_SLACK_M2
    mx = _min_square(xs[0], xs[-1], c[:, 0])
    ry = _reach(top - mx)
    if ry is None:
        return 0, 0, 0, 0
    y_lo, y_hi = np.max(-c[:, 1] - ry), np.min(-c[:, 1] + ry)
    j0, j1 = int(np.searchsorted(ys, y_lo, "left")), int(np.searchsorted(ys, y_hi, "right"))
    if j0 >= j1:
        return 0, 0, 0, 0
    rz = _reach(top - mx - _min_square(ys[j0], ys[j1 - 1], c[:, 1]))
    if rz is None:
        return 0, 0, 0, 0
    z_lo, z_hi = np.max(-c[:, 2] - rz), np.min(-c[:, 2] + rz)
    k0, k1 = int(np.searchsorted(zs, z_lo, "left")), int(np.searchsorted(zs, z_hi, "right"))
    return (j0, j1, k0, k1) if k0 < k1 else (0, 0, 0, 0)


# the last blocks' closest leg-axis distances: sweeps of one grid at several leg diameters (the report's two
# collision rows) measure the same stroke nodes' distances once
AXIS_DISTANCES = Memo(4)


def closest_leg_axes(platform: Platform, l: np.ndarray) -> np.ndarray:
    """``(n,)`` the closest two leg axes come (m) at each of ``n`` leg-vector sets ``l`` ``(n, 6, 3)``
    (``limits.leg_axis_distances``' minimum), remembered by the bytes of ``l``, the base anchors and the pairs."""
    key = digest(
        str(l.shape).encode(),
        np.ascontiguousarray(l).tobytes(),
        platform.base_anchors.tobytes(),
        leg_pairs(platform).tobytes(),
    )
    return AXIS_DISTANCES.get(key, lambda: leg_axis_distances(platform, l).min(axis=-1))


def inside_block(spec: GridSpec, xs, ys, zs) -> tuple[np.ndarray, dict]:
    """Classify the grid block xs × ys × zs: ``(inside, removed)`` where ``removed``
    counts, per optional limit, the stroke-feasible nodes it rejects in each x-plane ``(nx,)``.
    ``inside`` is bool ``(nx, ny, nz)``."""
    p = spec.platform
    shape = (len(xs), len(ys), len(zs))
    ok = np.zeros(shape, bool)
    # the stroke's nodes lie in a window of the block's y and z (``stroke_window``): only the window is tested
    j0, j1, k0, k1 = stroke_window(spec, xs, ys, zs) if spec.limits.stroke else (0, len(ys), 0, len(zs))
    win = ok[:, j0:j1, k0:k1]  # a view: the window's answers land in ``ok``
    win[...] = True
    ys_w, zs_w = ys[j0:j1], zs[k0:k1]
    win &= (np.asarray(zs_w) > spec.z_floor)[None, None, :]
    lo2, hi2 = p.L_min**2, p.L_max**2
    if spec.limits.stroke:
        for i in range(6):
            c = spec.offsets[i]
            d2 = (
                ((xs + c[0]) ** 2)[:, None, None]
                + ((ys_w + c[1]) ** 2)[None, :, None]
                + ((zs_w + c[2]) ** 2)[None, None, :]
            )
            win &= (d2 >= lo2) & (d2 <= hi2)
    removed = {}
    others = [n for n in spec.limits.active if n != "stroke"]
    if others:
        idx = np.nonzero(ok)
        pos = np.stack([xs[idx[0]], ys[idx[1]], zs[idx[2]]], -1)
        l = pos[:, None, :] + spec.offsets
        poses = np.concatenate([pos, np.broadcast_to(spec.orientation, pos.shape)], -1)
        valued = dataclasses.replace(spec.limits, stroke=False, max_condition=None, leg_diameter=None)
        margins = margins_from_legs(p, l, spec.R, valued, poses, spec.convention) if valued.active else {}
        outside = {name: margins[name][0] < 0 for name in valued.active}
        if spec.limits.leg_diameter is not None:  # min(d − D) = min(d) − D: rounding is monotone
            outside["collision"] = closest_leg_axes(p, l) - spec.limits.leg_diameter < 0
        if spec.limits.max_condition is not None:  # its margin max_condition − κ < 0 exactly where κ > max_condition
            J = inverse_jacobian(p, poses, spec.convention)  # the J of the margin's ``condition_number``
            outside["dexterity"] = condition_above(p, J, spec.limits.max_condition)
        keep = np.ones(len(pos), bool)
        for name in others:
            bad = outside[name]
            removed[name] = np.bincount(idx[0][bad], minlength=shape[0])
            keep &= ~bad
        ok[idx] = keep
    return ok, removed


def slab_task(spec: GridSpec, i0: int, i1: int) -> dict:
    """Sweep the owned x-planes i0..i1-1 (and one neighbour plane each side for cells and boundary)."""
    x, y, z = spec.axes
    lo, hi = max(i0 - 1, 0), min(i1 + 1, len(x))
    m, removed_all = inside_block(spec, x[lo:hi], y, z)
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
    nb = (
        pad[:-2, 1:-1, 1:-1]
        & pad[2:, 1:-1, 1:-1]
        & pad[1:-1, :-2, 1:-1]
        & pad[1:-1, 2:, 1:-1]
        & pad[1:-1, 1:-1, :-2]
        & pad[1:-1, 1:-1, 2:]
    )
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
        "edge": bool(
            (i0 == 0 and mo[0].any())
            or (i1 == len(x) and mo[-1].any())
            or mo[:, [0, -1], :].any()
            or mo[:, :, [0, -1]].any()
        ),
        "inside_2h": int(np.count_nonzero(mo[(np.arange(i0, i1) % 2) == 0][:, ::2, ::2])),
    }
