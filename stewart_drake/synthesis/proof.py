"""A proof that every pose of a box is reachable: within the stroke and with the plate above the base.

Not a sample. The box [lo, hi] (absolute poses, metres and radians) is covered by cells; on each cell C
with centre c and half-widths h (position h_p, angles h_θ), leg i's vector l_i = p + R(θ) t_i − b_i
(t_i = p_TTi − p_TC, b_i = p_BBi) is enclosed in a set that is exact in the position and second-order in
the angles:

    l_i(p, θ) ∈ Z_i ⊕ B(r_i),   Z_i = l_i(c) + { G_i u : |u_k| <= 1 } (a zonotope, 6 generators),

with generators h_p,k e_k (k = x, y, z) and h_θ,j ∂(R t_i)/∂θ_j at c (j = a, b, g), and the Taylor
remainder of θ ↦ R(θ) t_i bounded in the 2-norm by r_i = ½ |t_i| (Σ_j h_θ,j)². The constant is derived,
not estimated: R is a product of three elementary rotations (Ry·Rx·Rz for ``utn``, Rz·Ry·Rx for ``zyx``),
each second partial derivative ∂²R/∂θ_j∂θ_k inserts two factors [e]× (or one [e]×²) among them, and
‖[e]×‖₂ = ‖[e]×²‖₂ = ‖rotation‖₂ = 1, so ‖∂²(R t)/∂θ_j∂θ_k‖ <= |t| and the integral remainder of the
Taylor expansion is at most ½ |t| ‖δθ‖₁².

- Upper bound of L_i = |l_i| on the cell: the maximum of the convex |x| over Z_i is at one of its 2⁶
  vertices (all enumerated), plus r_i.
- Lower bound: for any unit n, |x| >= n·x >= n·l_i(c) − Σ_k |n·g_k| on Z_i (the support function); n is the
  direction of an approximate nearest point of Z_i to the origin (projected-gradient steps). Any n gives a
  valid bound; a good n makes it tight. Minus r_i.
- Plate anchor height z_i = p_z + (R t_i)_z >= c_z + (R(c) t_i)_z − h_p,z − Σ_j |∂(R t_i)_z/∂θ_j| h_θ,j − r_i.

- Joint cones (optional, the toolkit's definition in ``workspace.limits``: the angle between a leg and the base
  normal e_z at its base joint, and the plate normal n = R e_z at its plate joint): l_i·e_z is bounded below on
  the zonotope like the height; l_i·n = (p − b_i)·n + t_i,z with n ∈ n(c) + Σ_j δ_j ∂n/∂θ_j ⊕ B(½ ‖δθ‖₁²) (the
  same derived constant, |e_z| = 1), bounded below term by term. A leg is within the cone when
  l_i·a >= |l_i| cos(cone) for both axes a, checked with the bounds of |l_i|.

A cell is proven when every leg's bounds lie inside [L_min, L_max] and every anchor height is > 0 (and the
cones hold when asked). A cell
that is not proven is tested at its centre and at the poses where the bounds are attained, with the
toolkit's IK (``core.kinematics.leg_lengths``): a pose outside the stroke (by more than the slack below) is
a witness and the result is ``violated``; otherwise the cell is halved across its widest side (positions
in metres, angles times the plate radius). The cells examined are budgeted (``CellBudget``): ``START_CELLS``
first, the budget doubled each time it is reached while the volume of the cells left keeps shrinking (over the
last six levels: every side halved once), up to the cap ``max_cells``; when the cap is reached or the volume stops
shrinking the result is ``unresolved``, with the cells examined, the cells left and their share of the box's
volume.

Floating-point rounding. The bounds are computed in binary64 arithmetic. Each is a sum of at most ~200
rounded operations on numbers at most 100 m (the project's size limit) and on sines and cosines (numpy's
are within 4 ulp); by the standard error bound (n·u / (1 − n·u) relative, u = 2⁻⁵³) every bound is within
2.3e-12 m of its exact value. Every bound is widened by ``FP_SLACK`` = 1e-9 m, more than 400 times that;
a test recomputes cells' bounds in python-flint's ball arithmetic (rigorous) and finds them inside.
The cells' centres and half-widths are rounded too (c ± h of neighbours may leave a gap of a few ulp): each
cell's half-widths are grown by ``COVER_PAD`` × (1 + |c|) before its bounds are taken, so neighbours overlap
and every pose of the box lies in a cell whose bounds hold.
"""

