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

Floating point. Nothing is widened by a guessed factor: each centre quantity computed in binary64 is verified a
posteriori with a bound whose rounding terms are stated (``synthesis.verified`` states the lemmas: Higham's
γ_n = n u/(1 − n u), u = 2⁻⁵³, for products, |fl(AB) − AB| <= γ_n |A||B|; the Cholesky certificate; the ``up``/``down``
widening of every bound computed from rigorous operands by 1e-12 relative, above γ₁₀₀₀ + 2u).

- **Inputs** (the computed centre is taken as the exact data from here on; its distance from the true centre is
  added to the cell's perturbation). numpy's sin and cos are within 4 ulp (8u relative, as ``proof`` assumes); an
  elementary rotation's |R_e| has 2-norm <= √2, so the three factors' errors and the two rounded 3 × 3 products give
  ‖R~ − R(c)‖₂ <= 3·8√2u(1 + 8√2u)² + γ₃(2 + 2√2) < ``EPS_ROT`` = 64u, and ``EPS_DROT`` = 128u for ∂R/∂θ_j and its
  product with t~ (one more product with a [e]×: 3·8√2u(1 + ...) + γ₃(2 + 2 + 2√2) + γ₃√3 < 64u, doubled), plus the
  rounded t's error in the Taylor term. t~ = fl(p_TTi − p_TC) is within 2u(|p_TTi| + |p_TC|); r~ = fl(R~ t~) is
  within fp_r = (EPS_ROT + 8u)|t| + that of r(c); l~ within fp_l = fp_r + 3u(|p| + |t| + |b_i|) (two additions);
  |l(c)| >= |l~|(1 − 6u) − fp_l (the norm's γ₅); u~ within 2 fp_l/|l(c)| + 8u; fl(r~ × u~) within fp_r + |t| fp_u
  + 5u|t|; A_s~ = fl(A~ D) within u|·|. These are added to e_u and e_w, so δ bounds ‖A_s(x) − A_s~‖₂ and the speed
  bound holds for the computed rows. ε_R = Σh_θ + EPS_ROT bounds ‖R(x) − R~‖₂ (‖R~ I R~ᵀ − R I Rᵀ‖ <= ε_R ‖I‖
  (2 + EPS_ROT), the same for [r]×²), with the rounded c_m − p_C's 2u(|p_cm| + |p_C|). D holds the floats
  (1, 1, 1, fl(1/s)): the toolkit's condition number differs by at most (1 + u)/(1 − u), covered by a factor 1 + 4u.
- **Singular values**: G~ = fl(A_s~ᵀA_s~) (symmetrised) is within e_G = γ₈ ‖A_s~‖_F²; Cholesky of G~ − s 1 with s a
  little below the float SVD's σ_min² (by 4 times the rounding terms) certifies λ_min >= s − e_G − the Cholesky
  lemma's terms, and of s' 1 − G~ likewise λ_max (else the Frobenius norm). A centre whose certificate fails (a
  condition number beyond ~10⁷, where the Gram matrix's rounding reaches σ_min²) is refused: force inf, frequency 0,
  condition inf, and the cell is split (or left unresolved), never proven.
- **Solves**: B~ = fl(A_s~⁻¹) is any matrix: ‖B~ − A_s~⁻¹‖₂ <= ‖A_s~⁻¹‖ ‖A_s~B~ − 1‖₂ <= β ρ, with ρ the computed
  residual's Frobenius norm plus γ₇ ‖A_s~‖_F ‖B~‖_F; |b_i| gets β ρ, and X = fl(B~ᵀ D w~) the error γ₆ |B~|ᵀ|D w~|
  + β ρ |D w~_k| per column, contracted with the envelope's weights (1, a_max, v_i v_j) into the peak's error.
- **Wrench and inertia**: ``plate_wrench_terms`` and ``spatial_inertia_about_C`` evaluate, at R~, polynomials of
  degree <= 4 with fewer than 100 roundings an entry; each entry is within γ₁₀₀ of its absolute-value expression,
  which is at most S_w = 16 (m (1 + g)(1 + ‖c_m‖₁)² + 9 max|I_ij|) (|R~_ij| <= 1 + EPS_ROT, the polarisation's ω
  with entries <= 1); ``FP_W`` = 2⁻⁴⁰ > 80 γ₁₀₀. Over the envelope D w's error is at most √6 FP_W S_w max(1, 1/s)
  (1 + Σa + (Σv)²), added to |D Δw|; the scaled inertia's to ε_M (36 FP_W S_w max(1, 1/s)²).
- **Envelope maximum**: the centre's exact envelope peak for the data X is bounded above by |G|·a (rounded up), the
  quadratic part's maximum over the velocity box by ``verified.quad_box_max`` (every face of the box, its
  stationary point and definiteness decided with stated error terms, an interval bound where undecided), γ₃ of the
  sum's absolute values, and X's error above.
- **Pencil**: K_lo~ = fl(shrink k G~ − ε_K 1) is within e_K = shrink k e_G + γ₃(shrink k ‖G~‖_F + 3 ε_K) of the exact
  K_lo (shrink and ε_K rounded down and up); λ is the float pencil's least eigenvalue lowered by 1e-9 relative and
  4 (e_K + γ₈ tr)/λ_min(M_hi); fl-Cholesky then certifies K_lo − λ M_s~ ⪰ λ ε_M 1, i.e. K_lo − λ M_hi ⪰ 0, with the
  formation error γ₂(‖K_lo~‖_F + λ ‖M_s~‖_F) and e_K included. The frequency is down(√λ / up(2π)) (np.pi < π), 0
  where the certificate fails.

The perturbation bounds themselves (e_r, …, W, ‖D D_i D‖) are sums, products and quotients of non-negative floats,
each passed through ``up``; the subtractions (|l(c)| − e_l, σ_min − δ, 1 − δβ) through ``down``. Tests check the
float bounds against python-flint's arb (rotation, singular values, the centre's exact force and speed, the
pencil's eigenvalues), the quadratic maximum against exact rational enumeration, and every bound against 10⁴ poses
evaluated by the toolkit's own functions.

A cell is done when each requirement still open is proven on it; otherwise its centre is evaluated (the centre
values are the toolkit's formulas at that pose): a requirement the centre violates gets a witness, confirmed by
the toolkit's per-platform functions (``envelope_sizing``, ``stiffness_matrix`` + ``lowest_frequency``,
``condition_number``), and is closed as ``violated``; the others' cells are halved as in ``proof.prove_box``.
The cells are budgeted as ``proof.prove_box``'s (``proof.CellBudget``); when the budget runs out the requirements
still open on some cell are ``unresolved``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from stewart_drake.core.distinct import distinct_rows
from stewart_drake.core.dynamics import G_EARTH, skew
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import anchor_radius
from stewart_drake.core.rotations import check_convention, rotation_matrix
from stewart_drake.design.envelope import Envelope, envelope_peaks, plate_wrench_terms, spatial_inertia_about_C
from stewart_drake.design.maps import lowest_frequency
from stewart_drake.design.stiffness import geometric_load_term, stiffness_matrix
from stewart_drake.errors import StewartError
from stewart_drake.synthesis.proof import (
    BATCH,
    COVER_PAD,
    MAX_CELLS,
    CellBudget,
    Cells,
    initial_cells,
    rotation_derivatives,
    split_cells,
    unresolved_volume,
)
from stewart_drake.synthesis.verified import U, certified_min_eig, down, gamma, quad_box_max, up

EPS_ROT = 64 * U  # ‖R~ − R(c)‖₂ for the computed rotation (module docstring)
EPS_DROT = 128 * U  # ‖∂R~/∂θ_j − ∂R/∂θ_j(c)‖₂ for the computed derivatives
FP_W = 2.0**-40  # each computed wrench / inertia entry within FP_W × S_w of its value at R~ (module docstring)
TWO_PI_UP = float(up(2 * np.pi))  # >= 2π (np.pi < π)
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
    docstring derives them, rounding included). The plate alone carries mass (legs massless), as the synthesis's
    evaluation. A cell whose centre cannot be certified non-singular gets force inf, frequency 0, condition inf."""
    v_max, a_max = np.asarray(v_max, float), np.asarray(a_max, float)
    c = cells.c
    h = cells.h + COVER_PAD * (1.0 + np.abs(c))
    hp, ht = h[:, :3], h[:, 3:]
    top, rc, base = platform.top_anchors_per_leg, platform.rotation_centre, platform.base_anchors
    t = top - rc  # (6, 3)
    fp_t = 2.0 * U * (np.linalg.norm(top, axis=1) + np.linalg.norm(rc))  # |t~ − t| (6,)
    tn = up(np.linalg.norm(t, axis=1) + fp_t)  # >= |t| (6,)
    # what depends on the orientation alone is computed once per distinct angle centre (cells split across the
    # positions share theirs: ~2 % are distinct in the synthesis's proofs) and gathered: the same arithmetic per pose
    angles, inv = distinct_rows(c[:, 3:])
    R_u, dR_u = rotation_derivatives(angles, convention)
    r = np.einsum("nij,lj->nli", R_u, t)[inv]  # (n, 6, 3)
    dr_norm = np.linalg.norm(np.einsum("nkij,lj->nlki", dR_u, t), axis=-1)[inv]  # (n, 6, 3 [k]) |∂r_i/∂θ_k|
    lip = up(np.sum(ht, 1))  # (n,) ‖R(x) − R(c)‖₂
    eps_R = up(lip + EPS_ROT)  # ‖R(x) − R~‖₂, R~ the computed R(c)
    taylor = up(np.einsum("nlk,nk->nl", dr_norm + (EPS_DROT * tn + fp_t)[:, None], ht) + 0.5 * tn * lip[:, None] ** 2)
    e_r = np.minimum(up(lip[:, None] * tn), taylor)  # (n, 6) |r(x) − r(c)|
    fp_r = up((EPS_ROT + 8 * U) * tn + fp_t)  # (6,) |r~ − r(c)|
    l = c[:, None, :3] + r - base
    Lc = np.linalg.norm(l, axis=-1)
    u = l / Lc[..., None]
    fp_l = up(fp_r + 3 * U * (np.linalg.norm(c[:, :3], axis=1)[:, None] + tn + np.linalg.norm(base, axis=1)))
    L_lo = np.maximum(down(down(Lc * (1 - 6 * U)) - fp_l), 0.0)  # <= |l(c)|
    e_l = up(np.linalg.norm(hp, axis=1)[:, None] + e_r)  # |l(x) − l(c)|
    with np.errstate(divide="ignore", invalid="ignore"):
        gap = down(L_lo - e_l)
        e_u = np.minimum(up(2.0 * e_l / L_lo), np.where(gap > 0, up(e_l / gap), 2.0))  # |u(x) − u(c)|
        fp_u = np.where(L_lo > 0, up(2.0 * fp_l / L_lo + 8 * U), 2.0)  # |u(c) − u~|
    e_w = up(e_r + tn * e_u)  # |w(x) − w(c)|, w = r × u
    fp_w = up(fp_r + tn * fp_u + 5 * U * tn)  # |w(c) − w~|
    e_u, e_w = up(e_u + fp_u), up(e_w + fp_w)  # from now on: the changes from the computed centre row a~_i
    A = np.concatenate([u, np.cross(r, u)], -1)  # (n, 6, 6) J⁻¹ at the centre, computed
    s = anchor_radius(platform)
    Dg = np.r_[np.ones(3), np.full(3, 1.0 / s)]  # the scaling D: A_s = A D (D of these floats)
    As = A * Dg
    eps_leg = up(np.sqrt(e_u**2 + (e_w * Dg[3]) ** 2) + 2 * U * (1.0 + tn * Dg[3]))  # (n, 6) row changes of A_s
    d = up(np.sqrt(np.sum(eps_leg**2, -1)))  # ‖A_s(x) − A_s~‖₂ <= ‖·‖_F
    # singular values of the float A_s~ (exact data from here on): certified bounds of λ(A_s~ᵀA_s~)
    Gm = np.einsum("nki,nkj->nij", As, As)
    Gm = 0.5 * (Gm + np.swapaxes(Gm, -1, -2))
    fro2 = up(np.sum(As**2, axis=(-2, -1)))  # ‖A_s~‖_F²
    e_G = up(gamma(8) * fro2)  # ‖Gm − A_s~ᵀA_s~‖₂
    sig_s = np.linalg.svd(As, compute_uv=False)  # trial values only
    margin = 4.0 * up(e_G + gamma(8) * fro2)
    lam_lo = certified_min_eig(Gm, e_G, sig_s[:, -1] ** 2 * (1 - 1e-12) - margin)
    lam_hi = -certified_min_eig(-Gm, e_G, -(sig_s[:, 0] ** 2 * (1 + 1e-12) + margin))
    sig_lo = np.where(lam_lo > 0, down(np.sqrt(np.maximum(lam_lo, 0.0))), 0.0)
    sig_hi = np.where(np.isfinite(lam_hi), up(np.sqrt(np.abs(lam_hi))), up(np.sqrt(fro2)))
    with np.errstate(divide="ignore", invalid="ignore"):
        kappa_c = np.where(sig_s[:, -1] > 0, sig_s[:, 0] / sig_s[:, -1], np.inf)
        invertible = kappa_c < 1e12  # the centre pose itself (its values are a sample, bounds need ``regular``)
        regular = invertible & (sig_lo > d)  # ‖A_s~⁻¹‖ δ < 1: A_s(x) invertible on the cell
        den = np.where(regular, down(sig_lo - d), 1.0)  # <= σ_min − δ
        cond = np.where(regular, up(up(sig_hi + d) / den * (1 + 4 * U)), np.inf)
        beta = np.where(regular, up(1.0 / np.where(regular, sig_lo, 1.0)), np.inf)  # >= ‖A_s~⁻¹‖₂
        rel = np.where(regular, up(d / den), np.inf)  # δ/(σ_min − δ)
        dB = np.where(regular, up(d / down(np.where(regular, sig_lo, 1.0) * den)), np.inf)  # ‖ΔA_s⁻ᵀ‖₂
    # speed
    vl, va = up(np.linalg.norm(v_max[:3])), up(np.linalg.norm(v_max[3:]))
    speed_c = np.abs(A) @ v_max  # (n, 6)
    speed = up(speed_c + e_u * vl + e_w * va)
    # force: the exact envelope peak at the centre, plus the orientation's and the Jacobian's changes
    Binv = np.linalg.inv(np.where(invertible[:, None, None], As, np.eye(6)))  # row i of A_s⁻ᵀ: column i of A_s⁻¹
    res = np.einsum("nij,njk->nik", As, Binv) - np.eye(6)
    rho = up(
        np.linalg.norm(res, axis=(-2, -1)) * (1 + 2 * U)
        + gamma(7) * np.sqrt(fro2) * np.linalg.norm(Binv, axis=(-2, -1))
    )  # >= ‖A_s~ B~ − 1‖₂
    b_inv = up(beta * rho)  # >= ‖B~ − A_s~⁻¹‖₂
    b_norm = np.linalg.norm(Binv, axis=-2)  # (n, 6)
    b_hi = up(b_norm + b_inv[:, None])  # >= |row i of A_s~⁻ᵀ|
    rhs = plate_wrench_terms(platform, R_u, gravity)[inv] * Dg[:, None]  # D w: F = A⁻ᵀ w = A_s⁻ᵀ D w
    X = np.einsum("nji,njk->nik", Binv, rhs)
    # |X − A_s~⁻ᵀ rhs~| <= γ₆ |B~|ᵀ|rhs~| + ‖B~ − A_s~⁻¹‖ |rhs~_k| entrywise, contracted with the envelope's weights
    # (1, a_max, v_i v_j >= |1|, |acc|, |ω_i ω_j|) for the peak and with column 0 alone for the weight
    weights = np.r_[1.0, a_max, np.outer(v_max[3:], v_max[3:]).ravel()]  # (16,)
    rhs_abs = np.abs(rhs)
    col_norm = np.linalg.norm(rhs, axis=-2)  # (n, 16)
    Babs = np.abs(Binv)
    e_P = up(
        gamma(6) * np.einsum("nji,nj->ni", Babs, rhs_abs @ weights) + (b_inv * (col_norm @ weights))[:, None]
    )  # (n, 6) the envelope peak's change from X's rounding
    e_X0 = up(gamma(6) * np.einsum("nji,nj->ni", Babs, rhs_abs[..., 0]) + (b_inv * col_norm[:, 0])[:, None])
    cF, G, Q = X[..., 0], X[..., 1:7], X[..., 7:].reshape(X.shape[:-1] + (3, 3))
    vel = np.flatnonzero(v_max[3:] > 0)
    Qv = Q[..., vel, :][..., :, vel]
    qmax, qmax_hi = quad_box_max(Qv, v_max[3:][vel])  # the centre's value (a sample) and a rigorous bound
    qmin, qmin_hi = quad_box_max(-Qv, v_max[3:][vel])
    lin = np.abs(G) @ a_max
    peak_c = np.maximum(cF + lin + qmax, -(cF - lin - qmin))  # (n, 6) the centre's value
    lin_hi = up(lin)
    peak_hi = up(
        np.maximum(cF + lin_hi + qmax_hi, -cF + lin_hi + qmin_hi)
        + gamma(3) * (np.abs(cF) + lin_hi + np.maximum(np.abs(qmax_hi), np.abs(qmin_hi)))
        + e_P
    )  # >= the exact envelope peak of A_s~⁻ᵀ D w(R~)
    m = platform.mass
    c_m = platform.com - rc
    fp_cm = 2.0 * U * (np.linalg.norm(platform.com) + np.linalg.norm(rc))
    cm = up(np.linalg.norm(c_m) + fp_cm)
    In = _sym_norm_upper(platform.inertia)
    al, aa = up(np.linalg.norm(a_max[:3])), up(np.linalg.norm(a_max[3:]))
    dr_cm = up(eps_R * cm + fp_cm)  # (n,) |r_cm(x) − R~ c_m~|
    dI = up(eps_R * In * (2.0 + EPS_ROT))  # ‖R I Rᵀ − R~ I R~ᵀ‖₂
    dSS = up(m * dr_cm * cm * (2.0 + EPS_ROT))  # m ‖[r]×² − [r~]×²‖₂
    dw_f = m * dr_cm * aa + m * va**2 * dr_cm
    dw_t = m * gravity * dr_cm + m * dr_cm * al + (dI + dSS) * (aa + va**2)
    scale_w = max(1.0, Dg[3])
    e_ent = FP_W * _wrench_scale(platform, gravity) * scale_w  # each computed entry of rhs (module docstring)
    envelope_weight = up(1.0 + np.sum(a_max) + np.sum(v_max[3:]) ** 2)
    dw = up(np.hypot(dw_f, dw_t / s) + np.sqrt(6.0) * e_ent * envelope_weight)  # |D Δw|
    W = up(
        np.hypot(
            m * (gravity + al + cm * aa + cm * va**2), (m * cm * (gravity + al) + (In + m * cm**2) * (aa + va**2)) / s
        )
    )  # |D w|
    near = up(peak_hi + b_hi * dw[:, None])  # |F'_i| over the cell × envelope
    f_norm = np.minimum(up(np.linalg.norm(near, axis=-1)), up(beta * W))  # |F'|₂ <= ‖A_s~⁻¹‖ |D w| too
    per_leg = up((b_hi + dB[:, None]) * np.sum(near * eps_leg, -1)[:, None])
    jac = np.minimum(np.minimum(up(rel * f_norm), up(dB * W))[:, None], per_leg)
    force = up(near + jac)
    # frequency: K ⪰ K_lo, M ⪯ M_s~ + ε_M 1 (the pencil in y = D⁻¹ v)
    W_g = up(m * gravity * np.hypot(1.0, cm / s))
    dw_g = up(m * gravity * dr_cm / s + np.sqrt(6.0) * e_ent)
    near_g = up(np.abs(cF) + e_X0 + b_hi * dw_g[:, None])
    static = up(near_g + np.minimum(up(rel * up(np.linalg.norm(near_g, axis=-1))), up(dB * W_g))[:, None])
    L_x = down(L_lo - e_l)  # |l(x)| >= it
    with np.errstate(divide="ignore", invalid="ignore"):  # ‖D D_i D‖ from its blocks' norms
        D_norm = np.where(
            L_x > 0,
            up(np.sqrt(1 / L_x**2 + 2 * (tn / (L_x * s)) ** 2 + ((tn + tn**2 / L_x) / s**2) ** 2)),
            np.inf,
        )
    g_sup = up(np.sum(static * D_norm, -1) + m * gravity * cm / s**2)
    one_minus = np.maximum(down(1.0 - up(d * np.where(regular, beta, 0.0))), 0.0)  # <= 1 − δ‖A_s~⁻¹‖
    shrink = np.where(regular, down(one_minus**2), 0.0)  # (1 − δ/σ_min)²
    M_c = spatial_inertia_about_C(platform, R_u)[inv]
    M_s = M_c * Dg[:, None] * Dg
    eps_M = up(
        np.hypot(np.sqrt(2.0) * m * dr_cm / s, (dI + dSS) / s**2)
        + 36.0 * FP_W * _wrench_scale(platform, gravity) * scale_w**2
    )
    freq = np.zeros(len(c))
    ok = regular & np.isfinite(g_sup)
    if ok.any():
        k_lo = down(stiffness * shrink[ok])  # <= k (1 − δβ)²
        freq[ok] = _certified_frequency(k_lo, Gm[ok], e_G[ok], g_sup[ok], M_s[ok], eps_M[ok])
    K_full = stiffness * np.einsum("nki,nkj->nij", A, A) - geometric_load_term(cF, u, r, Lc)
    r_cm = np.einsum("nij,j->ni", R_u, c_m)[inv]
    K_full[:, 3:, 3:] -= skew(np.broadcast_to([0.0, 0.0, -m * gravity], r_cm.shape)) @ skew(r_cm)
    freq_c = lowest_frequency(K_full, M_c)
    return PerformanceBounds(
        np.where(regular, force.max(-1), np.inf),
        speed.max(-1),
        freq,
        cond,
        np.where(invertible, peak_c.max(-1), np.inf),
        speed_c.max(-1),
        np.where(invertible, freq_c, 0.0),
        kappa_c,
    )


def _certified_frequency(k_shrink, Gm, e_G, eps_K, M_s, eps_M) -> np.ndarray:
    """``(n,)`` a certified lower bound (Hz) of the pencil (K, M)'s least eigenvalue for every K ⪰ k_shrink A_s~ᵀA_s~
    − eps_K 1 and M ⪯ M_s + eps_M 1 (``Gm`` the computed A_s~ᵀA_s~, within ``e_G``): λ from the float pencil, a hair
    lowered, then K_lo − λ (M_s + eps_M 1) ⪰ 0 certified by floating-point Cholesky (module docstring); 0 where the
    certificate fails or λ <= 0."""
    n = len(Gm)
    I6 = np.eye(6)
    K_lo = k_shrink[:, None, None] * Gm - eps_K[:, None, None] * I6
    e_K = up(k_shrink * e_G + gamma(3) * (k_shrink * np.linalg.norm(Gm, axis=(-2, -1)) + 3.0 * eps_K))
    M_hi = M_s + eps_M[:, None, None] * I6
    lam_f = (2 * np.pi * lowest_frequency(K_lo, M_hi)) ** 2
    # estimate of λ_min(M_hi), for the trial only: M_s's spectrum does not depend on the orientation (D commutes
    # with diag(R, R), and M_C(R) = diag(R, R) M_C(1) diag(R, R)ᵀ)
    mu = np.linalg.eigvalsh(M_s[:1])[0, 0] + eps_M
    tr = np.abs(np.einsum("nii->n", K_lo)) + lam_f * np.abs(np.einsum("nii->n", M_s))
    lam = lam_f * (1 - 1e-9) - 4.0 * (e_K + gamma(8) * tr) / mu
    out = np.zeros(n)
    pos = lam > 0
    if not pos.any():
        return out
    lam, K_lo, M_s, M_hi = lam[pos], K_lo[pos], M_s[pos], M_hi[pos]
    Xm = K_lo - lam[:, None, None] * M_s  # the float K_lo − λ M_s
    abs_err = up(
        e_K[pos] + gamma(2) * (np.linalg.norm(K_lo, axis=(-2, -1)) + lam * np.linalg.norm(M_s, axis=(-2, -1)))
    )  # ‖Xm − (K_lo − λ M_s)‖₂, K_lo the exact one
    need = up(lam * eps_M[pos])  # K_lo − λ M_s ⪰ need·1 gives K_lo − λ M_hi ⪰ 0
    shift = up(need + 2.0 * (abs_err + gamma(8) * np.abs(np.einsum("nii->n", Xm))))
    lb = certified_min_eig(Xm, abs_err, shift)
    good = lb >= need
    out[np.flatnonzero(pos)[good]] = down(down(np.sqrt(lam[good])) / TWO_PI_UP)
    return out


def _sym_norm_upper(S) -> float:
    """A rigorous upper bound of ‖S‖₂ for a symmetric positive semidefinite float matrix (the inertia): its largest
    eigenvalue certified by floating-point Cholesky (``verified.certified_min_eig``), else the Frobenius norm."""
    S = np.asarray(S, float)
    w = float(np.linalg.eigvalsh(S)[-1])
    lb = certified_min_eig(-S[None], 0.0, np.array([-(w * (1 + 1e-9) + 1e-300)]))[0]
    fro = float(up(np.linalg.norm(S)))
    return min(float(up(-lb)), fro) if np.isfinite(lb) else fro


def _wrench_scale(platform: Platform, gravity: float) -> float:
    """S_w (module docstring): a bound of the absolute-value expressions of ``plate_wrench_terms``' and
    ``spatial_inertia_about_C``'s entries."""
    m = platform.mass
    cm1 = float(np.sum(np.abs(platform.com - platform.rotation_centre)))
    return float(16.0 * (m * (1.0 + gravity) * (1.0 + cm1) ** 2 + 9.0 * np.max(np.abs(platform.inertia))))


def sampled_performance(platform: Platform, poses, v_max, a_max, stiffness: float, convention: str = "utn") -> dict:
    """``{name: (m,)}`` the requirements' quantities at poses (m, 6) by the toolkit's per-platform functions:
    peak leg force and speed (``envelope_peaks``: ``envelope_sizing``'s, exact over the envelope), lowest frequency (``stiffness_matrix``
    and ``spatial_inertia_about_C`` through ``lowest_frequency``) and ``condition_number``. The independent check."""
    poses = np.atleast_2d(np.asarray(poses, float))
    env = Envelope(poses, np.asarray(v_max, float), np.asarray(a_max, float), convention, "box")
    force, speed, cond = envelope_peaks(platform, env, stroke=False)  # envelope_sizing's peaks, bit for bit
    K = stiffness_matrix(platform, poses, stiffness, convention)
    M = spatial_inertia_about_C(platform, rotation_matrix(poses[:, 3:], convention))
    return {
        "force": force.max(-1),
        "speed": speed.max(-1),
        "frequency": lowest_frequency(K, M),
        "condition": cond,  # condition_number's, computed by the envelope's workspace check
    }


@dataclass
class PerformanceProof:
    """Per requirement (``NAMES`` that were asked): ``status`` proven | violated | unresolved, ``required``,
    ``bound`` (the proven worst over the box: max force/speed/condition, min frequency; over the proven cells when
    not proven), ``sampled`` (the worst of the cells' centres, a sample), ``witness`` (a pose and the toolkit's
    value at it) when violated, and when unresolved the cells left (``unresolved_count``, the first 20 as lo/hi pairs
    in ``unresolved_cells``) and their share of the box's volume; ``stopped``: why the cell budget ran out
    (``"cap"``, ``"stalled"``; None when it did not)."""

    results: dict
    cells_examined: int
    max_cells: int
    seconds: float = 0.0
    stopped: str | None = None
    method: str = field(
        default="Weyl and Neumann bounds of J⁻¹ over each cell, the envelope peak at its centre, derived rotation "
        "constants; centre singular values, solve, envelope maximum and pencil eigenvalue verified in floating "
        "point with stated rounding bounds (Cholesky certificates, residual-bounded inverse; synthesis.performance)"
    )

    def to_dict(self) -> dict:
        """JSON-able (SI)."""
        return {
            "requirements": self.results,
            "cells_examined": self.cells_examined,
            "max_cells": self.max_cells,
            "stopped": self.stopped,
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
    (6,) m and rad) × the motion envelope, find a witness pose against one, or give up (unresolved) when the
    ``proof.CellBudget`` runs out: at ``max_cells`` cells, or earlier when the volume of the cells left stops
    shrinking (see the module docstring). Each cell carries the requirements still open on it: a requirement
    proven on a cell is not split further for it, and a requirement is proven when no cell left needs it. While
    fewer than ``tighten_cells`` cells have been examined, a cell whose bound meets a limit but exceeds the worst
    centre value seen by more than ``TIGHT`` (relative) is split too (branch and bound), so that the reported
    bound is close to the box's worst rather than merely within the limit."""
    check_convention(convention)
    t0 = time.perf_counter()
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    names = [k for k in NAMES if limits.get(k) is not None]
    open_ = list(names)
    res = {
        k: {"status": "proven", "required": float(limits[k]), "bound": None, "sampled": None, "unit": UNITS[k]}
        for k in names
    }
    worst = {k: (np.inf if k == "frequency" else -np.inf) for k in names}
    sampled = dict(worst)
    pending = initial_cells(platform, lo, hi, initial)
    # per cell and requirement: still open on the cell, and the bound its parent proved (nan: not proven there;
    # a cell split only to tighten a proven bound carries it, so a budget that runs out leaves that bound valid)
    need = np.ones((len(pending), len(names)), bool)
    held = np.full((len(pending), len(names)), np.nan)
    examined = 0
    budget = CellBudget(max_cells, lo, hi)
    while len(pending) and open_:
        if not budget.allows(examined, pending):
            _give_up(res, names, open_, pending, need, held, worst, lo, hi, budget.stopped)
            break
        tighten = examined + len(pending) <= tighten_cells
        nxt, nxt_need, nxt_held = [], [], []
        for s in range(0, len(pending), BATCH):
            cells = Cells(pending.c[s : s + BATCH], pending.h[s : s + BATCH])
            nd, hd = need[s : s + BATCH], held[s : s + BATCH]
            b = performance_bounds(platform, cells, v_max, a_max, stiffness, convention)
            examined += len(cells)
            split_k = np.zeros((len(cells), len(names)), bool)
            bound_k = np.full((len(cells), len(names)), np.nan)
            for k in list(open_):
                j = names.index(k)
                bound, centre = getattr(b, k), getattr(b, "centre_" + k)
                low = k == "frequency"
                sampled[k] = min(sampled[k], centre.min()) if low else max(sampled[k], centre.max())
                good = bound >= limits[k] if low else bound <= limits[k]
                bad_c = (centre < limits[k] if low else centre > limits[k]) & nd[:, j]
                w = _confirm(platform, k, cells.c[bad_c], limits[k], v_max, a_max, stiffness, convention)
                if w is not None:
                    res[k].update(status="violated", witness=w)
                    open_.remove(k)
                    continue
                split = ~good
                if tighten:  # branch and bound: only cells that could hold a worse value than (1 + TIGHT) × the worst
                    split |= bound < sampled[k] / (1 + TIGHT) if low else bound > sampled[k] * (1 + TIGHT)
                split &= nd[:, j]
                leaf = nd[:, j] & ~split  # the leaves' bounds (cells not split further for k) cover the box
                if leaf.any():
                    worst[k] = min(worst[k], bound[leaf].min()) if low else max(worst[k], bound[leaf].max())
                split_k[:, j] = split
                bound_k[:, j] = np.where(good, bound, np.nan)
            cols = [names.index(k) for k in open_]
            split = split_k[:, cols].any(1)
            if split.any():
                nxt.append(split_cells(platform, Cells(cells.c[split], cells.h[split])))
                carried = np.where(np.isnan(bound_k), hd, bound_k)[split]  # the cell's own bound where proven on it
                nxt_need.append(np.tile(split_k[split], (2, 1)))
                nxt_held.append(np.tile(np.where(split_k[split], carried, np.nan), (2, 1)))
        if nxt:
            pending = Cells(np.concatenate([p.c for p in nxt]), np.concatenate([p.h for p in nxt]))
            need, held = np.concatenate(nxt_need), np.concatenate(nxt_held)
            keep = need[:, [names.index(k) for k in open_]].any(1)  # requirements closed meanwhile drop out
            pending, need, held = Cells(pending.c[keep], pending.h[keep]), need[keep], held[keep]
        else:
            pending = Cells(np.zeros((0, 6)), np.zeros((0, 6)))
    for k, r in res.items():
        r["bound"] = None if r["status"] != "proven" else float(worst[k])
        r["sampled"] = None if not np.isfinite(sampled[k]) else float(sampled[k])
    return PerformanceProof(res, examined, max_cells, time.perf_counter() - t0, stopped=budget.stopped)


def _give_up(res, names, open_, pending: Cells, need, held, worst, lo, hi, stopped) -> None:
    """The budget ran out with ``pending`` cells left: a requirement that no cell left needs unproven (every cell
    left for it carries its parent's proven bound) is proven with those bounds; the others are ``unresolved``,
    with their cells left, the first 20 of them (lo, hi pairs) and their share of the box's volume."""
    for k in list(open_):
        j = names.index(k)
        mine = need[:, j]
        open_cells = mine & np.isnan(held[:, j])
        if not open_cells.any():
            if mine.any():
                low = k == "frequency"
                worst[k] = min(worst[k], held[mine, j].min()) if low else max(worst[k], held[mine, j].max())
            continue
        left = Cells(pending.c[open_cells], pending.h[open_cells])
        res[k]["status"] = "unresolved"
        res[k]["unresolved_count"] = len(left)
        res[k]["unresolved_volume"] = unresolved_volume(left, lo, hi)
        res[k]["stopped"] = stopped
        res[k]["unresolved_cells"] = [
            [(cc - hh).tolist(), (cc + hh).tolist()] for cc, hh in zip(left.c[:20], left.h[:20], strict=True)
        ]


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


def prove_requirements_performance(
    platform: Platform, req, max_cells: int = MAX_CELLS, tighten_cells: int = TIGHTEN_CELLS
) -> PerformanceProof:
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
        max_cells, tighten_cells=tighten_cells,
    )  # fmt: skip
