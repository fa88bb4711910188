"""Verified floating-point primitives for the performance proof (``synthesis.performance``): directed widening of
computed bounds, a positive-semidefiniteness certificate by floating-point Cholesky, and an upper bound of a
quadratic form's maximum over a box. Vectorised over leading axes; binary64, rounding to nearest, u = 2⁻⁵³.

Lemmas (stated here, used there):

- **Widening** (``up``/``down``). Let y be a real and x = fl(y) its value computed by at most 1000 rounded operations
  (+ of non-negative terms, ×, /, √) from floats, none underflowing below 1e-290: |x − y| <= γ₁₀₀₀ |y| (Higham,
  Lemma 3.1; γ_n = n u/(1 − n u), γ₁₀₀₀ < 1.2e-13). The same holds for one rounded operation of any sign, such as
  a − b of two floats (|x − y| <= u |y|). Then ``up(x)`` = x + (|x| 1e-12 + 1e-300), computed in binary64, is >= y
  and ``down(x)`` <= y: the added term exceeds the error by 1e-12 − 2.4e-13 relative, and its own rounding (u
  relative) and the underflow gap (< 1e-300) are inside that margin. Every bound that the proof computes from
  rigorous operands is passed through one of them.
- **Products** (Higham, §3.5): for float matrices, |fl(A B) − A B| <= γ_n |A| |B| entrywise (n the inner dimension),
  whatever the order of summation and with or without fused multiply-adds; so ‖fl(A B) − A B‖₂ <= γ_n ‖A‖_F ‖B‖_F.
- **Cholesky** (Higham, Theorem 10.3; Rump's ``isspd`` idea): if floating-point Cholesky of a symmetric float k × k
  H runs to completion (every pivot computed > 0), the computed R satisfies RᵀR = H + ΔH with |ΔH| <= γ_{k+1} |Rᵀ||R|,
  whatever the order of the inner products. Taking diagonals, (RᵀR)_jj <= H_jj / (1 − γ_{k+1}), so
  ‖ΔH‖₂ <= γ_{k+1} ‖R‖_F² <= γ_{k+1}/(1 − γ_{k+1}) tr H and H ⪰ −(γ_{k+1}/(1 − γ_{k+1})) tr H · 1. ``certified_min_eig``
  applies it to H = fl(X − s 1): fl(x_jj − s) is within u|H_jj|/(1 − u) of x_jj − s, so
  X ⪰ (s − γ_{k+1}/(1 − γ_{k+1}) tr H − 2u max_j |H_jj|) 1.
- **Quadratic maximum** (``quad_box_max``): see its docstring.
"""

from __future__ import annotations

import itertools

import numpy as np

U = 2.0**-53  # unit roundoff of binary64 (round to nearest)
WIDEN = 1e-12  # relative widening of ``up``/``down`` (>= γ₁₀₀₀ + 2u, the Widening lemma)
TINY = 1e-300  # absolute widening (below it, an underflow's error)


def gamma(n: int) -> float:
    """Higham's γ_n = n u/(1 − n u): the relative error bound of n rounded operations."""
    return n * U / (1.0 - n * U)


def up(x):
    """An upper bound of the real y whose computed value is ``x`` (the Widening lemma of the module)."""
    return x + (np.abs(x) * WIDEN + TINY)


def down(x):
    """A lower bound of the real y whose computed value is ``x`` (the Widening lemma of the module)."""
    return x - (np.abs(x) * WIDEN + TINY)


def cholesky_succeeds(H) -> np.ndarray:
    """``(...)`` bool: whether textbook floating-point Cholesky of the symmetric (..., k, k) H runs to completion
    (every pivot > 0; NaN fails). Vectorised over the batch, so one failing matrix does not stop the others (numpy's
    ``cholesky`` raises for the whole batch)."""
    H = np.asarray(H, dtype=float)
    k = H.shape[-1]
    L = np.zeros_like(H)
    ok = np.ones(H.shape[:-2], dtype=bool)
    for j in range(k):
        d = H[..., j, j] - np.sum(L[..., j, :j] ** 2, -1)
        ok &= d > 0
        r = np.sqrt(np.where(d > 0, d, 1.0))
        L[..., j, j] = r
        if j + 1 < k:
            s = H[..., j + 1 :, j] - np.einsum("...ip,...p->...i", L[..., j + 1 :, :j], L[..., j, :j])
            L[..., j + 1 :, j] = s / r[..., None]
    return ok


