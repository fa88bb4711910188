"""The performance proof's floating-point rigour (``synthesis.verified``, ``synthesis.performance``): its centre
quantities are checked against independent exact or ball arithmetic. python-flint's arb (200-bit balls) gives the
rotation, the scaled J⁻¹, its singular values, the exact centre leg speed and force (the envelope's quadratic part
maximised exactly in rationals, ``fractions``), and the pencil's eigenvalues; the verified float bounds must contain
them, be tight (rigour is not bought with slack) and refuse a near-singular centre rather than prove it."""

from __future__ import annotations

import itertools
from fractions import Fraction

import numpy as np
import pytest
from flint import acb_mat, arb, arb_mat, ctx

from stewart_drake.core.dynamics import G_EARTH
from stewart_drake.synthesis.performance import (
    EPS_DROT,
    EPS_ROT,
    _certified_frequency,
    performance_bounds,
)
from stewart_drake.synthesis.proof import Cells, rotation_derivatives
from stewart_drake.synthesis.verified import U, certified_min_eig, gamma, quad_box_max


@pytest.fixture(autouse=True)
def prec200():
    old = ctx.prec
    ctx.prec = 200
    yield
    ctx.prec = old


# --- arb oracles -------------------------------------------------------------------------------------------------


def _elem(axis: int, t: arb) -> arb_mat:
    c, s = t.cos(), t.sin()
    R = [[arb(1 if i == j == axis else 0) for j in range(3)] for i in range(3)]
    i, j = (axis + 1) % 3, (axis + 2) % 3
    R[i][i], R[j][j], R[i][j], R[j][i] = c, c, -s, s
    return arb_mat(R)


def _rot(angles, convention) -> arb_mat:
    Rx, Ry, Rz = (_elem(k, arb(float(angles[k]))) for k in range(3))
    return Ry * Rx * Rz if convention == "utn" else Rz * Ry * Rx


def _vec(x) -> arb_mat:
    return arb_mat([[arb(float(v))] for v in x])


def _cross(a, b) -> arb_mat:
    return arb_mat([[a[1, 0] * b[2, 0] - a[2, 0] * b[1, 0]], [a[2, 0] * b[0, 0] - a[0, 0] * b[2, 0]],
                    [a[0, 0] * b[1, 0] - a[1, 0] * b[0, 0]]])  # fmt: skip


def _inverse_jacobian(p, pose, convention):
    """(J⁻¹ exact (6×6 arb), R) at the float pose: rows [u_i; r_i × u_i]."""
    R = _rot(pose[3:], convention)
    rows = []
    for i in range(6):
        t = _vec(p.top_anchors_per_leg[i]) - _vec(p.rotation_centre)
        r = R * t
        l = _vec(pose[:3]) + r - _vec(p.base_anchors[i])
        L = (l[0, 0] ** 2 + l[1, 0] ** 2 + l[2, 0] ** 2).sqrt()
        u = l * (1 / L)
        w = _cross(r, u)
        rows.append([u[k, 0] for k in range(3)] + [w[k, 0] for k in range(3)])
    return arb_mat(rows), R


def _eigs_sym(M: arb_mat) -> list:
    """Enclosures of a symmetric arb matrix's eigenvalues (Rump's verified algorithm), ascending by midpoint."""
    ev = [e.real for e in acb_mat(M).eig(algorithm="rump")]
    return sorted(ev, key=lambda e: float(e.mid()))


