"""A proof of the actuator and dexterity requirements over a pose box: peak leg force and speed over the box ×
the motion envelope, the lowest natural frequency and the worst condition number. Not a sample.

The box is covered by cells (``proof.Cells``, the same start and split rule as ``proof.prove_box``). On a cell with
centre c and half-widths h (position h_p, angles h_θ), with leg i's plate anchor t_i (relative to C), r_i = R t_i,
l_i = p + r_i − b_i, u_i = l_i/|l_i| and J⁻¹'s rows a_i = [u_i; r_i × u_i] (``A``), every bound below is derived:

- ‖R(θ) − R(c)‖₂ <= ε_R = Σ_j h_θ,j (each elementary rotation is 1-Lipschitz in its angle in the 2-norm, and a
  product of rotations adds the factors' differences);
- |r_i − r_i(c)| <= e_r = min(ε_R |t_i|, Σ_j |∂r_i/∂θ_j| h_θ,j + ½ |t_i| ‖h_θ‖₁²) (``proof``'s Taylor constant);
  |l_i − l_i(c)| <= e_l = |h_p| + e_r;
- |u_i − u_i(c)| <= e_u = min(2 e_l / |l_i(c)|, e_l / (|l_i(c)| − e_l)) (from a/|a| − b/|b| = (a − b)/|b|
  + a (1/|a| − 1/|b|), and normalising is 1-Lipschitz outside the unit ball); |r_i × u_i − r_i(c) × u_i(c)| <= e_w
  = e_r + |t_i| e_u;
- everything is done in the scaled J⁻¹ A_s = A D, D = diag(1, 1, 1, 1/s, 1/s, 1/s) (s the anchor radius, as
  ``core.kinematics.condition_number``): row i changes by at most ε_i = (e_u² + (e_w/s)²)^½ and
  ‖A_s(x) − A_s(c)‖₂ <= δ = (Σ_i ε_i²)^½ (the Frobenius norm); σ_min, σ_max, β = 1/σ_min are A_s(c)'s.

From these:

- **condition number**: by Weyl's inequalities cond <= (σ_max + δ)/(σ_min − δ);
- **non-singularity**: βδ < 1 proves A_s(x) invertible on the cell, and ‖A_s(x)⁻ᵀ − A_s(c)⁻ᵀ‖₂ <= ΔB = β²δ/(1 − βδ)
  (Neumann series);
- **leg speed** over the velocity box |V_j| <= v_j (``design.envelope``): |a_i·V| <= Σ_j |a_ij(c)| v_j
  + e_u |v_lin| + e_w |v_ang| (Cauchy–Schwarz on the change);
- **leg force** F = A⁻ᵀ w = A_s⁻ᵀ D w, w = w_g + M_C [a_C; ω̇] + H(ω) the plate's wrench (``design.envelope.
  plate_wrench_terms``). F' = A_s(c)⁻ᵀ D w(x) has |F'_i| <= P_i(c) + |b_i(c)| |D Δw| =: near_i, with P_i(c) the exact
  envelope peak at the centre pose (the envelope method), b_i(c) row i of A_s(c)⁻ᵀ and |D Δw| bounded term by term
  (the orientation enters through r_cm = R c_m and I_W = R I Rᵀ: |Δr_cm| <= ε_R |c_m|, ‖ΔI_W‖ <= 2 ε_R ‖I‖). Then
  A_s(x)ᵀ(F − F') = (A_s(c) − A_s(x))ᵀ F' = −Σ_k F'_k Δa_k bounds |F_i − F'_i| by the least of δ/(σ_min − δ) |near|,
  ΔB W (W >= |D w| over the envelope, orientation-free norms) and (|b_i(c)| + ΔB) Σ_k near_k ε_k;
- **lowest natural frequency** of K v = ω² M_C v with K = k AᵀA − Σ_i F_i D_i − [f_g]×[r_cm]× (the loaded
  stiffness of ``design.stiffness``/``synthesis.batch``, F the static leg forces): in y = D⁻¹ v the pencil is
  (k A_sᵀA_s − D G D, D M_C D) with the same eigenvalues. |A_s(x) y| >= |A_s(c) y| − δ|y| >= (1 − βδ) |A_s(c) y|, so
  k A_sᵀA_s(x) ⪰ (1 − βδ)² k A_sᵀA_s(c); ‖D G D‖ <= Σ_i |F_i|max ‖D D_i D‖ + m g |c_m| / s² (|F_i|max as the force,
  ‖D D_i D‖ from its blocks' norms with |l_i| >= |l_i(c)| − e_l); D M_C(x) D ⪯ D M_C(c) D + ε_M 1. With K_lo and M_hi
  those, when the pencil's least eigenvalue λ_lo is >= 0, K_lo ⪰ 0 and vᵀK v / vᵀM v >= vᵀK_lo v / vᵀM_hi v >=
  λ_lo for every v: ω² >= λ_lo (computed by ``design.maps.lowest_frequency``).

Floating point: the centre quantities (SVD, solves, the envelope maximum, the eigenvalues) are computed in binary64;
each bound is widened by a relative ``REL_SLACK`` (1e-9) of its scale times the centre's condition, orders of
magnitude above the backward-error bounds of those factorisations (n·u·κ, u = 1.1e-16, κ <= 1e4 here); a test
checks every bound against 10⁴ poses evaluated by the toolkit's own functions.

A cell is done when each requirement still open is proven on it; otherwise its centre is evaluated (the centre
values are the toolkit's formulas at that pose): a requirement the centre violates gets a witness, confirmed by
the toolkit's per-platform functions (``envelope_sizing``, ``stiffness_matrix`` + ``lowest_frequency``,
``condition_number``), and is closed as ``violated``; the others' cells are halved as in ``proof.prove_box``.
Past ``max_cells`` the requirements still open are ``unresolved``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from stewart_drake.core.dynamics import G_EARTH, skew
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import anchor_radius, condition_number
from stewart_drake.core.rotations import check_convention, rotation_matrix
from stewart_drake.design.boxquad import box_quadratic_max
from stewart_drake.design.envelope import Envelope, envelope_sizing, plate_wrench_terms, spatial_inertia_about_C
from stewart_drake.design.maps import lowest_frequency
from stewart_drake.design.stiffness import geometric_stiffness, stiffness_matrix
from stewart_drake.errors import StewartError
from stewart_drake.synthesis.proof import BATCH, COVER_PAD, Cells, initial_cells, rotation_derivatives, split_cells

REL_SLACK = 1e-9  # relative widening of each bound for rounding (module docstring)
MAX_CELLS = 200_000
TIGHTEN_CELLS = 60_000  # cells examined while bounds that meet their limits are still refined (TIGHT)
TIGHT = 0.1  # bounds within this fraction of the worst centre value seen are tight enough
NAMES = ("force", "speed", "frequency", "condition")
UNITS = {"force": "N", "speed": "m/s", "frequency": "Hz", "condition": ""}


@dataclass
class PerformanceBounds:
    """Per cell ``(n,)`` rigorous bounds: ``force`` (max |F_i| over the cell × envelope, N), ``speed`` (m/s),
    ``frequency`` (a lower bound, Hz), ``condition`` (an upper bound; inf where non-singularity is not proven),
    and the centre pose's own values ``centre_*`` (the toolkit's formulas at c, a sample)."""

    force: np.ndarray
    speed: np.ndarray
    frequency: np.ndarray
    condition: np.ndarray
    centre_force: np.ndarray
    centre_speed: np.ndarray
    centre_frequency: np.ndarray
    centre_condition: np.ndarray


def performance_bounds(
    platform: Platform,
    cells: Cells,
    v_max,
    a_max,
    stiffness: float,
    convention: str = "utn",
    gravity: float = G_EARTH,
) -> PerformanceBounds:
    """Rigorous bounds of peak leg force and speed (over ``v_max``/``a_max`` (6,), SI, the envelope's box), lowest
    natural frequency (leg stiffness ``stiffness`` N/m) and scaled condition number on each cell (the module
    docstring derives them). The plate alone carries mass (legs massless), as the synthesis's evaluation."""
    v_max, a_max = np.asarray(v_max, float), np.asarray(a_max, float)
    c = cells.c
    h = cells.h + COVER_PAD * (1.0 + np.abs(c))
    hp, ht = h[:, :3], h[:, 3:]
    t = platform.top_anchors_per_leg - platform.rotation_centre  # (6, 3)
    tn = np.linalg.norm(t, axis=1)  # (6,)
    R, dR = rotation_derivatives(c[:, 3:], convention)
    r = np.einsum("nij,lj->nli", R, t)  # (n, 6, 3)
    dr = np.einsum("nkij,lj->nlki", dR, t)  # (n, 6, 3 [k], 3)
    eps_R = np.sum(ht, 1)  # (n,)
    taylor = np.einsum("nlk,nk->nl", np.linalg.norm(dr, axis=-1), ht) + 0.5 * tn * eps_R[:, None] ** 2
    e_r = np.minimum(eps_R[:, None] * tn, taylor)  # (n, 6)
    l = c[:, None, :3] + r - platform.base_anchors
    Lc = np.linalg.norm(l, axis=-1)
    u = l / Lc[..., None]
    e_l = np.linalg.norm(hp, axis=1)[:, None] + e_r
    with np.errstate(divide="ignore"):
        e_u = np.minimum(2.0 * e_l / Lc, np.where(Lc > e_l, e_l / (Lc - e_l), 2.0))
    e_w = e_r + tn * e_u
    A = np.concatenate([u, np.cross(r, u)], -1)  # (n, 6, 6) J⁻¹ at the centre
    s = anchor_radius(platform)
    Dg = np.r_[np.ones(3), np.full(3, 1.0 / s)]  # the scaling D: A_s = A D
    As = A * Dg
    delta_s = np.sqrt(np.sum(e_u**2 + (e_w / s) ** 2, -1))
    sig_s = np.linalg.svd(As, compute_uv=False)
    with np.errstate(divide="ignore", invalid="ignore"):
        kappa_c = np.where(sig_s[:, -1] > 0, sig_s[:, 0] / sig_s[:, -1], np.inf)
        slack = REL_SLACK * np.minimum(kappa_c, 1e12)  # (n,) relative rounding widening
        d = delta_s + slack * sig_s[:, 0]
        cond = np.where(sig_s[:, -1] > d, (sig_s[:, 0] + d) / (sig_s[:, -1] - d), np.inf)
        cond_c = kappa_c
        beta = 1.0 / sig_s[:, -1]
        regular = beta * d < 1.0
        dB = np.where(regular, beta**2 * d / np.where(regular, 1.0 - beta * d, 1.0), np.inf)  # ‖ΔA_s⁻ᵀ‖₂
    # speed
    vl, va = np.linalg.norm(v_max[:3]), np.linalg.norm(v_max[3:])
    speed_c = np.abs(A) @ v_max  # (n, 6)
    speed = (speed_c + e_u * vl + e_w * va) * (1.0 + REL_SLACK)
    # force: the exact envelope peak at the centre, plus the orientation's and the Jacobian's changes
    invertible = kappa_c < 1e12  # the centre pose itself (its values are a sample, bounds need ``regular``)
    Binv = np.linalg.inv(np.where(invertible[:, None, None], As, np.eye(6)))  # row i of A_s⁻ᵀ: column i of A_s⁻¹
    b_norm = np.linalg.norm(Binv, axis=-2)  # (n, 6)
    rhs = plate_wrench_terms(platform, R, gravity) * Dg[:, None]  # D w: F = A⁻ᵀ w = A_s⁻ᵀ D w
    X = np.einsum("nji,njk->nik", Binv, rhs)
    cF, G, Q = X[..., 0], X[..., 1:7], X[..., 7:].reshape(X.shape[:-1] + (3, 3))
    vel = np.flatnonzero(v_max[3:] > 0)
    Qv = Q[..., vel, :][..., :, vel]
    qmax, _ = box_quadratic_max(Qv, v_max[3:][vel])
    qmin, _ = box_quadratic_max(-Qv, v_max[3:][vel])
    lin = np.abs(G) @ a_max
    peak_c = np.maximum(cF + lin + qmax, -(cF - lin - qmin))  # (n, 6) exact at the centre
    m = platform.mass
    cm = np.linalg.norm(platform.com - platform.rotation_centre)
    In = np.linalg.norm(platform.inertia, 2)
    al, aa = np.linalg.norm(a_max[:3]), np.linalg.norm(a_max[3:])
    dr_cm = eps_R * cm  # (n,)
    dI = 2.0 * eps_R * In
    dw_f = m * dr_cm * aa + m * va**2 * dr_cm
    dw_t = m * gravity * dr_cm + m * dr_cm * al + (dI + 2 * m * cm * dr_cm) * (aa + va**2)
    dw = np.hypot(dw_f, dw_t / s)  # |D Δw|
    W = np.hypot(
        m * (gravity + al + cm * aa + cm * va**2), (m * cm * (gravity + al) + (In + m * cm**2) * (aa + va**2)) / s
    )  # |D w|
    scale_F = np.abs(cF) + lin + np.maximum(np.abs(qmax), np.abs(qmin))
    # F = A_s(c)⁻ᵀ D w(x) + e with A_s(x)ᵀ e = (A_s(c) − A_s(x))ᵀ A_s(c)⁻ᵀ D w(x): |e| <= δ/(σ_min − δ) |F'|
    near = peak_c + b_norm * dw[:, None]  # |F'_i| over the cell × envelope
    rel = np.where(regular, d / np.where(regular, sig_s[:, -1] - d, 1.0), np.inf)  # δ/(σ_min − δ)
    f_norm = np.minimum(np.linalg.norm(near, axis=-1), beta * W)  # |F'|₂ <= ‖A_s(c)⁻¹‖ |D w| too
    # leg by leg: (A_s(c) − A_s(x))ᵀ F' = Σ_k F'_k Δa_k, |Δa_k| <= ε_k, and row i of A_s(x)⁻ᵀ is within ΔB of b_i(c)
    eps_leg = np.sqrt(e_u**2 + (e_w / s) ** 2)  # (n, 6)
    per_leg = (b_norm + dB[:, None]) * np.sum(near * eps_leg, -1)[:, None]
    jac = np.minimum(np.minimum(rel * f_norm, dB * W)[:, None], per_leg)
    force = near + jac + slack[:, None] * scale_F
    # frequency: K ⪰ k A(c)ᵀA(c) − ε_K 1 and M ⪯ M_C(c) + ε_M 1
    W_g = m * gravity * np.hypot(1.0, cm / s)
    near_g = np.abs(cF) + b_norm * (m * gravity * dr_cm / s)[:, None]
    static = near_g + np.minimum(rel * np.linalg.norm(near_g, axis=-1), dB * W_g)[:, None]  # (n, 6) |F_static| max
    L_lo = Lc - e_l
    with np.errstate(divide="ignore", invalid="ignore"):  # ‖D D_i D‖ from its blocks' norms
        D_norm = np.where(
            L_lo > 0, np.sqrt(1 / L_lo**2 + 2 * (tn / (L_lo * s)) ** 2 + ((tn + tn**2 / L_lo) / s**2) ** 2), np.inf
        )
    g_sup = np.sum(static * D_norm, -1) + m * gravity * cm / s**2
    # the pencil in y = D⁻¹ v: (k A_sᵀA_s − D G D, D M D), the same eigenvalues
    shrink = np.where(regular, 1.0 - d * beta, 0.0) ** 2  # |A v| >= |A_c v| − δ|v| >= (1 − δ/σ_min) |A_c v|
    eps_K = g_sup
    eps_M = np.hypot(np.sqrt(2.0) * m * dr_cm / s, (dI + 2 * m * cm * dr_cm) / s**2)
    K_c = stiffness * np.einsum("nki,nkj->nij", As, As)
    M_c = spatial_inertia_about_C(platform, R)
    M_s = M_c * Dg[:, None] * Dg
    I6 = np.eye(6)
    ok = np.isfinite(eps_K)
    freq = np.zeros(len(c))
    if ok.any():
        widen = slack * stiffness * sig_s[:, 0] ** 2 * _kappa_sym(M_s)
        K_lo = shrink[ok, None, None] * K_c[ok] - (eps_K + widen)[ok, None, None] * I6
        freq[ok] = lowest_frequency(K_lo, M_s[ok] + eps_M[ok, None, None] * I6)
    K_full = stiffness * np.einsum("nki,nkj->nij", A, A) - np.einsum("nk,nkij->nij", cF, geometric_stiffness(u, r, Lc))
    r_cm = np.einsum("nij,j->ni", R, platform.com - platform.rotation_centre)
    K_full[:, 3:, 3:] -= skew(np.broadcast_to([0.0, 0.0, -m * gravity], r_cm.shape)) @ skew(r_cm)
    freq_c = lowest_frequency(K_full, M_c)
    return PerformanceBounds(
        np.where(regular, force.max(-1), np.inf),
        speed.max(-1),
        np.where(regular, freq, 0.0),
        cond,
        np.where(invertible, peak_c.max(-1), np.inf),
        speed_c.max(-1),
        np.where(invertible, freq_c, 0.0),
        cond_c,
    )


def _kappa_sym(M) -> np.ndarray:
    """``(n,)`` the 2-norm condition number of symmetric positive definite (n, 6, 6) M."""
    w = np.linalg.eigvalsh(M)
    return w[:, -1] / w[:, 0]


def sampled_performance(platform: Platform, poses, v_max, a_max, stiffness: float, convention: str = "utn") -> dict:
    """``{name: (m,)}`` the requirements' quantities at poses (m, 6) by the toolkit's per-platform functions:
    peak leg force and speed (``envelope_sizing``, exact over the envelope), lowest frequency (``stiffness_matrix``
    and ``spatial_inertia_about_C`` through ``lowest_frequency``) and ``condition_number``. The independent check."""
    poses = np.atleast_2d(np.asarray(poses, float))
    env = Envelope(poses, np.asarray(v_max, float), np.asarray(a_max, float), convention, "box")
    sz = envelope_sizing(platform, env, stroke=False)
    K = stiffness_matrix(platform, poses, stiffness, convention)
    M = spatial_inertia_about_C(platform, rotation_matrix(poses[:, 3:], convention))
    return {
        "force": sz.peak_force.max(-1),
        "speed": sz.peak_speed.max(-1),
        "frequency": lowest_frequency(K, M),
        "condition": condition_number(platform, poses, convention),
    }


@dataclass
class PerformanceProof:
    """Per requirement (``NAMES`` that were asked): ``status`` proven | violated | unresolved, ``required``,
    ``bound`` (the proven worst over the box: max force/speed/condition, min frequency; over the proven cells when
    not proven), ``sampled`` (the worst of the cells' centres, a sample), ``witness`` (a pose and the toolkit's
    value at it) when violated, ``unresolved`` cells (first 20, lo/hi pairs) when unresolved."""

    results: dict
    cells_examined: int
    max_cells: int
    seconds: float = 0.0
    method: str = field(
        default="Weyl and Neumann bounds of J⁻¹ over each cell, the exact envelope peak at its centre, "
        "derived rotation constants (synthesis.performance)"
    )

    def to_dict(self) -> dict:
        """JSON-able (SI)."""
        return {
            "requirements": self.results,
            "cells_examined": self.cells_examined,
            "max_cells": self.max_cells,
            "seconds": self.seconds,
            "method": self.method,
        }

    @property
    def ok(self) -> bool:
        return all(r["status"] == "proven" for r in self.results.values())


def prove_performance(
    platform: Platform,
    lo,
    hi,
    limits: dict,
    v_max,
    a_max,
    stiffness: float,
    convention: str = "utn",
    max_cells: int = MAX_CELLS,
    initial: int | None = None,
    tighten_cells: int = TIGHTEN_CELLS,
) -> PerformanceProof:
    """Prove the ``limits`` (``{"force": N, "speed": m/s, "frequency": Hz, "condition": x}``, any subset; force,
    speed and condition are upper limits, frequency a lower one) over every pose of the box [lo, hi] (absolute,
    (6,) m and rad) × the motion envelope, find a witness pose against one, or give up after ``max_cells`` cells
    (see the module docstring). While fewer than ``tighten_cells`` cells have been examined, a cell whose bound
    meets a limit but exceeds the worst centre value seen by more than ``TIGHT`` (relative) is split too (branch
    and bound), so that the reported bound is close to the box's worst rather than merely within the limit."""
    check_convention(convention)
    t0 = time.perf_counter()
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    open_ = [k for k in NAMES if limits.get(k) is not None]
    res = {
        k: {"status": "proven", "required": float(limits[k]), "bound": None, "sampled": None, "unit": UNITS[k]}
        for k in open_
    }
    worst = {k: (np.inf if k == "frequency" else -np.inf) for k in open_}
    sampled = dict(worst)
    pending = initial_cells(platform, lo, hi, initial)
    examined = 0
    while len(pending) and open_:
        if examined + len(pending) > max_cells:
            for k in open_:
                res[k]["status"] = "unresolved"
                res[k]["unresolved_count"] = len(pending)
                res[k]["unresolved_cells"] = [
                    [(cc - hh).tolist(), (cc + hh).tolist()]
                    for cc, hh in zip(pending.c[:20], pending.h[:20], strict=True)
                ]
            break
        tighten = examined + len(pending) <= tighten_cells
        nxt = []
        for s in range(0, len(pending), BATCH):
            cells = Cells(pending.c[s : s + BATCH], pending.h[s : s + BATCH])
            b = performance_bounds(platform, cells, v_max, a_max, stiffness, convention)
            examined += len(cells)
            split = np.zeros(len(cells), bool)
            for k in list(open_):
                bound, centre = getattr(b, k), getattr(b, "centre_" + k)
                low = k == "frequency"
                sampled[k] = min(sampled[k], centre.min()) if low else max(sampled[k], centre.max())
                good = bound >= limits[k] if low else bound <= limits[k]
                bad_c = centre < limits[k] if low else centre > limits[k]
                w = _confirm(platform, k, cells.c[bad_c], limits[k], v_max, a_max, stiffness, convention)
                if w is not None:
                    res[k].update(status="violated", witness=w)
                    open_.remove(k)
                    continue
                split |= ~good
                if (
                    tighten
                ):  # branch and bound: only cells that could hold a worse value than (1 + TIGHT) × the worst seen
                    split |= bound < sampled[k] / (1 + TIGHT) if low else bound > sampled[k] * (1 + TIGHT)
            for k in open_:  # the leaves' bounds (cells not split further) cover the box
                bound = getattr(b, k)[~split]
                if len(bound):
                    low = k == "frequency"
                    worst[k] = min(worst[k], bound.min()) if low else max(worst[k], bound.max())
            if split.any() and open_:
                nxt.append(split_cells(platform, Cells(cells.c[split], cells.h[split])))
        pending = (
            Cells(np.concatenate([p.c for p in nxt]), np.concatenate([p.h for p in nxt]))
            if nxt
            else Cells(np.zeros((0, 6)), np.zeros((0, 6)))
        )
    for k, r in res.items():
        r["bound"] = None if r["status"] != "proven" else float(worst[k])
        r["sampled"] = None if not np.isfinite(sampled[k]) else float(sampled[k])
    return PerformanceProof(res, examined, max_cells, time.perf_counter() - t0)


def _confirm(platform, name, poses, limit, v_max, a_max, stiffness, convention) -> dict | None:
    """The first of ``poses`` (at most 16 tried) at which the toolkit's per-platform functions find ``name``
    beyond ``limit``: ``{"pose", "value", "limit"}``; None if none."""
    if not len(poses):
        return None
    poses = poses[:16]
    try:
        vals = sampled_performance(platform, poses, v_max, a_max, stiffness, convention)[name]
    except StewartError:  # a centre off the workspace (the box's own proof says so): no witness here, split on
        return None
    bad = vals < limit if name == "frequency" else vals > limit
    if not bad.any():
        return None
    k = int(np.argmax(bad))
    return {"pose": poses[k].tolist(), "value": float(vals[k]), "limit": float(limit)}


def prove_requirements_performance(platform: Platform, req, max_cells: int = MAX_CELLS) -> PerformanceProof:
    """``prove_performance`` of a ``Requirements``' actuator and limits over its box (relative to home)."""
    limits = {
        "force": req.max_force,
        "speed": req.max_speed,
        "frequency": req.min_frequency_hz,
        "condition": req.max_condition,
    }
    home = platform.home_pose()
    return prove_performance(
        platform, home + req.box_lo, home + req.box_hi, limits, req.v_max, req.a_max, req.stiffness, req.convention,
        max_cells,
    )  # fmt: skip