def certified_min_eig(X, abs_err, s) -> np.ndarray:
    """``(...)`` a rigorous lower bound of λ_min(Y) for every symmetric Y with ‖Y − X‖₂ <= ``abs_err`` (...), from
    the symmetric float (..., k, k) X and a trial shift ``s`` (...) (best a little below λ_min(X)): s minus the
    Cholesky lemma's rounding terms where Cholesky of fl(X − s 1) succeeds, −inf where it does not."""
    X = np.asarray(X, dtype=float)
    k = X.shape[-1]
    s = np.asarray(s, dtype=float)
    idx = np.arange(k)
    H = X.copy()
    H[..., idx, idx] -= s[..., None]
    ok = cholesky_succeeds(H)
    diag = H[..., idx, idx]
    g = gamma(k + 1)
    err = up(g / (1.0 - g) * np.sum(np.abs(diag), -1) + 2.0 * U * np.max(np.abs(diag), -1) + abs_err)
    return np.where(ok, down(s - err), -np.inf)


def _faces(d: int, b) -> list:
    """One representative p of each ± pair of faces of the box (first non-zero entry +1; the interior and faces
    with a zero-width free coordinate excluded: those points lie on smaller faces)."""
    out = []
    for p in itertools.product((-1, 0, 1), repeat=d):
        nz = [v for v in p if v]
        free = [j for j in range(d) if p[j] == 0]
        if nz and nz[0] == 1 and len(free) < d and not np.any(b[free] == 0):
            out.append(np.array(p))
    return out