from __future__ import annotations

import itertools
import time
from dataclasses import dataclass, field

import numpy as np

from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.rotations import check_convention
from stewart_drake.core.sanity import plate_anchor_heights
from stewart_drake.workspace.limits import Limits, leg_pairs, limit_margins, segment_gaps

FP_SLACK = 1e-9  # m: each bound widened by this (rounding; see the module docstring)
COVER_PAD = 1e-12  # each cell's half-widths grown by this × (1 + |centre|): adjacent cells overlap
MAX_CELLS = 2_000_000  # default cap on the cells a proof examines
START_CELLS = 200_000  # its first budget, doubled while the unresolved volume shrinks (``CellBudget``)
SHRINK = 0.99  # the unresolved volume shrinks when it falls below this fraction of its value ROUND levels before
ROUND = 6  # levels of cells in which every side of a cell is halved once (one per level, six sides)
BATCH = 4096  # cells per vectorised step
PG_STEPS = 40  # projected-gradient steps for the direction of the lower bound
VERTICES = np.array(list(itertools.product((-1.0, 1.0), repeat=6))).T  # (6, 64)
E = np.eye(3)


def skew(v) -> np.ndarray:
    """``(3, 3)`` [v]×."""
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def _elementary(axis: int, t) -> np.ndarray:
    c, s = np.cos(t), np.sin(t)
    R = np.zeros(np.shape(t) + (3, 3))
    i, j = (axis + 1) % 3, (axis + 2) % 3  # cyclic: R[i, j] = -sin for X (1, 2), Y (2, 0), Z (0, 1)
    R[..., axis, axis] = 1.0
    R[..., i, i] = c
    R[..., j, j] = c
    R[..., i, j] = -s
    R[..., j, i] = s
    return R


def rotation_derivatives(angles, convention: str = "utn") -> tuple[np.ndarray, np.ndarray]:
    """``(R (..., 3, 3), dR (..., 3, 3, 3))``: R(θ) and ∂R/∂θ_j (index j first after the batch) for angles
    (..., 3) about X, Y, Z (radians)."""
    a, b, g = np.moveaxis(np.asarray(angles, dtype=float), -1, 0)
    Rx, Ry, Rz = _elementary(0, a), _elementary(1, b), _elementary(2, g)
    Sx, Sy, Sz = skew(E[0]), skew(E[1]), skew(E[2])
    if convention == "utn":  # R = Ry Rx Rz
        R = Ry @ Rx @ Rz
        dR = [Ry @ Rx @ Sx @ Rz, Sy @ R, R @ Sz]
    else:  # R = Rz Ry Rx
        R = Rz @ Ry @ Rx
        dR = [R @ Sx, Rz @ Ry @ Sy @ Rx, Sz @ R]
    return R, np.stack(dR, -3)


def unresolved_volume(cells: Cells, lo, hi) -> float:
    """The share of the box [lo, hi] ((6,) m, rad) that ``cells`` cover, over its axes of non-zero width (cells of
    the box's cover do not overlap but by ``COVER_PAD``)."""
    half = (np.asarray(hi, dtype=float) - np.asarray(lo, dtype=float)) / 2
    axes = half > 0
    return float(np.sum(np.prod(cells.h[:, axes] / half[axes], axis=1)))


