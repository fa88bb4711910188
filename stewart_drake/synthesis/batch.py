"""The search's evaluation vectorised over a batch of designs as well as over the box's poses.

``evaluate.evaluate_design`` evaluates one design through the project's per-platform functions (envelope
sizing, stiffness, frequency, condition); most of its time is numpy's per-call overhead. Here the same
quantities are computed for D designs × P poses at once, with the same formulas and the same library pieces:

- the payload's wrench terms depend on the orientation only (``design.envelope.plate_wrench_terms``), so they
  are computed once per pose and solved against each design's J⁻ᵀ: F = c + G [a_C; ω̇] + ωᵀ Q ω, the worst case
  over the motion envelope exact by ``design.boxquad.box_quadratic_max`` (the envelope method);
- the loaded stiffness K = Aᵀ diag(k) A − Σ F_i ∂a_i/∂x − ∂w_g/∂x (``design.stiffness``'s expression) with
  the static forces F = c, the inertia M_C (``design.envelope.spatial_inertia_about_C``) and
  ``design.maps.lowest_frequency``;
- the scaled condition number (``core.kinematics.scaled_jacobian``, ``singular_value_condition``).

A test checks every metric against ``evaluate_design`` (the per-platform functions) to 1e-9 relative.
"""

from __future__ import annotations

import numpy as np

from stewart_drake.core.dynamics import G_EARTH, skew
from stewart_drake.core.kinematics import scaled_jacobian, singular_value_condition
from stewart_drake.core.rotations import rotation_matrix
from stewart_drake.design.boxquad import box_quadratic_max
from stewart_drake.design.envelope import MAX_CONDITION, plate_wrench_terms, spatial_inertia_about_C
from stewart_drake.design.maps import lowest_frequency
from stewart_drake.design.stiffness import geometric_load_term
from stewart_drake.errors import StewartError
from stewart_drake.synthesis.evaluate import (
    ANGLE_SAMPLES,
    CONSTRAINTS,
    INFEASIBLE_F,
    INFEASIBLE_G,
    METRICS,
    box_vertices,
    constraint_values,
    design_stroke,
    joint_angles,
    objective_values,
)
from stewart_drake.synthesis.families import anchors, design_platform
from stewart_drake.workspace.limits import leg_pairs, segment_distances

SINGULAR = "a pose of the box is singular or nearly so (scaled condition number above {limit:g})"