def quad_box_max(Q, b) -> tuple[np.ndarray, np.ndarray]:
    """``(value (...), upper (...))``: max xᵀQx over |x_j| <= b_j for float (..., d, d) Q taken as exact data and
    (d,) b >= 0, d <= 3; ``value`` the maximum evaluated in floating point (``design.boxquad``'s enumeration: a
    sample, not a bound), ``upper`` a rigorous upper bound (Q symmetrised first: fl(½(Q + Qᵀ)) is within u|·| of the
    exact symmetric part, added).

    The maximum lies in the relative interior of a face (free set F, the others at x_C = ±b_C) at a local maximum
    of the face's restriction h(y) = α + 2gᵀy + yᵀQ_FF y, α = x_CᵀQ_CC x_C, g = Q_FC x_C (``design.boxquad``'s
    argument); every face is visited (one of each ± pair, f being even) and 0 (the interior's candidate) is kept:

    - vertices: the value α, plus γ₁₂ times its absolute-value expression;
    - one free coordinate (a = Q_ff): if a >= 0 (the sign of a float is exact) the maximum is at an end (a vertex);
      else the stationary value α + g²/|a|, skipped when |y*| = |g|/|a| > b_f certainly (with g's error);
    - two free (d = 3): negative definite when a < 0 and det = ae − c² > 0; fl(ae − c²) is within γ₂(|ae| + c²);
      where that leaves the sign undecided, det = (p₁ − p₂) + (e₁ − e₂) from the error-free products ae = p₁ + e₁,
      c² = p₂ + e₂ (Dekker's TwoProduct), within 2u(|p₁ − p₂| + |e₁ − e₂|)(1 + 4u) (an exact tie, such as integer
      data with det = 0, is decided exactly).
      Certified definite: α + gᵀ(−Q_FF)⁻¹g, the numerator N = −e g₀² + 2c g₀g₁ − a g₁² with γ₅ of its absolute
      expression over a lower bound of det, plus ‖(−Q_FF)⁻¹‖ (2|g||Δg| + |Δg|²) for g's error (‖(−Q_FF)⁻¹‖ <=
      −tr/det, the larger eigenvalue being at most the trace); skipped when y* = (−Q_FF)⁻¹g is certainly outside.
      Certified not definite (a >= 0 or det <= 0 certainly): the maximum is on the face's boundary (skipped).
      Undecided: the interval bound α + 2Σ(|g_j| + Δg_j) b_j + 2|c| b₀b₁ + max(e, 0) b₁² (a < 0 there).

    Each α and g carries γ₁₂ of its absolute expression (bounded by Σ_jk |Q_jk| b_j b_k and Σ_k |Q_ik| b_k); every
    candidate is widened by ``up``. Taking the largest
    of upper bounds of each face's maximum bounds the box's maximum. Vectorised over the batch, a Python loop over
    the ≤ 13 faces (elementwise arithmetic on the entries: tiny matrix products are slow in BLAS); a face with free
    coordinates is evaluated only on the entries whose a = Q_ff (f its first free coordinate) is negative, the only
    ones it can change (``_face``), with the same arithmetic per entry as on the whole batch."""
    Q = np.asarray(Q, dtype=float)
    Q = 0.5 * (Q + np.swapaxes(Q, -1, -2))
    b = np.asarray(b, dtype=float)
    d = b.shape[0]
    if d > 3:
        raise ValueError("quad_box_max: at most 3 dimensions")
    best = np.zeros(Q.shape[:-2])  # the interior's candidate x = 0
    value = best.copy()
    q = [[np.ascontiguousarray(Q[..., j, k]) for k in range(d)] for j in range(d)]  # entries as (...) arrays
    qa = [[np.abs(x) for x in row] for row in q]
    g12 = gamma(12)
    # the absolute-value expressions, bounded once for every face: Σ_jk |Q_jk| b_j b_k for the α's, and
    # Σ_k |Q_ik| b_k for the g's (over all k: more than the fixed ones, by at most γ₁₂ of the box's scale)
    rows = [sum(qa[i][k] * b[k] for k in range(d)) for i in range(d)]
    scale = sum(rows[i] * b[i] for i in range(d))
    e_alpha = _up_pos(g12 * scale)
    e_row = [_up_pos(g12 * r) for r in rows]
    # per leading free coordinate f, where Q_ff < 0: everywhere (None), nowhere (skipped), mostly (a mask: the face
    # evaluated on every entry and merged where it holds) or on fewer than half (their indices: evaluated there)
    subsets = {}
    for p in _faces(d, b):
        free, fixed = [j for j in range(d) if p[j] == 0], [j for j in range(d) if p[j] != 0]
        x = p * b
        if not free:
            alpha = sum(q[j][k] * (x[j] * x[k]) for j in fixed for k in fixed)
            best = np.maximum(best, up(alpha + e_alpha))
            value = np.maximum(value, alpha)
            continue
        if free[0] not in subsets:
            neg = q[free[0]][free[0]] < 0
            n_neg = np.count_nonzero(neg)
            subsets[free[0]] = (
                (None if n_neg == neg.size else neg if 2 * n_neg >= neg.size else np.flatnonzero(neg)),
                {},
            )
        sel, got = subsets[free[0]]
        if sel is not None and sel.size == 0:
            continue
        if sel is None or sel.dtype == bool:
            qs = {(j, k): q[j][k] for j in range(d) for k in range(d)}
            with np.errstate(all="ignore"):  # entries outside the mask may divide by 0: they are discarded
                bs, vs = _face(qs, x, b, free, fixed, [e_row[i] for i in free], e_alpha, best, value, sel)
            best, value = (bs, vs) if sel is None else (np.where(sel, bs, best), np.where(sel, vs, value))
            continue

        def take(key, z, sel=sel, got=got):  # z at the indices sel, gathered once per leading coordinate
            if key not in got:
                got[key] = z.reshape(-1)[sel]
            return got[key]

        qs = {(j, k): take((j, k), q[j][k]) for j in range(d) for k in range(d) if j in free or k in fixed}
        eg = [take(i, e_row[i]) for i in free]
        bs, vs = _face(qs, x, b, free, fixed, eg, take("alpha", e_alpha), take(0, best, got={}), take(0, value, got={}))
        # best and value are C-contiguous arrays here (np.zeros, np.maximum, np.where): reshape(-1) is a view
        best.reshape(-1)[sel], value.reshape(-1)[sel] = bs, vs
    return value, up(best + _up_pos(U * scale))  # and the symmetrisation's rounding over the box