class CellBudget:
    """How many cells a proof may examine, asked once per level of cells (each level halves every cell left across
    one side): ``min(START_CELLS, cap)`` first; when the next level would pass it, it is doubled (up to ``cap``, as
    many times as that level needs) while the volume of the cells left (``unresolved_volume``) shrinks: below
    ``SHRINK`` times its value ``ROUND`` levels before (the whole box before the first level), a full round of
    halvings of every side. ``stopped`` says why it ran out: ``"cap"`` or ``"stalled"``."""

    def __init__(self, cap: int, lo, hi):
        self.cap, self.limit, self.lo, self.hi = int(cap), min(START_CELLS, int(cap)), lo, hi
        self.volumes, self.stopped = [], None

    def allows(self, examined: int, pending: Cells) -> bool:
        """Whether the proof may examine the ``pending`` cells (the next level) after ``examined`` ones."""
        volume = unresolved_volume(pending, self.lo, self.hi)
        self.volumes.append(volume)
        if examined + len(pending) <= self.limit:
            return True
        before = self.volumes[-1 - ROUND] if len(self.volumes) > ROUND else 1.0
        if self.limit >= self.cap or volume >= SHRINK * before:
            self.stopped = "cap" if self.limit >= self.cap else "stalled"
            return False
        while examined + len(pending) > self.limit and self.limit < self.cap:
            self.limit = min(2 * self.limit, self.cap)
        if examined + len(pending) <= self.limit:
            return True
        self.stopped = "cap"
        return False


@dataclass
class Cells:
    """Cells as centres ``c`` (n, 6) and half-widths ``h`` (n, 6) (m, rad)."""

    c: np.ndarray
    h: np.ndarray

    def __len__(self) -> int:
        return len(self.c)


@dataclass
class CellBounds:
    """Per cell and leg (n, 6): ``lower``/``upper`` bounds of the leg length (m), ``z_lower`` of the plate
    anchor height (m), with FP_SLACK applied; ``lower_pose``/``upper_pose`` (n, 6, 6) poses where the
    enclosures' extremes are attained (for witnesses)."""

    lower: np.ndarray
    upper: np.ndarray
    z_lower: np.ndarray
    lower_pose: np.ndarray
    upper_pose: np.ndarray
    axial_lower: np.ndarray | None = None
    normal_lower: np.ndarray | None = None
    clearance_lower: np.ndarray | None = None  # (n, k): lower bound of the distance between leg_pairs' segments