def _wrench_terms(p, R, gravity) -> arb_mat:
    """(6 × 16) the plate's wrench terms about C (``design.envelope.plate_wrench_terms``), written out again."""
    m = arb(float(p.mass))
    r = R * (_vec(p.com) - _vec(p.rotation_centre))
    I_W = R * arb_mat(p.inertia.tolist()) * R.transpose()
    g = arb_mat([[arb(0)], [arb(0)], [m * arb(float(gravity))]])
    cols = [[g[k, 0] for k in range(3)] + [_cross(r, g)[k, 0] for k in range(3)]]
    S = arb_mat([[0, -r[2, 0], r[1, 0]], [r[2, 0], 0, -r[0, 0]], [-r[1, 0], r[0, 0], 0]])
    for j in range(3):  # M_C [a; 0]
        e = arb_mat([[arb(int(k == j))] for k in range(3)])
        f, tq = e * m, S * e * m
        cols.append([f[k, 0] for k in range(3)] + [tq[k, 0] for k in range(3)])
    for j in range(3):  # M_C [0; ω̇]
        e = arb_mat([[arb(int(k == j))] for k in range(3)])
        f, tq = -(S * e) * m, (I_W - S * S * m) * e
        cols.append([f[k, 0] for k in range(3)] + [tq[k, 0] for k in range(3)])

    def h(w):
        f = _cross(w, _cross(w, r)) * m
        tq = _cross(w, I_W * w) + _cross(r, f)
        return [f[k, 0] for k in range(3)] + [tq[k, 0] for k in range(3)]

    E = [arb_mat([[arb(int(k == j))] for k in range(3)]) for j in range(3)]
    for j in range(3):
        for k in range(3):
            col = h(E[j]) if j == k else [(a - b - c) / 2 for a, b, c in zip(h(E[j] + E[k]), h(E[j]), h(E[k]))]
            cols.append(col)
    return arb_mat([[cols[c][i] for c in range(16)] for i in range(6)])


# --- an exact quadratic maximum over a box, in rationals -----------------------------------------------------------


def _solve(A, y):
    """Exact solve of a small rational system (Gauss–Jordan); None when singular."""
    n = len(A)
    M = [list(A[i]) + [y[i]] for i in range(n)]
    for c in range(n):
        piv = next((r for r in range(c, n) if M[r][c] != 0), None)
        if piv is None:
            return None
        M[c], M[piv] = M[piv], M[c]
        for r in range(n):
            if r != c and M[r][c] != 0:
                f = M[r][c] / M[c][c]
                M[r] = [a - f * b for a, b in zip(M[r], M[c])]
    return [M[i][n] / M[i][i] for i in range(n)]


def _det(A):
    if len(A) == 1:
        return A[0][0]
    return sum((-1) ** j * A[0][j] * _det([row[:j] + row[j + 1 :] for row in A[1:]]) for j in range(len(A)))


def exact_box_max(Q, b) -> Fraction:
    """max xᵀQx over |x_j| <= b_j in exact rational arithmetic: every face, its stationary point when Q_FF is
    negative definite (leading minors' signs) and inside the box, every vertex, and 0."""
    d = len(b)
    Qf = [[(Fraction(Q[i][j]) + Fraction(Q[j][i])) / 2 for j in range(d)] for i in range(d)]
    bf = [Fraction(v) for v in b]
    best = Fraction(0)
    for p in itertools.product((-1, 0, 1), repeat=d):
        free = [j for j in range(d) if p[j] == 0]
        x = [p[j] * bf[j] for j in range(d)]
        if free:
            QFF = [[Qf[i][j] for j in free] for i in free]
            if not all((-1) ** (k + 1) * _det([row[: k + 1] for row in QFF[: k + 1]]) > 0 for k in range(len(free))):
                continue
            g = [sum(Qf[i][k] * x[k] for k in range(d) if p[k] != 0) for i in free]
            y = _solve(QFF, [-v for v in g])
            if y is None or any(abs(v) > bf[j] for v, j in zip(y, free)):
                continue
            for v, j in zip(y, free):
                x[j] = v
        best = max(best, sum(Qf[i][j] * x[i] * x[j] for i in range(d) for j in range(d)))
    return best


# --- tests ---------------------------------------------------------------------------------------------------------


def _skew_axis(k: int) -> arb_mat:
    S = [[arb(0)] * 3 for _ in range(3)]
    i, j = (k + 1) % 3, (k + 2) % 3
    S[i][j], S[j][i] = arb(-1), arb(1)
    return arb_mat(S)


def _rot_derivatives(angles, convention) -> list:
    """Exact ∂R/∂θ_j (arb) for the two conventions' products of elementary rotations."""
    Rx, Ry, Rz = (_elem(k, arb(float(angles[k]))) for k in range(3))
    Sx, Sy, Sz = (_skew_axis(k) for k in range(3))
    if convention == "utn":  # R = Ry Rx Rz
        return [Ry * Rx * Sx * Rz, Sy * Ry * Rx * Rz, Ry * Rx * Rz * Sz]
    return [Rz * Ry * Rx * Sx, Rz * Ry * Sy * Rx, Sz * Rz * Ry * Rx]  # R = Rz Ry Rx


