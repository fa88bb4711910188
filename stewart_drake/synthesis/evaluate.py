"""One design's metrics against the requirements, and the search's objectives and constraints.

For a design vector x (SI, the family's variables) and the requirements' box (relative to home):

- leg-length range over the box: the angles on a grid of ``ANGLE_SAMPLES`` values per axis, and for each
  orientation the exact extremes over the whole translation box (|l| over a box of p is extreme where each
  coordinate is extreme or clamped): a sample in the angles, exact in the position. The design's stroke is
  that range widened by ``stroke_margin`` at each end (``stroke_ratio`` requirements), or the fixed stroke;
  the proof (``synthesis.proof``) then covers every pose of the chosen design;
- sizing: peak leg force and speed over the box's vertices and centre × the motion envelope, each pose by
  the exact envelope method (``design.envelope.envelope_sizing``);
- lowest natural frequency (``design.maps.lowest_frequency`` of the loaded stiffness and the plate's
  inertia) and worst scaled condition number of J⁻¹ at the same poses.

Each constraint g is normalised so that g <= 0 means met (pymoo's convention).
"""

from __future__ import annotations

import numpy as np

from stewart_drake.core.kinematics import condition_number, leg_vectors
from stewart_drake.core.rotations import rotation_matrix
from stewart_drake.design.envelope import Envelope, envelope_sizing, spatial_inertia_about_C
from stewart_drake.design.maps import lowest_frequency
from stewart_drake.design.stiffness import stiffness_matrix
from stewart_drake.errors import StewartError
from stewart_drake.synthesis.families import anchors, base_radius, design_platform, home_height
from stewart_drake.synthesis.requirements import OBJECTIVES
from stewart_drake.workspace.limits import leg_pairs, segment_distances

ANGLE_SAMPLES = 5  # per angle axis, for the leg-length range
INFEASIBLE_F = 1e9  # objective of a design that cannot be evaluated (invalid geometry, singular pose)
INFEASIBLE_G = 1e3
CONSTRAINTS = (
    "force",
    "speed",
    "stroke",
    "base_radius",
    "frequency",
    "condition",
    "above_base",
    "joint_cone",
    "clearance",
)
METRICS = (
    "peak_force",
    "peak_speed",
    "L_min",
    "L_max",
    "stroke",
    "stroke_ratio",
    "base_radius",
    "frequency",
    "condition",
    "min_anchor_height",
    "max_joint_angle",
    "min_leg_distance",
)


def box_vertices(lo, hi) -> np.ndarray:
    """``(m, 6)`` the box's vertices (axes of zero width once) and its centre."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    axes = [np.unique([lo[j], hi[j]]) for j in range(6)]
    v = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 6)
    return np.concatenate([v, (0.5 * (lo + hi))[None]], 0)


def joint_angles(l, R) -> np.ndarray:
    """``(..., 6)`` the larger of each leg's angles (rad) to the base normal e_z and to the plate normal R e_z
    (the joint cones of ``workspace.limits``) for leg vectors l (..., 6, 3) and rotations R (..., 3, 3)."""
    u = l / np.linalg.norm(l, axis=-1)[..., None]
    base = np.arccos(np.clip(u[..., 2], -1.0, 1.0))
    top = np.arccos(np.clip(np.einsum("...li,...i->...l", u, R[..., :, 2]), -1.0, 1.0))
    return np.maximum(base, top)


def leg_clearance(platform, poses, convention: str = "utn") -> np.ndarray:
    """``(n,)`` the smallest distance (m) between the axes of two legs that can touch (``workspace.limits``'
    ``leg_pairs`` and ``segment_distances``) at each pose; inf when no pair can."""
    pairs = leg_pairs(platform)
    if not len(pairs):
        return np.full(len(poses), np.inf)
    B = platform.base_anchors
    P = B + leg_vectors(platform, poses, convention)
    i, j = pairs[:, 0], pairs[:, 1]
    return segment_distances(B[i], P[:, i], B[j], P[:, j]).min(-1)


def leg_range(req, x) -> tuple[float, float, float]:
    """``(L_low, L_high, z_low)`` over the box: leg lengths (m) and the lowest plate anchor height (m), the
    angles sampled (``ANGLE_SAMPLES`` per axis) and the position exact (see the module docstring)."""
    base, top, leg_top = anchors(req.family, x)
    t = top[leg_top]
    h = home_height(req.family, x)
    axes = [
        np.linspace(req.box_lo[j], req.box_hi[j], ANGLE_SAMPLES if req.box_hi[j] > req.box_lo[j] else 1)
        for j in range(3, 6)
    ]
    ang = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3)
    R = rotation_matrix(ang, req.convention)
    q = np.einsum("nij,lj->nli", R, t)  # (n, 6, 3)
    w = q - base  # l = p + w
    plo = req.box_lo[:3] + np.array([0.0, 0.0, h])
    phi = req.box_hi[:3] + np.array([0.0, 0.0, h])
    far = np.maximum(np.abs(plo + w), np.abs(phi + w))
    near = np.maximum(0.0, np.maximum(plo + w, -(phi + w)))  # distance of −w to [plo, phi] per coordinate
    L_high = float(np.sqrt(np.sum(far**2, -1)).max())
    L_low = float(np.sqrt(np.sum(near**2, -1)).min())
    z_low = float((plo[2] + q[..., 2]).min())
    return L_low, L_high, z_low


def design_stroke(req, L_low: float, L_high: float) -> np.ndarray:
    """``(2,)`` the design's stroke: the fixed one, or the needed range widened by the margin."""
    if req.stroke is not None:
        return req.stroke.copy()
    return np.array([max(L_low - req.stroke_margin, 1e-6), L_high + req.stroke_margin])