def cell_bounds(
    platform: Platform, cells: Cells, convention: str = "utn", cones: bool = False, clearance: bool = False
) -> CellBounds:
    """Rigorous leg-length and anchor-height bounds on each cell (see the module docstring); with ``cones``
    also lower bounds of l_i·e_z (``axial_lower``) and of l_i·n (``normal_lower``, n = R e_z the plate normal)."""
    c = cells.c
    h = cells.h + COVER_PAD * (1.0 + np.abs(c))  # cells overlap: no gap from rounded centres (docstring)
    t = platform.top_anchors_per_leg - platform.rotation_centre  # (6, 3)
    R, dR = rotation_derivatives(c[:, 3:], convention)  # (n, 3, 3), (n, 3, 3, 3)
    q = np.einsum("nij,lj->nli", R, t)  # (n, 6, 3)
    Jq = np.einsum("nkij,lj->nlik", dR, t)  # (n, 6, 3, 3): ∂q_i/∂θ_k
    lc = c[:, None, :3] + q - platform.base_anchors  # (n, 6, 3)
    n = len(c)
    G = np.empty((n, 6, 3, 6))
    G[..., :3] = np.eye(3) * h[:, None, None, :3]
    G[..., 3:] = Jq * h[:, None, None, 3:]
    r2 = 0.5 * np.linalg.norm(t, axis=1)[None, :] * np.sum(h[:, 3:], axis=1)[:, None] ** 2  # (n, 6)
    # upper: the vertices of the zonotope
    V = lc[..., None] + G @ VERTICES  # (n, 6, 3, 64)
    norms = np.linalg.norm(V, axis=-2)
    k = np.argmax(norms, axis=-1)
    upper = np.take_along_axis(norms, k[..., None], -1)[..., 0] + r2 + FP_SLACK
    upper_pose = c[:, None, :] + VERTICES.T[k] * h[:, None, :]
    # lower: support function in the direction of an approximate nearest point
    u = np.zeros((n, 6, 6))
    step = 1.0 / np.maximum(np.sum(G * G, axis=(-2, -1)), 1e-300)[..., None]
    for _ in range(PG_STEPS):
        x = lc + np.einsum("nlij,nlj->nli", G, u)
        u = np.clip(u - step * np.einsum("nlij,nli->nlj", G, x), -1.0, 1.0)
    x = lc + np.einsum("nlij,nlj->nli", G, u)
    nx = np.linalg.norm(x, axis=-1)
    dirn = x / np.where(nx > 0, nx, 1.0)[..., None]
    support = np.sum(dirn * lc, -1) - np.sum(np.abs(np.einsum("nli,nlij->nlj", dirn, G)), -1)
    lower = np.where(nx > 0, np.maximum(support, 0.0), 0.0) - r2 - FP_SLACK
    lower_pose = c[:, None, :] + u * h[:, None, :]
    z_lower = c[:, None, 2] + q[..., 2] - h[:, None, 2] - np.sum(np.abs(Jq[:, :, 2, :]) * h[:, None, 3:], -1) - r2
    out = CellBounds(lower, upper, z_lower - FP_SLACK, lower_pose, upper_pose)
    if cones:
        # l·e_z over the zonotope and the ball
        out.axial_lower = lc[..., 2] - np.sum(np.abs(G[:, :, 2, :]), -1) - r2 - FP_SLACK
        # l·n = (p − b)·n + t_z with n = R e_z ∈ n(c) + Σ_j δ_j ∂n/∂θ_j + B(½ ‖δθ‖₁²) (|e_z| = 1)
        n_c, Jn = R[:, :, 2], dR[:, :, :, 2]  # (n, 3), (n, 3 [j], 3)
        rn = 0.5 * np.sum(h[:, 3:], 1) ** 2  # (n,)
        a_c = c[:, None, :3] - platform.base_anchors  # (n, 6, 3)
        first = np.einsum("nli,ni->nl", a_c, n_c)
        first -= np.sum(np.abs(np.einsum("nli,nji->nlj", a_c, Jn)) * h[:, None, 3:], -1)
        first -= np.linalg.norm(a_c, axis=-1) * rn[:, None]
        n_abs = np.abs(n_c) + np.einsum("nji,nj->ni", np.abs(Jn), h[:, 3:]) + rn[:, None]  # (n, 3) max |n_k|
        out.normal_lower = first - np.sum(h[:, :3] * n_abs, -1)[:, None] + t[None, :, 2] - FP_SLACK
    if clearance:
        # how far each plate anchor moves over the cell: |l_i − l_i(c)| <= |h_p| + min(ε_R |t_i|, Σ_j |∂q_i/∂θ_j| h_θ,j
        # + r_i), ε_R = Σ_j h_θ,j bounding ‖R(θ) − R(c)‖₂ (each elementary rotation is 1-Lipschitz in its angle)
        tn = np.linalg.norm(t, axis=1)
        first = np.einsum("nlk,nk->nl", np.linalg.norm(Jq, axis=-2), h[:, 3:]) + r2
        move = np.linalg.norm(h[:, :3], axis=1)[:, None] + np.minimum(np.sum(h[:, 3:], 1)[:, None] * tn, first)
        out.clearance_lower = _clearance_lower(platform, lc + platform.base_anchors, G, r2, move)
    return out


PIECES = 4  # each leg cut into this many pieces for the clearance bound