def _face(q, x, b, free, fixed, eg, e_alpha, best, value, mask=None):
    """``quad_box_max``'s update of ``(best, value)`` by one face with free coordinates ``free`` (one or two) at the
    vertex coordinates ``x`` on ``fixed``, for entries where its leading entry a = Q_ff is negative (the only ones it
    can change): ``q`` the entries ``{(j, k): (m,)}``, ``eg`` g's error terms, ``e_alpha`` α's (the module's lemma).
    With ``mask`` (those entries among more) the result holds where it is true, and only those entries decide
    whether the determinants are recomputed exactly."""
    alpha = sum(q[j, k] * (x[j] * x[k]) for j in fixed for k in fixed)
    alpha_hi = up(alpha + e_alpha)
    g = [sum(q[i, k] * x[k] for k in fixed) for i in free]  # Q_FC x_C
    if len(free) == 1:
        (f,) = free
        a, ga = q[f, f], np.abs(g[0])
        aa = -a
        inside = down((ga - eg[0]) / aa) <= b[f]  # else |y*| > b_f certainly
        gh = _up_pos(ga + eg[0])
        cand = up(alpha_hi + _up_pos(gh * gh / aa))
        best = np.where(inside, np.maximum(best, cand), best)
        value = np.where(ga <= b[f] * aa, np.maximum(value, alpha + ga * ga / aa), value)
        return best, value
    f0, f1 = free
    a, c, e = q[f0, f0], q[f0, f1], q[f1, f1]
    g0, g1, eg0, eg1 = g[0], g[1], eg[0], eg[1]
    b0, b1 = b[f0], b[f1]
    ae, cc = a * e, c * c
    det = ae - cc
    e_det = gamma(2) * (np.abs(ae) + cc) * (1.0 + 4.0 * U)  # |fl(ae − c²) − (ae − c²)|
    if np.any(np.abs(det) <= e_det if mask is None else mask & (np.abs(det) <= e_det)):
        # the sign undecided somewhere: det nearly exactly, ae = p₁ + e₁, c² = p₂ + e₂ without error
        # (TwoProduct), det = (p₁ − p₂) + (e₁ − e₂) with two roundings (an exact tie gives det = 0 exactly)
        p1, e1 = _two_product(a, e)
        p2, e2 = _two_product(c, c)
        s1, s2 = p1 - p2, e1 - e2
        det = s1 + s2
        e_det = 2.0 * U * (np.abs(s1) + np.abs(s2)) * (1.0 + 4.0 * U)
    det_lo = np.where(e_det > 0, down(det - e_det), det)
    det_hi = np.where(e_det > 0, up(det + e_det), det)
    nd = det_lo > 0
    undecided = ~nd & (det_hi > 0)
    dl, dh = np.where(nd, det_lo, 1.0), np.where(nd, det_hi, 1.0)
    g00, g11, cg = g0 * g0, g1 * g1, c * g0 * g1
    ea, ca, aab = np.abs(e), np.abs(c), np.abs(a)
    N_hi = up(2.0 * cg - e * g00 - a * g11 + gamma(5) * (ea * g00 + 2.0 * np.abs(cg) + aab * g11))
    g_norm, eg_norm = np.hypot(g0, g1), np.hypot(eg0, eg1)
    extra = -(a + e) / dl * (2.0 * g_norm * eg_norm + eg_norm * eg_norm)  # ‖(−Q_FF)⁻¹‖ (2|g||Δg| + |Δg|²)
    cand = up(alpha_hi + _up_pos(np.maximum(N_hi, 0.0) / dl + extra))
    # y* = (−Q_FF)⁻¹ g = [−e g₀ + c g₁, c g₀ − a g₁] / det: skipped if some |y*_j| > b_j certainly
    a0, a1 = np.abs(g0), np.abs(g1)
    y0_err = _up_pos(gamma(3) * (ea * a0 + ca * a1) + ea * eg0 + ca * eg1)
    y1_err = _up_pos(gamma(3) * (ca * a0 + aab * a1) + ca * eg0 + aab * eg1)
    out = (down((np.abs(c * g1 - e * g0) - y0_err) / dh) > b0) | (down((np.abs(c * g0 - a * g1) - y1_err) / dh) > b1)
    box = up(
        alpha_hi + _up_pos(2.0 * ((a0 + eg0) * b0 + (a1 + eg1) * b1 + ca * (b0 * b1)) + np.maximum(e, 0.0) * b1**2)
    )
    best = np.where(nd & ~out, np.maximum(best, cand), best)
    best = np.where(undecided, np.maximum(best, box), best)
    ok = det > 0
    dv = np.where(ok, det, 1.0)
    ok &= (np.abs(c * g1 - e * g0) <= b0 * dv) & (np.abs(c * g0 - a * g1) <= b1 * dv)
    value = np.where(ok, np.maximum(value, alpha + (2.0 * cg - e * g00 - a * g11) / dv), value)
    return best, value


def _two_product(a, b):
    """``(p, e)`` with p = fl(a b) and p + e = a b exactly (Dekker's TwoProduct with Veltkamp's splitting; no
    overflow: |a|, |b| < 1e150 here)."""
    p = a * b
    ah, al = _split(a)
    bh, bl = _split(b)
    return p, ((ah * bh - p) + ah * bl + al * bh) + al * bl


def _split(a):
    c = 134217729.0 * a  # 2²⁷ + 1
    ah = c - (c - a)
    return ah, a - ah


def _up_pos(x):
    """``up`` for a computed x >= 0 (one operation fewer)."""
    return x * (1.0 + WIDEN) + TINY