def evaluate_design(req, x) -> dict:
    """Metrics (``METRICS``; SI) of design ``x``, its constraint values ``g`` (``CONSTRAINTS``, <= 0 met) and
    objectives ``f`` (minimised; a maximised metric negated). ``error`` names why a design could not be
    evaluated (then f and g are large)."""
    x = np.asarray(x, dtype=float)
    out = {"x": x.tolist(), "error": None}
    try:
        L_low, L_high, z_low = leg_range(req, x)
        stroke = design_stroke(req, L_low, L_high)
        # the metrics on the stroke the box needs (a fixed stroke too short is the stroke constraint's concern)
        platform = design_platform(req, x, [max(L_low - req.stroke_margin, 1e-6), L_high + req.stroke_margin])
        poses = box_vertices(req.box_lo, req.box_hi) + platform.home_pose()
        env = Envelope(poses, req.v_max, req.a_max, req.convention, "requirements box")
        sizing = envelope_sizing(platform, env)
        K = stiffness_matrix(platform, poses, req.stiffness, req.convention)
        M = spatial_inertia_about_C(platform, rotation_matrix(poses[:, 3:], req.convention))
        freq = float(lowest_frequency(K, M).min())
        cond = float(condition_number(platform, poses, req.convention).max())
        gap = float(leg_clearance(platform, poses, req.convention).min())
        joint = float(
            joint_angles(
                leg_vectors(platform, poses, req.convention), rotation_matrix(poses[:, 3:], req.convention)
            ).max()
        )
    except (StewartError, np.linalg.LinAlgError) as e:
        out.update({k: None for k in METRICS})
        out.update(error=str(e).splitlines()[0][:200], f=[INFEASIBLE_F] * len(req.objectives))
        out["g"] = [INFEASIBLE_G] * len(CONSTRAINTS)
        return out
    m = {
        "peak_force": float(sizing.peak_force.max()),
        "peak_speed": float(sizing.peak_speed.max()),
        "L_min": float(stroke[0]),
        "L_max": float(stroke[1]),
        "stroke": float(stroke[1] - stroke[0]),
        "stroke_ratio": float(stroke[1] / stroke[0]),
        "base_radius": base_radius(req.family, x),
        "frequency": freq,
        "condition": cond,
        "min_anchor_height": z_low,
        "max_joint_angle": joint,
        "min_leg_distance": gap,
        "L_needed": [L_low, L_high],
    }
    out.update(m)
    out["g"] = constraint_values(req, m, home_height(req.family, x))
    out["f"] = objective_values(req, m)
    return out


def constraint_values(req, m: dict, home: float) -> list[float]:
    """The constraints (``CONSTRAINTS``, normalised, <= 0 met) of a design's metrics ``m``; ``home`` its home height (m)."""
    g = {
        "force": m["peak_force"] / req.max_force - 1.0,
        "speed": m["peak_speed"] / req.max_speed - 1.0 if req.max_speed else -1.0,
        "base_radius": m["base_radius"] / req.base_radius_max - 1.0 if req.base_radius_max else -1.0,
        "frequency": 1.0 - m["frequency"] / req.min_frequency_hz if req.min_frequency_hz else -1.0,
        "condition": m["condition"] / req.max_condition - 1.0 if req.max_condition else -1.0,
        "above_base": -m["min_anchor_height"] / max(home, 1e-9),
        "joint_cone": m["max_joint_angle"] / req.joint_cone - 1.0 if req.joint_cone else -1.0,
        "clearance": 1.0 - m["min_leg_distance"] / req.leg_diameter if req.leg_diameter else -1.0,
    }
    L_low, L_high = m["L_needed"]
    if req.stroke is None:
        g["stroke"] = m["stroke_ratio"] / req.stroke_ratio - 1.0
    else:
        s0, s1 = req.stroke
        g["stroke"] = max((s0 - (L_low - req.stroke_margin)) / s0, ((L_high + req.stroke_margin) - s1) / s1)
    return [float(g[k]) for k in CONSTRAINTS]


def objective_values(req, m: dict) -> list[float]:
    """The objectives (minimised; a maximised metric negated) of a design's metrics ``m``."""
    return [OBJECTIVES[o][1] * m[OBJECTIVES[o][0]] for o in req.objectives]