def _clearance_lower(platform: Platform, P_c, G, r2, move) -> np.ndarray:
    """``(n, k)`` lower bounds of the distance between the legs of each ``leg_pairs`` row over each cell.

    Leg i's points are b_i + s l_i, s in [0, 1], with l_i = l_i(c) + G_i u + e_i, |u_g| <= 1 (the cell's
    coefficients, the same u for every leg: the pose is shared) and |e_i| <= r_i. For a point s on leg i and t on
    leg j and a unit n, n·(y_j − y_i) = n·(b_j − b_i) + t n·l_j(c) − s n·l_i(c) + Σ_g (t n·g_j − s n·g_i) u_g
    + n·(t e_j − s e_i) >= n·(b_j − b_i) + t n·l_j(c) − s n·l_i(c) − Σ_g |t n·g_j − s n·g_i| − t r_j − s r_i,
    and the distance is at least that. Cut s and t into ``PIECES`` intervals; on a pair of pieces the right side
    is concave in (s, t), so its minimum is at one of the four corners. n: the unit vector between the closest
    points of the two centre-pose pieces (any n gives a valid bound; this one separates the pieces' difference set,
    a convex parallelogram, from the origin at their distance, so at a zero-width cell the bound is the distance).
    The bound is the least over the piece pairs.

    That bound does not tend to the distance as the cell shrinks (the pieces and their directions n stay fixed), so
    the larger of it and a second one is taken: the exact segment distance at the centre pose minus how far the two
    plate anchors can move over the cell (``move`` (n, 6), m). Leg i is the segment from its fixed base anchor to its
    plate anchor; moving the plate anchor by ε moves the point at parameter s by s ε <= ε, so the distance between two
    legs changes by at most ε_i + ε_j (the bound is first order in the cell and tends to the distance)."""
    pairs = leg_pairs(platform)
    if not len(pairs):
        return np.full((len(P_c), 1), np.inf)
    out = np.empty((len(P_c), len(pairs)))
    for s in range(0, len(P_c), 256):
        out[s : s + 256] = _clearance_chunk(platform, pairs, P_c[s : s + 256], G[s : s + 256], r2[s : s + 256])
    i, j = pairs[:, 0], pairs[:, 1]
    B = platform.base_anchors
    centre = np.linalg.norm(segment_gaps(B[i], P_c[:, i], B[j], P_c[:, j]), axis=-1)  # (n, k)
    return np.maximum(out, centre - move[:, i] - move[:, j] - FP_SLACK)


def _clearance_chunk(platform: Platform, pairs, P_c, G, r2) -> np.ndarray:
    i, j = pairs[:, 0], pairs[:, 1]
    B = platform.base_anchors
    edges = np.linspace(0.0, 1.0, PIECES + 1)
    s0, s1 = edges[:-1], edges[1:]
    lc = P_c - B  # (n, 6, 3) centre leg vectors
    ends = [B[leg][None, :, None] + e[None, None, :, None] * lc[:, leg][:, :, None] for leg in (i, j) for e in (s0, s1)]
    a0, a1, b0, b1 = (x[:, :, :, None] if k < 2 else x[:, :, None, :] for k, x in enumerate(ends))  # (n, k, m|1, ...)
    v = -segment_gaps(*np.broadcast_arrays(a0, a1, b0, b1))  # (n, k, m, m, 3): between the pieces' closest points
    norm = np.linalg.norm(v, axis=-1)
    n = v / np.where(norm > 0, norm, 1.0)[..., None]
    Ai = np.einsum("nkabx,nkxg->nkabg", n, G[:, i])  # n·g for leg i's generators (shared coefficients u)
    Aj = np.einsum("nkabx,nkxg->nkabg", n, G[:, j])
    ci = np.einsum("nkabx,nkx->nkab", n, lc[:, i])
    cj = np.einsum("nkabx,nkx->nkab", n, lc[:, j])
    base = np.einsum("nkabx,kx->nkab", n, B[j] - B[i])
    a0, a1 = s0[None, None, :, None], s1[None, None, :, None]
    b0, b1 = s0[None, None, None, :], s1[None, None, None, :]
    ball = a1 * r2[:, i][:, :, None, None] + b1 * r2[:, j][:, :, None, None]
    g = np.full(ci.shape, np.inf)
    for sa in (a0, a1):  # the bound is concave in (s, t): its minimum over the piece pair is at a corner
        for tb in (b0, b1):
            spread = np.sum(np.abs(tb[..., None] * Aj - sa[..., None] * Ai), -1)
            g = np.minimum(g, base + tb * cj - sa * ci - spread)
    gap = np.where(norm > 0, g - ball, -np.inf)
    return gap.min(axis=(2, 3)) - FP_SLACK