def _fro_err(exact: arb_mat, approx) -> float:
    """An upper bound of the Frobenius norm of exact − approx (3 × 3)."""
    return float(sum(((exact[i, j] - arb(float(approx[i, j]))) ** 2).upper() for i in range(3) for j in range(3)))


def test_rotation_rounding_within_the_derived_constants():
    """The computed R(c) and ∂R/∂θ_j (``proof.rotation_derivatives``) at 300 random angles per convention are within
    EPS_ROT = 64u and EPS_DROT = 128u (spectral norm, bounded by Frobenius) of arb's exact ones; the constants are
    the derivation's (sin/cos within 4 ulp = 8u relative, three factors of ‖|R_e|‖₂ <= √2, two or three rounded
    3 × 3 products): 3·8√2u(1 + 8√2u)² + γ₃·(2 + 2√2) < 64u."""
    assert 3 * 8 * np.sqrt(2) * U * (1 + 8 * np.sqrt(2) * U) ** 2 + gamma(3) * (2 + 2 * np.sqrt(2)) < EPS_ROT
    rng = np.random.default_rng(11)
    worst = 0.0
    for convention in ("utn", "zyx"):
        th = rng.uniform(-np.pi, np.pi, (300, 3))
        R, dR = rotation_derivatives(th, convention)
        for n in range(len(th)):
            err = _fro_err(_rot(th[n], convention), R[n])
            worst = max(worst, err)
            assert np.sqrt(err) <= EPS_ROT
            for j, dRj in enumerate(_rot_derivatives(th[n], convention)):
                assert np.sqrt(_fro_err(dRj, dR[n, j])) <= EPS_DROT
    assert worst > 0  # the check saw rounding


def test_quadratic_maximum_upper_bound_contains_the_exact_rational_maximum():
    """``quad_box_max`` against the exact maximum in rationals on 400 quadratic forms: random ones, integer
    ones (stationary points exactly on the box's faces, exact ties), and nearly singular free blocks (det of Q_FF
    a few ulp from 0, where the float decision of definiteness is undecided). The bound is never below the exact
    maximum and within 1e-9 of its scale Σ|Q_jk| b_j b_k above it (tight); the float value within 1e-9 of it."""
    rng = np.random.default_rng(12)
    cases = []
    for _ in range(150):
        cases.append((rng.normal(size=(3, 3)), rng.uniform(0.05, 2.0, 3)))
    for _ in range(150):
        cases.append((rng.integers(-3, 4, (3, 3)).astype(float), np.array([1.0, 1.0, 2.0])))
    for _ in range(100):
        a, c = -rng.uniform(0.5, 2), rng.normal()
        Q = rng.normal(size=(3, 3))
        Q[0, 0], Q[0, 1], Q[1, 0] = a, c, c
        Q[1, 1] = c * c / a * (1 + rng.integers(-4, 5) * U)  # ae − c² within a few ulp of 0
        cases.append((Q, rng.uniform(0.1, 1.0, 3)))
    for d in (1, 2):
        cases += [(rng.normal(size=(d, d)), rng.uniform(0.1, 1.0, d)) for _ in range(20)]
    for Q, b in cases:
        value, bound = (float(v[0]) for v in quad_box_max(Q[None], b))
        exact = exact_box_max(Q.tolist(), b.tolist())
        scale = float(np.sum(np.abs(Q) * np.outer(b, b)))
        assert Fraction(bound) >= exact, (Q, b)
        assert abs(value - float(exact)) <= 1e-9 * scale  # the float value: the centre's sample
        assert bound - float(exact) <= 1e-9 * scale, (Q, b, bound, float(exact))


