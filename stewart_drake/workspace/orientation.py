"""Orientation limits: the largest rotation about the base X, Y and Z axes each way from a position,
about the top origin or a given centre, with the final leg lengths and the limiting leg (seed 001).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_lengths, leg_vectors
from stewart_drake.core.rotations import rotation_matrix
from stewart_drake.core.sanity import above_base, plate_anchor_heights
from stewart_drake.workspace.limits import (
    AXES,
    LIMIT_UNITS,
    Limits,
    WorkspaceError,
    leg_pairs,
    limit_margins,
    raw_margins,
)


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
    limit is met (the plate reaching the base plane is one: limit ``base``, with the leg whose plate
    anchor touches it). The first crossing is found by a scan of ``step`` rad, then bisected to ``tol``.
    Returns six ``RotationLimit`` (x+, x-, y+, y-, z+, z-)."""
    pos = platform.home_pose()[:3] if position is None else np.asarray(position, dtype=float)
    if pos.shape != (3,) or not np.all(np.isfinite(pos)):
        raise WorkspaceError(WorkspaceError.POSITION.format(value=np.asarray(position).tolist()))
    c = platform.rotation_centre if centre is None else np.asarray(centre, dtype=float)
    if c.shape != (3,) or not np.all(np.isfinite(c)):
        raise WorkspaceError(WorkspaceError.CENTRE.format(value=np.asarray(centre).tolist()))
    if not (0 < step < max_angle):
        raise WorkspaceError(WorkspaceError.STEP.format(step=step, max_angle=max_angle))
    pivot = platform.replace(rotation_centre=c)
    p_C = pos - platform.rotation_centre + c  # zero orientation: the pivot point in B
    start = np.r_[p_C, 0.0, 0.0, 0.0]
    m0 = limit_margins(pivot, start, limits)
    bad = [n for n, (m, _) in m0.items() if m < 0]
    if bad:
        raise WorkspaceError(
            WorkspaceError.START_OUTSIDE.format(
                pose=np.round(np.r_[pos, 0, 0, 0], 6).tolist(),
                limit=bad[0],
                margin=float(m0[bad[0]][0]),
                unit=LIMIT_UNITS[bad[0]],
            )
        )

    def poses(dirs, angles):  # dirs (k,) 0..5 -> axis, sign; angles (k, n) magnitudes
        q = np.broadcast_to(start, angles.shape + (6,)).copy()
        for d in range(6):
            sel = dirs == d
            q[sel, ..., 3 + d // 2] = (1 if d % 2 == 0 else -1) * angles[sel]
        return q

    def inside(q):
        ok = above_base(pivot, q)  # the plate stays above its base (sanity.above_base)
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
    if not pivot.plate_below_base_allowed:
        raw_hi["base"] = plate_anchor_heights(pivot, q_hi)  # (6, 6) m: the height of each leg's plate anchor
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
        out.append(
            RotationLimit(AXES[d // 2], sign, sign * float(lo[d]), L[d], name, leg, pair, side, bool(reached), at_limit)
        )
    return out