def cones_ok(b: CellBounds, cone: float) -> np.ndarray:
    """``(n,)`` cells on which every leg is within ``cone`` (rad) of the base normal and of the plate normal:
    l·a >= |l| cos(cone) for both axes a, from the lower bounds of l·a and the bounds of |l|."""
    cos = np.cos(cone)
    need = np.maximum(cos * b.upper, cos * b.lower)
    return np.all(b.axial_lower >= need, -1) & np.all(b.normal_lower >= need, -1)


@dataclass
class ProofResult:
    """The outcome for a box: ``status`` "proven" | "violated" | "unresolved"; cells examined and proven; the
    rigorous leg-length range over the box when proven (``length_bounds`` m); the least stroke margin and
    anchor height proven; a ``witness`` (pose, leg, what) when violated; when unresolved, the cells left
    (``unresolved_count``, the first 20 as lo, hi pairs in ``unresolved_cells``), their share of the box's volume
    and why the proof ``stopped`` (``"cap"``: ``max_cells`` reached; ``"stalled"``: the volume left stopped
    shrinking)."""

    status: str
    box_lo: np.ndarray
    box_hi: np.ndarray
    cells_examined: int
    cells_proven: int
    max_cells: int
    length_bounds: list = field(default_factory=list)
    stroke_margin_m: float | None = None
    min_anchor_height_m: float | None = None
    witness: dict | None = None
    unresolved_cells: list = field(default_factory=list)
    unresolved_count: int = 0
    unresolved_volume: float = 0.0
    stopped: str | None = None
    seconds: float = 0.0
    method: str = "zonotope enclosure of the leg vectors with a derived Taylor remainder, rounding widened by 1e-9 m"

    def to_dict(self) -> dict:
        """JSON-able form (metres, radians)."""
        return {
            "status": self.status,
            "box_lo": self.box_lo.tolist(),
            "box_hi": self.box_hi.tolist(),
            "cells_examined": self.cells_examined,
            "cells_proven": self.cells_proven,
            "max_cells": self.max_cells,
            "length_bounds_m": self.length_bounds,
            "stroke_margin_m": self.stroke_margin_m,
            "min_anchor_height_m": self.min_anchor_height_m,
            "witness": self.witness,
            "unresolved_count": self.unresolved_count,
            "unresolved_volume": self.unresolved_volume,
            "stopped": self.stopped,
            "unresolved_cells": self.unresolved_cells,
            "seconds": self.seconds,
            "method": self.method,
        }