def leg_ranges(req, base, top, h) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(L_low, L_high, z_low)`` (D,) for designs with per-leg anchors ``base``/``top`` (D, 6, 3) and home
    heights ``h`` (D,): as ``evaluate.leg_range`` (angles sampled, position exact)."""
    axes = [
        np.linspace(req.box_lo[j], req.box_hi[j], ANGLE_SAMPLES if req.box_hi[j] > req.box_lo[j] else 1)
        for j in range(3, 6)
    ]
    R = rotation_matrix(np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3), req.convention)
    q = np.einsum("aij,dlj->dali", R, top)  # (D, n, 6, 3)
    w = q - base[:, None]
    up = np.array([0.0, 0.0, 1.0])
    plo = (req.box_lo[:3] + h[:, None] * up)[:, None, None]
    phi = (req.box_hi[:3] + h[:, None] * up)[:, None, None]
    far = np.maximum(np.abs(plo + w), np.abs(phi + w))
    near = np.maximum(0.0, np.maximum(plo + w, -(phi + w)))
    L_high = np.sqrt(np.sum(far**2, -1)).max(axis=(1, 2))
    L_low = np.sqrt(np.sum(near**2, -1)).min(axis=(1, 2))
    z_low = (plo[..., 2] + q[..., 2]).min(axis=(1, 2))
    return L_low, L_high, z_low


_POSE_TERMS: dict = {}  # per process: the terms of the last requirements seen (a search's every batch)


def pose_terms(req, payload, gravity: float = G_EARTH) -> tuple:
    """``(rel (P, 6), R (P, 3, 3), wrench terms (P, 6, 16), M_C (P, 6, 6))`` at the box's vertices and centre: they
    depend on the box, the convention and the payload only, not on the design, so each process computes them once
    per requirements (a fixed per-batch cost otherwise: small batches, as on several workers, paid it each time)."""
    key = (
        req.box_lo.tobytes(),
        req.box_hi.tobytes(),
        req.convention,
        float(payload.mass),
        payload.com.tobytes(),
        payload.inertia.tobytes(),
        payload.rotation_centre.tobytes(),
        gravity,
    )
    hit = _POSE_TERMS.get(key)
    if hit is None:
        rel = box_vertices(req.box_lo, req.box_hi)
        R = rotation_matrix(rel[:, 3:], req.convention)
        hit = (rel, R, plate_wrench_terms(payload, R, gravity), spatial_inertia_about_C(payload, R))
        _POSE_TERMS.clear()
        _POSE_TERMS[key] = hit
    return hit


def evaluate_designs(req, X, gravity: float = G_EARTH) -> list[dict]:
    """``[evaluate_design(req, x) for x in X]`` computed for the whole batch at once (same metrics, f, g)."""
    X = np.atleast_2d(np.asarray(X, dtype=float))
    out = [{"x": x.tolist(), "error": None} for x in X]
    good, plats = [], []
    for k, x in enumerate(X):
        try:
            plats.append(design_platform(req, x, [1.0, 2.0]))  # the anchors' own checks (stroke set below)
            good.append(k)
        except StewartError as e:
            _infeasible(req, out[k], str(e))
    if not good:
        return out
    geo = [anchors(req.family, X[k]) for k in good]
    base = np.stack([b for b, _, _ in geo])
    top = np.stack([t[lt] for _, t, lt in geo])  # per leg, relative to the rotation centre (the plate origin)
    h = X[good, -1]
    L_low, L_high, z_low = leg_ranges(req, base, top, h)
    rel, R, rhs, M = pose_terms(req, plats[0], gravity)
    p = rel[None, :, :3] + h[:, None, None] * np.array([0.0, 0.0, 1.0])  # (D, P, 3)
    r = np.einsum("pij,dlj->dpli", R, top)  # (D, P, 6, 3)
    l = p[:, :, None] + r - base[:, None]
    L = np.linalg.norm(l, axis=-1)
    u = l / L[..., None]
    A = np.concatenate([u, np.cross(r, u)], -1)  # J⁻¹ (D, P, 6, 6)
    scale = np.linalg.norm(top, axis=-1).max(-1)[:, None, None, None]
    cond = singular_value_condition(np.linalg.svd(scaled_jacobian(A, scale), compute_uv=False)).max(-1)
    ok = cond <= MAX_CONDITION
    for k in np.flatnonzero(~ok):
        _infeasible(req, out[good[k]], SINGULAR.format(limit=MAX_CONDITION))
    if not ok.any():
        return out
    A, u, r, L, base, top, h = A[ok], u[ok], r[ok], L[ok], base[ok], top[ok], h[ok]
    idx = [good[k] for k in np.flatnonzero(ok)]
    payload = plats[0]
    Xs = np.linalg.solve(np.swapaxes(A, -1, -2), np.broadcast_to(rhs, A.shape[:2] + rhs.shape[1:]))
    c, G, Q = Xs[..., 0], Xs[..., 1:7], Xs[..., 7:].reshape(Xs.shape[:-1] + (3, 3))
    vel = np.flatnonzero(req.v_max[3:] > 0)
    Qv = Q[..., vel, :][..., :, vel]
    qmax, _ = box_quadratic_max(Qv, req.v_max[3:][vel])
    qmin, _ = box_quadratic_max(-Qv, req.v_max[3:][vel])
    lin = np.abs(G) @ req.a_max
    peak = np.maximum(c + lin + qmax, -(c - lin - qmin)).max(axis=(1, 2))
    speed = (np.abs(A) @ req.v_max).max(axis=(1, 2))
    # loaded stiffness about C (design.stiffness.stiffness_matrix's expression) and the lowest frequency
    K = np.einsum("dpki,dpkj->dpij", A * req.stiffness, A)
    K = K - geometric_load_term(c, u, r, L)
    r_cm = np.einsum("pij,j->pi", R, payload.com - payload.rotation_centre)
    f_g = np.broadcast_to(np.array([0.0, 0.0, -payload.mass * gravity]), r_cm.shape)
    K[..., 3:, 3:] -= skew(f_g) @ skew(r_cm)
    freq = lowest_frequency(K, np.broadcast_to(M, K.shape)).min(-1)
    radius = np.hypot(base[..., 0], base[..., 1]).max(-1)
    joint = joint_angles(l[ok], np.broadcast_to(R, l[ok].shape[:2] + (3, 3))).max(axis=(1, 2))
    gap = _clearances(l[ok], base, [plats[good.index(k)] for k in idx])
    for n, k in enumerate(idx):
        lo, hi = float(L_low[good.index(k)]), float(L_high[good.index(k)])
        stroke = design_stroke(req, lo, hi)
        m = {
            "peak_force": float(peak[n]),
            "peak_speed": float(speed[n]),
            "L_min": float(stroke[0]),
            "L_max": float(stroke[1]),
            "stroke": float(stroke[1] - stroke[0]),
            "stroke_ratio": float(stroke[1] / stroke[0]),
            "base_radius": float(radius[n]),
            "frequency": float(freq[n]),
            "condition": float(cond[ok][n]),
            "min_anchor_height": float(z_low[good.index(k)]),
            "max_joint_angle": float(joint[n]),
            "min_leg_distance": float(gap[n]),
            "L_needed": [lo, hi],
        }
        out[k].update(m)
        out[k]["g"] = constraint_values(req, m, float(h[n]))
        out[k]["f"] = objective_values(req, m)
    return out


def _clearances(l, base, platforms) -> np.ndarray:
    """``(D,)`` the smallest distance (m) between two legs that can touch, over the poses: every pair of legs
    at once (``segment_distances``), masked by each design's ``leg_pairs``."""
    i, j = np.triu_indices(6, 1)
    P = base[:, None] + l  # (D, P, 6, 3) plate anchors
    b = np.broadcast_to(base[:, None], P.shape)
    d = segment_distances(b[:, :, i], P[:, :, i], b[:, :, j], P[:, :, j]).min(1)  # (D, 15)
    mask = np.zeros((len(platforms), 15), bool)
    for k, plat in enumerate(platforms):
        rows = {tuple(r) for r in leg_pairs(plat).tolist()}
        mask[k] = [(a, c) in rows for a, c in zip(i.tolist(), j.tolist(), strict=True)]
    return np.where(mask, d, np.inf).min(-1)


def _infeasible(req, row: dict, why: str) -> None:
    row.update({k: None for k in METRICS})
    row.update(error=why.splitlines()[0][:200], f=[INFEASIBLE_F] * len(req.objectives))
    row["g"] = [INFEASIBLE_G] * len(CONSTRAINTS)
