"""Extents of a grid workspace: per axis the extreme inside nodes from the three views, then each
extreme refined by a constrained optimisation (SLSQP on the limit margins) with an error bound.
"""

from __future__ import annotations

import numpy as np

from stewart_drake.workspace.limits import raw_margins
from stewart_drake.workspace.slabs import GridSpec


def _extreme_indices(views) -> list:
    """Per axis: (min index, max index) of inside nodes, from the views."""
    top, front, side = views
    ix = np.flatnonzero(top.any(axis=1))
    iy = np.flatnonzero(top.any(axis=0))
    iz = np.flatnonzero(front.any(axis=0))
    return [(a[0], a[-1]) for a in (ix, iy, iz)]


def extents_from_views(axes, top, front, side, h):
    """Grid-level extents: the true extreme lies within h beyond the extreme inside node."""
    ext = np.array(
        [[axes[k][i0] - h / 2, axes[k][i1] + h / 2] for k, (i0, i1) in enumerate(_extreme_indices((top, front, side)))]
    )
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


def plate_offsets(spec: GridSpec) -> np.ndarray:
    """``(6, 3)`` r_i = R (p_TTi − p_TC) at the sweep's orientation (m), as ``leg_vectors`` and
    ``inverse_jacobian`` compute it (the same einsum of the same R: the same bits)."""
    platform = spec.platform
    return np.einsum("...jk,ik->...ij", spec.R, platform.top_anchors_per_leg - platform.rotation_centre)


def point_margins(spec: GridSpec, p, offsets: np.ndarray) -> np.ndarray:
    """Every margin at one position ``p`` (3,) (m) of the sweep's orientation: ``raw_margins`` of ``leg_vectors``
    at the pose, then the half-space above the base, bit for bit, with the orientation's part (``offsets``,
    ``plate_offsets``) computed once instead of at every call of the refinement's optimiser."""
    platform = spec.platform
    q = np.concatenate([np.asarray(p, dtype=float), spec.orientation])  # np.r_'s numbers without its parsing
    l = q[..., None, :3] + offsets - platform.base_anchors  # leg_vectors' (p + r) − b
    margins = raw_margins(platform, l, spec.R, spec.limits, q, spec.convention, offsets=offsets)
    ms = [m.ravel() for m in margins.values()]
    above = [np.array([p[2] - spec.z_floor])] if np.isfinite(spec.z_floor) else []  # the half-space above the base
    return np.concatenate(ms + above)


def refine_extents(spec: GridSpec, extents, top, front, side, h, feas_tol: float = 1e-9):
    """Each extreme found by a constrained optimisation (SLSQP on the per-leg margins, all smooth
    pieces) from the extreme grid node; kept only if the optimum is feasible (every margin >=
    -``feas_tol``) and at least as far out as the node. Returns (extents, error) where error is the
    largest gap between a refined extreme and its grid bracket's far end (node ± h): under the grid
    assumption (the boundary is resolved at h) the true extreme lies in that gap."""
    from scipy.optimize import minimize  # here: ~0.1 s CPU to import, and the package's importers rarely refine

    axes, o = spec.axes, spec.orientation
    out = extents.copy()
    gaps = []

    def margins_batch(P):
        """``(m, k)`` every margin at positions ``P`` (m, 3): leg vectors P + l_i(0, R), as in the sweep."""
        P = np.asarray(P, dtype=float).reshape(-1, 3)
        q = np.concatenate([P, np.broadcast_to(o, P.shape)], -1)
        ms = raw_margins(spec.platform, P[:, None, :] + spec.offsets, spec.R, spec.limits, q, spec.convention)
        above = [P[:, 2:3] - spec.z_floor] if np.isfinite(spec.z_floor) else []  # the half-space above the base
        return np.concatenate([m.reshape(len(P), -1) for m in ms.values()] + above, axis=1)

    offsets = plate_offsets(spec)

    def margins(p):
        """Every margin at one position ``p`` (3,) (``point_margins``): SLSQP's finite-difference Jacobian of
        this form converges where the batched one above stalled (gonzalez-dutra-2009, z_min)."""
        return point_margins(spec, p, offsets)

    for k, (i_lo, i_hi) in enumerate(_extreme_indices((top, front, side))):
        for side_i, (idx, sign) in enumerate(((i_lo, -1), (i_hi, 1))):
            node_c = axes[k][idx]
            best = node_c
            nodes = _extreme_plane_nodes(axes, top, front, side, k, idx)
            cands = nodes[margins_batch(nodes).min(axis=1) >= 0] if len(nodes) else nodes
            if len(cands):
                start = cands[np.argmin(np.linalg.norm(cands - cands.mean(axis=0), axis=1))]
                res = minimize(
                    lambda p: -sign * p[k],
                    start,
                    jac=lambda p: -sign * np.eye(3)[k],
                    method="SLSQP",
                    constraints={"type": "ineq", "fun": margins},
                    options={"ftol": 1e-12, "maxiter": 200},
                )
                if margins(res.x).min() >= -feas_tol and sign * res.x[k] >= sign * node_c:
                    best = float(res.x[k])
            out[k, side_i] = best
            gaps.append(max(0.0, sign * (node_c + sign * h - best)))
    return out, max(gaps)