def _witness(
    platform: Platform, poses, convention: str, cone: float | None = None, diameter: float | None = None
) -> dict | None:
    """The first pose among ``poses`` (m, 6) that the toolkit's IK finds outside the stroke (by more than
    FP_SLACK), with a plate anchor at or below the base, or (``cone``) with a joint beyond its cone by more
    than 1e-9 rad (``workspace.limits``' joint angles); None if all are fine."""
    if cone is not None:
        m = limit_margins(platform, poses, Limits(stroke=False, base_cone=cone, top_cone=cone), convention)
        for name in ("base_joint", "top_joint"):
            margin, leg = m[name]
            if np.any(margin < -1e-9):
                k = int(np.argmax(margin < -1e-9))
                return {
                    "pose": poses[k].tolist(),
                    "leg": int(leg[k]) + 1,
                    "length_m": float(leg_lengths(platform, poses[k], convention)[leg[k]]),
                    "anchor_height_m": float(plate_anchor_heights(platform, poses[k], convention)[leg[k]]),
                    "what": f"{name.replace('_', ' ')} beyond its cone by {np.degrees(-margin[k]):.6f} deg",
                }
    if diameter is not None:
        margin, row = limit_margins(platform, poses, Limits(stroke=False, leg_diameter=diameter), convention)[
            "collision"
        ]
        if np.any(margin < -1e-9):
            k = int(np.argmax(margin < -1e-9))
            a, b = leg_pairs(platform)[row[k]]
            return {
                "pose": poses[k].tolist(),
                "leg": int(a) + 1,
                "length_m": float(leg_lengths(platform, poses[k], convention)[a]),
                "anchor_height_m": float(plate_anchor_heights(platform, poses[k], convention)[a]),
                "what": f"legs {a + 1} and {b + 1} closer than the leg diameter by {-margin[k] * 1e3:.6f} mm",
            }
    L = leg_lengths(platform, poses, convention)
    z = plate_anchor_heights(platform, poses, convention)
    below = L < platform.L_min - FP_SLACK
    above = L > platform.L_max + FP_SLACK
    low = (z <= 0.0) & (not platform.plate_below_base_allowed)
    bad = below | above | low
    if not bad.any():
        return None
    k, leg = np.argwhere(bad)[0]
    what = (
        "below the stroke"
        if below[k, leg]
        else "above the stroke"
        if above[k, leg]
        else "plate anchor at or below the base"
    )
    return {
        "pose": poses[k].tolist(),
        "leg": int(leg) + 1,
        "length_m": float(L[k, leg]),
        "anchor_height_m": float(z[k, leg]),
        "what": what,
    }


def initial_cells(platform: Platform, lo, hi, initial: int | None = None) -> Cells:
    """The box [lo, hi] ((6,) m, rad) cut into cells: ``initial`` splits per angle axis (default: cells of about
    5°), positions whole."""
    lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
    splits = np.ones(6, dtype=int)
    width = hi - lo
    splits[3:] = np.maximum(1, np.ceil(width[3:] / np.radians(5.0)).astype(int)) if initial is None else initial
    splits[3:] = np.where(width[3:] > 0, splits[3:], 1)
    axes = [(lo[j] + (np.arange(splits[j]) + 0.5) * width[j] / splits[j]) for j in range(6)]
    c = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 6)
    return Cells(c, np.broadcast_to(width / (2 * splits), c.shape).copy())


def split_cells(platform: Platform, cells: Cells) -> Cells:
    """Each cell halved across its widest side (positions in metres, angles times the plate's anchor radius):
    twice as many cells covering the same poses."""
    rmax = float(np.max(np.linalg.norm(platform.top_anchors - platform.rotation_centre, axis=1)))
    scale = np.r_[np.ones(3), np.full(3, max(rmax, 1e-9))]
    j = np.argmax(cells.h * scale, axis=1)
    rows = np.arange(len(cells))
    h2 = cells.h.copy()
    h2[rows, j] /= 2
    halves = []
    for sgn in (-1.0, 1.0):
        c2 = cells.c.copy()
        c2[rows, j] += sgn * h2[rows, j]
        halves.append(c2)
    return Cells(np.concatenate(halves), np.concatenate([h2, h2]))