def test_cholesky_certificate_never_exceeds_the_true_least_eigenvalue():
    """``certified_min_eig`` on symmetric 6 × 6 matrices against arb's least eigenvalue (Rump's verified algorithm):

    - 150 with least eigenvalues 1 .. 1e-13 of the trace: with a shift 64γ₇ tr below it the bound is within 1e-12 tr
      (tight); a shift 1e-12 tr above it is refused (−inf);
    - 100 nearly singular ones (least eigenvalue 1e-14 .. 1e-18 of the trace) with shifts 0.05 .. 2 u tr above it:
      floating-point Cholesky of X − s 1 then sometimes runs to completion although X − s 1 is indefinite (it does
      here: the rounding term is what keeps the bound below λ_min), and the certified bound is never above λ_min."""
    rng = np.random.default_rng(13)

    def draw(lam):
        V, _r = np.linalg.qr(rng.normal(size=(6, 6)))
        X = (V * lam) @ V.T
        X = 0.5 * (X + X.T)
        ev = _eigs_sym(arb_mat(X.tolist()))[0]
        return X, float(ev.lower()), float(ev.upper()), float(np.trace(X))

    for _ in range(150):
        X, lo, _hi, tr = draw(np.r_[10.0 ** -rng.uniform(0, 13), rng.uniform(0.5, 1.0, 5)])
        lb = certified_min_eig(X[None], 0.0, np.array([lo - 64 * gamma(7) * tr]))[0]
        assert lo - 1e-12 * tr <= lb <= lo
        assert certified_min_eig(X[None], 0.0, np.array([lo + 1e-12 * tr]))[0] == -np.inf
    completed = 0
    for _ in range(100):
        X, lo, hi, tr = draw(np.r_[10.0 ** -rng.uniform(14, 18), rng.uniform(0.5, 1.0, 5)])
        for k in (0.05, 0.2, 0.5, 1.0, 2.0):
            s = hi + k * U * tr  # above the exact least eigenvalue: X − s 1 is indefinite
            lb = certified_min_eig(X[None], 0.0, np.array([s]))[0]
            assert lb <= lo
            completed += int(np.isfinite(lb))
    assert completed > 0  # Cholesky ran to completion on indefinite matrices: the test has teeth


def test_centre_bounds_contain_the_exact_values_in_ball_arithmetic(req, design):
    """On 60 point cells (h = 0: only COVER_PAD's 1e-12 remains) at random poses of the box: the force, speed and
    condition bounds contain the exact centre values computed in arb (J⁻¹ from the exact rotation, singular values
    by Rump's verified eigenvalues of J_sᵀJ_s, the force as A⁻ᵀ w with the envelope's quadratic part maximised in
    rationals at the balls' midpoints, radius < 1e-50) and are within 1e-8 relative of them."""
    rng = np.random.default_rng(14)
    home = design.home_pose()
    c = home + req.box_lo + rng.random((60, 6)) * (req.box_hi - req.box_lo)
    b = performance_bounds(design, Cells(c, np.zeros_like(c)), req.v_max, req.a_max, req.stiffness, req.convention)
    s = float(np.max(np.linalg.norm(design.top_anchors - design.rotation_centre, axis=1)))
    vel = np.flatnonzero(req.v_max[3:] > 0)
    for n in range(len(c)):
        A, R = _inverse_jacobian(design, c[n], req.convention)
        As = A * arb_mat([[arb(1) if i == j and i < 3 else (1 / arb(s) if i == j else arb(0)) for j in range(6)]
                          for i in range(6)])  # fmt: skip
        ev = _eigs_sym(As.transpose() * As)
        cond = (ev[-1] / ev[0]).sqrt()
        assert float(cond.upper()) <= b.condition[n] <= float(cond.mid()) * (1 + 1e-8)
        speed = max(sum(abs(A[i, j]) * arb(float(req.v_max[j])) for j in range(6)) for i in range(6))
        assert float(speed.upper()) <= b.speed[n] <= float(speed.mid()) * (1 + 1e-8)
        Xw = A.transpose().solve(_wrench_terms(design, R, G_EARTH))  # (6, 16) exact A⁻ᵀ w
        peak = Fraction(0)
        for i in range(6):
            cF = Fraction(float(Xw[i, 0].mid()))
            lin = sum(abs(Fraction(float(Xw[i, 1 + j].mid()))) * Fraction(float(req.a_max[j])) for j in range(6))
            Qi = [[float(Xw[i, 7 + 3 * j + k].mid()) for k in vel] for j in vel]
            bv = [float(req.v_max[3 + j]) for j in vel]
            qmax = exact_box_max(Qi, bv)
            qmin = exact_box_max([[-v for v in row] for row in Qi], bv)
            peak = max(peak, cF + lin + qmax, -cF + lin + qmin)
        assert float(peak) * (1 + 1e-40) <= b.force[n] <= float(peak) * (1 + 1e-8)