def prove_box(
    platform: Platform,
    lo,
    hi,
    convention: str = "utn",
    max_cells: int = MAX_CELLS,
    initial: int | None = None,
    joint_cone: float | None = None,
    leg_diameter: float | None = None,
) -> ProofResult:
    """Prove that every pose in the box [lo, hi] (absolute, (6,) m and rad) is within the stroke with the
    plate above the base (and, with ``joint_cone`` (rad), every leg within that angle of the base normal and
    of the plate normal at its joints), or find a witness pose that is not, or give up (unresolved) when the
    ``CellBudget`` runs out: at ``max_cells`` cells, or earlier when the volume left stops shrinking. ``initial``: splits per angle axis to start with (default: cells of about 5°)."""
    check_convention(convention)
    t0 = time.perf_counter()
    lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
    pending = initial_cells(platform, lo, hi, initial)
    examined = proven = 0
    lmin_b, lmax_b, margin, zmin = np.inf, -np.inf, np.inf, np.inf
    budget = CellBudget(max_cells, lo, hi)
    while len(pending):
        if not budget.allows(examined, pending):
            left = pending
            cells = [[(cc - hh).tolist(), (cc + hh).tolist()] for cc, hh in zip(left.c[:20], left.h[:20], strict=True)]
            return ProofResult(
                "unresolved", lo, hi, examined, proven, max_cells, unresolved_cells=cells,
                unresolved_count=len(left), unresolved_volume=unresolved_volume(left, lo, hi),
                stopped=budget.stopped, seconds=time.perf_counter() - t0,
            )  # fmt: skip
        nxt_c, nxt_h = [], []
        for s in range(0, len(pending), BATCH):
            cells = Cells(pending.c[s : s + BATCH], pending.h[s : s + BATCH])
            b = cell_bounds(platform, cells, convention, joint_cone is not None, leg_diameter is not None)
            z_ok = np.all(b.z_lower > 0, -1) | platform.plate_below_base_allowed
            ok = np.all(b.lower >= platform.L_min, -1) & np.all(b.upper <= platform.L_max, -1) & z_ok
            if joint_cone is not None:
                ok &= cones_ok(b, joint_cone)
            if leg_diameter is not None:
                ok &= np.all(b.clearance_lower >= leg_diameter, -1)
            examined += len(cells)
            proven += int(ok.sum())
            if ok.any():
                lmin_b = min(lmin_b, float(b.lower[ok].min()))
                lmax_b = max(lmax_b, float(b.upper[ok].max()))
                margin = min(
                    margin, float(b.lower[ok].min() - platform.L_min), float(platform.L_max - b.upper[ok].max())
                )
                zmin = min(zmin, float(b.z_lower[ok].min()))
            bad = ~ok
            if not bad.any():
                continue
            cand = np.concatenate([cells.c[bad][:, None, :], b.lower_pose[bad], b.upper_pose[bad]], axis=1).reshape(
                -1, 6
            )
            w = _witness(platform, np.clip(cand, lo, hi), convention, joint_cone, leg_diameter)  # cells overlap the box
            if w is not None:
                return ProofResult(
                    "violated", lo, hi, examined, proven, max_cells, witness=w, seconds=time.perf_counter() - t0
                )
            halves = split_cells(platform, Cells(cells.c[bad], cells.h[bad]))
            nxt_c.append(halves.c)
            nxt_h.append(halves.h)
        pending = (
            Cells(np.concatenate(nxt_c), np.concatenate(nxt_h)) if nxt_c else Cells(np.zeros((0, 6)), np.zeros((0, 6)))
        )
    return ProofResult(
        "proven",
        lo,
        hi,
        examined,
        proven,
        max_cells,
        length_bounds=[lmin_b, lmax_b],
        stroke_margin_m=margin,
        min_anchor_height_m=zmin,
        seconds=time.perf_counter() - t0,
    )


def prove_requirements_box(platform: Platform, box_lo, box_hi, convention: str = "utn", **kw) -> ProofResult:
    """``prove_box`` for a box given relative to the platform's home pose (keywords ``joint_cone``, ``max_cells``,
    ``initial`` as there)."""
    home = platform.home_pose()
    return prove_box(platform, home + np.asarray(box_lo), home + np.asarray(box_hi), convention, **kw)