def test_pencil_certificate_below_the_exact_least_eigenvalue():
    """``_certified_frequency`` on 60 random stiffness/inertia pencils (K_lo = k' G − ε_K 1, M_s + ε_M 1): the
    certified frequency's (2π f)² is never above arb's least eigenvalue of M_hi⁻¹ K_lo, and below it by no more than
    the trial's stated offset (rounding-sized: 1e-13 of tr K_lo over λ_min(M_hi), plus 1e-9 relative)."""
    rng = np.random.default_rng(15)
    n = 60
    A = rng.normal(size=(n, 6, 6))
    G = np.einsum("nki,nkj->nij", A, A)
    G = 0.5 * (G + np.swapaxes(G, -1, -2))
    Bm = rng.normal(size=(n, 6, 6))
    M = np.einsum("nki,nkj->nij", Bm, Bm) + np.eye(6)
    M = 0.5 * (M + np.swapaxes(M, -1, -2))
    k = rng.uniform(1e6, 1e8, n)
    eps_K = rng.uniform(0, 1e-3, n) * k * np.linalg.eigvalsh(G)[:, 0]
    eps_M = rng.uniform(0, 1e-3, n)
    e_G = gamma(8) * np.sum(A**2, axis=(-2, -1))
    f = _certified_frequency(k, G, e_G, eps_K, M, eps_M)
    assert np.all(f > 0)
    for i in range(n):
        K_lo = arb_mat(G[i].tolist()) * arb(float(k[i])) - arb_mat(np.eye(6).tolist()) * arb(float(eps_K[i]))
        M_hi = arb_mat(M[i].tolist()) + arb_mat(np.eye(6).tolist()) * arb(float(eps_M[i]))
        lam = min((e.real for e in acb_mat(M_hi.solve(K_lo)).eig(algorithm="rump")), key=lambda e: float(e.mid()))
        lam_f = (2 * arb.pi() * arb(float(f[i]))) ** 2
        assert float(lam_f.upper()) <= float(lam.lower())  # certified: below the exact value, balls included
        # tight: the trial λ sits 1e-9 relative and 4 (e_K + γ₈ tr)/λ_min(M_hi) below the float one, and
        # e_K + γ₈ tr < 3 γ₈ tr(K_lo) here, so the loss times λ_min(M_hi) is below 1e-13 tr(K_lo) + 1e-9 λ λ_min(M_hi)
        mu = np.linalg.eigvalsh(M[i])[0] + eps_M[i]
        loss = float((lam - lam_f).mid())
        assert loss * mu <= 1e-13 * (k[i] * np.trace(G[i])) + 1e-9 * float(lam.mid()) * mu


def test_near_singular_centre_is_refused_not_proven(req, design):
    """At γ = 90° the design's J⁻¹ is singular. Point cells at 1e-9 .. 1e-3 rad from it: where the centre is
    nearly singular (float condition 1e7 and beyond, where the Gram matrix's rounding reaches σ_min²) the bounds
    are refused (force and condition inf, frequency 0) while the float sample is still finite; nearer the
    well-conditioned end they are proven, and each proven condition bound contains arb's."""
    home = design.home_pose()
    offs = np.array([1e-9, 1e-8, 1e-6, 1e-4, 1e-3])
    c = np.tile(home, (len(offs), 1))
    c[:, 5] = np.pi / 2 + offs
    b = performance_bounds(design, Cells(c, np.zeros_like(c)), req.v_max, req.a_max, req.stiffness, req.convention)
    near = b.centre_condition > 1e7
    assert near.any() and (~near).any()
    assert np.all(np.isfinite(b.centre_condition[near]))  # the float sample: finite, a sample only
    assert np.all(b.condition[near] == np.inf) and np.all(b.force[near] == np.inf) and np.all(b.frequency[near] == 0)
    s = float(np.max(np.linalg.norm(design.top_anchors - design.rotation_centre, axis=1)))
    for n in np.flatnonzero(np.isfinite(b.condition)):
        A, _ = _inverse_jacobian(design, c[n], req.convention)
        D = arb_mat([[arb(1) if i == j and i < 3 else (1 / arb(s) if i == j else arb(0)) for j in range(6)]
                     for i in range(6)])  # fmt: skip
        As = A * D
        ev = _eigs_sym(As.transpose() * As)
        assert float((ev[-1] / ev[0]).sqrt().upper()) <= b.condition[n]
