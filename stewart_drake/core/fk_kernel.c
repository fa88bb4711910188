/* Real-time forward kinematics of stewart_drake.core.realtime_fk: Newton from the previous pose with a
 * certificate that the new pose is on the previous pose's branch (assembly mode).
 *
 * Newton is the numpy reference's (newton_fk.newton_core) step for step: iterate on the rotation centre's
 * position p and the orientation R, solve J d = L* - L(p, R) with rows [u_i, r_i x u_i], scale the step so
 * that |dp| <= max_step_m and |w| <= max_step_rad, update p += dp, R = exp([w]x) R. The first step uses the
 * inverse of J(y0) the certificate needs (one Gauss-Jordan pass), later steps an LU (a last chord step may
 * reuse it, see REUSE_MARGIN): each step is Newton's to rounding.
 *
 * Certificate (see realtime_fk.py for the argument): in the coordinates y = (p, a w) around the previous
 * pose y0 (a the anchor radius, R = exp([w]x) R0), F(y) = L(y) - L*. With beta >= |J(y0)^-1| (2-norm, from
 * the computed inverse X and its residual |I - X J|_F), gamma(rho) a Lipschitz constant of F' on the ball
 * B(y0, rho) (from |d exp([w]x) r| <= |r| e^|w| |dw| and its second derivative bound, term by term of the
 * series) and eta >= |J^-1 F(y0)|:
 *   uniqueness (lemma): beta gamma(rho) rho < 1  => F has at most one zero in B(y0, rho), for every L*
 *               (two zeros y1, y2: 0 = (J(y0) + E)(y1 - y2), |J(y0)^-1 E| <= beta gamma rho < 1);
 *   branch:     2 eta <= rho              => along L(s) = L(y0) + s (L* - L(y0)), s in [0, 1], the zero
 *               in B(y0, rho) exists (Kantorovich, h(s) = s beta gamma eta <= 1/2), is unique and moves
 *               continuously: it is y0's branch.
 * rho is the largest radius found by three trials (rho_s, c = 0.999 / (beta gamma(rho_s)), and 2 eta when the
 * first two fall below it: gamma is taken on the smallest ball the branch test needs).
 * The Newton result is accepted as that zero when it lies in B(y0, rho). Evaluated in double precision
 * with the rounding of the 6x6 products covered by a relative margin (MARGIN), not interval arithmetic.
 *
 * Speed: independent length sets run two at a time (newton_pair), their factorisations interleaved column by
 * column, so that one solve's chain of dependent operations fills the other's waits; each set sees exactly
 * the operations it sees alone (the same bits, tests/core/test_realtime_fk_pairs.py). The Gauss-Jordan inverse runs
 * in place (the pivot's column takes the inverse's column), the Jacobian rows are built two legs a lane pair, and
 * the module is built with -fno-math-errno (sqrt one instruction): each a change of the work's shape, not of any
 * operation, so every output keeps its bits.
 */
#include <math.h>
#include <stdint.h>

enum { CONVERGED = 0, MAX_ITER = 1, DIVERGED = 2, SINGULAR = 3 };
enum { I_RES = 0, I_ITER, I_STATUS, I_CERT, I_RADIUS, I_ETA, I_STEP, I_SUB, N_INFO };

#define DIVERGENCE_FACTOR 1e3
#define MAX_STEP_M 0.1
#define MAX_STEP_RAD 0.5
#define MARGIN 1e-9
/* A Newton step reuses the previous iterate's factorisation (a chord step) when the predicted chord residual is
 * below tol / REUSE_MARGIN: the chord's rate is beta * gamma * |dy| with |dy| ~ beta * res_prev, which is also
 * Newton's observed rate res / res_prev, so the chord leaves ~ res^2 / res_prev. Convergence is still decided by
 * res <= tol at the true lengths; only when the prediction is far off does an iteration more run. The margin
 * 1e3 puts the chord's residual below rounding, so the pose is the full Newton's to rounding where certified
 * (1e-15 m on the presets, 1e5 workspace solves each; with 1e2 it was 1e-13 m). */
#define REUSE_MARGIN 1e3
/* The factorisation at hand: none, the inverse Y of J(y0) (computed for the certificate and the first step), or an
 * LU of J at a later iterate (the only one a chord step reuses: a chord with Y would leave Newton's path). */
enum { NONE = 0, INVERSE = 1, LU = 2 };

/* g: base anchors (6x3), plate anchors relative to the rotation centre in T (6x3), anchor radius a,
 * size0 = max(|base anchors|max, |top anchors|max) (the numpy divergence test's scale), |t_i| (6). */
enum { G_BASE = 0, G_TOP = 18, G_A = 36, G_SIZE = 37, G_RT = 38, N_GEOM = 44 }; /* G_RT: |t_i| */

/* The 6x6 matrices are kept as rows of six doubles in three SIMD pairs (the GCC/Clang vector extension: SSE2
 * on x86-64, NEON on arm64), so that a row operation is three paired multiplies and subtracts; element j of a
 * row is v[j >> 1][j & 1]. Each element sees the same operations, in the same order, as in scalar code. */
typedef double v2 __attribute__((vector_size(16)));
typedef long long m2 __attribute__((vector_size(16)));
typedef struct { v2 v[3]; } row6;
#define EL(row, j) ((row).v[(j) >> 1][(j) & 1])

static void rotation(int conv, const double *ang, double R[9]) {
    double ca = cos(ang[0]), cb = cos(ang[1]), cg = cos(ang[2]);
    double sa = sin(ang[0]), sb = sin(ang[1]), sg = sin(ang[2]);
    if (conv == 0) { /* utn: Ry(b) Rx(a) Rz(g) */
        R[0] = cb * cg + sa * sb * sg; R[1] = sa * sb * cg - cb * sg; R[2] = ca * sb;
        R[3] = ca * sg; R[4] = ca * cg; R[5] = -sa;
        R[6] = sa * cb * sg - sb * cg; R[7] = sb * sg + sa * cb * cg; R[8] = ca * cb;
    } else { /* zyx: Rz(psi) Ry(theta) Rx(phi) */
        R[0] = cb * cg; R[1] = sa * sb * cg - ca * sg; R[2] = ca * sb * cg + sa * sg;
        R[3] = cb * sg; R[4] = sa * sb * sg + ca * cg; R[5] = ca * sb * sg - sa * cg;
        R[6] = -sb; R[7] = sa * cb; R[8] = ca * cb;
    }
}

static double clip1(double x) { return x < -1.0 ? -1.0 : (x > 1.0 ? 1.0 : x); }

static void angles(int conv, const double R[9], double *ang) {
    if (conv == 0) {
        ang[0] = asin(clip1(-R[5]));
        if (R[2] * R[2] + R[8] * R[8] < 1e-24) { /* hypot < 1e-12 (no underflow at these magnitudes) */
            ang[1] = atan2(-R[6], R[0]);
            ang[2] = 0.0;
        } else {
            ang[1] = atan2(R[2], R[8]);
            ang[2] = atan2(R[3], R[4]);
        }
    } else {
        ang[1] = asin(clip1(-R[6]));
        if (R[7] * R[7] + R[8] * R[8] < 1e-24) {
            ang[0] = 0.0;
            ang[2] = atan2(-R[1], R[4]);
        } else {
            ang[0] = atan2(R[7], R[8]);
            ang[2] = atan2(R[3], R[0]);
        }
    }
}

/* The geometry for the hot loop: g, and the plate and base anchors by coordinate in leg pairs (t[k][j] holds
 * coordinate k of legs 2j and 2j + 1), so that the leg vectors are computed two legs at a time. */
typedef struct { const double *g; v2 t[3][3], b[3][3]; } geom;

static void geom_init(geom *G, const double *g) {
    G->g = g;
    for (int k = 0; k < 3; k++)
        for (int j = 0; j < 3; j++) {
            G->t[k][j] = (v2){g[G_TOP + 6 * j + k], g[G_TOP + 6 * j + 3 + k]};
            G->b[k][j] = (v2){g[G_BASE + 6 * j + k], g[G_BASE + 6 * j + 3 + k]};
        }
}

/* Leg vectors l_i = p + R t_i - b_i, lengths, plate vectors r_i = R t_i, two legs a lane pair: r[k][j], l[k][j]
 * hold coordinate k of legs 2j, 2j + 1. Each lane sees the scalar expression's operations in its order. */
static void legs(const geom *G, const double p[3], const double R[9], v2 r[3][3], v2 l[3][3], double L[6]) {
    for (int k = 0; k < 3; k++) { /* each entry of R and p broadcast once */
        v2 R0 = {R[3 * k], R[3 * k]}, R1 = {R[3 * k + 1], R[3 * k + 1]}, R2 = {R[3 * k + 2], R[3 * k + 2]};
        v2 pk = {p[k], p[k]};
        for (int j = 0; j < 3; j++) {
            r[k][j] = R0 * G->t[0][j] + R1 * G->t[1][j] + R2 * G->t[2][j];
            l[k][j] = pk + r[k][j] - G->b[k][j];
        }
    }
    for (int j = 0; j < 3; j++) {
        v2 s = l[0][j] * l[0][j] + l[1][j] * l[1][j] + l[2][j] * l[2][j];
        L[2 * j] = sqrt(s[0]);
        L[2 * j + 1] = sqrt(s[1]);
    }
}

/* Rows [u_i, r_i x u_i] (the unscaled J^-1 of newton_fk), two legs a lane pair (each lane the scalar expression's
 * operations: one division, the cross product), the rows assembled from the lanes. */
static void jac(v2 r[3][3], v2 l[3][3], const double L[6], row6 J[6]) {
    for (int j = 0; j < 3; j++) {
        v2 il = (v2){1.0, 1.0} / (v2){L[2 * j], L[2 * j + 1]};
        v2 ux = l[0][j] * il, uy = l[1][j] * il, uz = l[2][j] * il;
        v2 cx = r[1][j] * uz - r[2][j] * uy, cy = r[2][j] * ux - r[0][j] * uz, cz = r[0][j] * uy - r[1][j] * ux;
        for (int h = 0; h < 2; h++) {
            J[2 * j + h].v[0] = (v2){ux[h], uy[h]};
            J[2 * j + h].v[1] = (v2){uz[h], cx[h]};
            J[2 * j + h].v[2] = (v2){cy[h], cz[h]};
        }
    }
}

/* The partial pivot of column k: the first row i >= k of largest |A[i][k]|, that value in *big. It selects rather
 * than jumps: no mispredicted branches. Shared by lu_column and gj_column (the same pivot choice). */
static inline int pivot_row(const row6 A[6], int k, double *big) {
    int m = k;
    double b = fabs(EL(A[k], k));
    for (int i = k + 1; i < 6; i++) {
        double v = fabs(EL(A[i], k));
        int gt = v > b;
        m = gt ? i : m;
        b = gt ? v : b;
    }
    *big = b;
    return m;
}

/* LU with partial pivoting in place (LAPACK's dgetf2: multipliers below the diagonal, rows swapped whole);
 * 0 when a pivot is exactly zero (numpy's LinAlgError). Each update runs over the whole row with the pivot
 * row's columns <= k masked to zero (so those columns of the updated row are unchanged; pairs wholly left of
 * column k are skipped), then column k takes the multiplier. The swap is unconditional (a row with itself when
 * m == k): no mispredicted branches. */
static inline int lu_column(row6 A[6], int piv[6], double dinv[6], int k) { /* called with constant k: unrolled */
    double big;
    int m = pivot_row(A, k, &big);
    piv[k] = m;
    if (big == 0.0) return 0;
    row6 t = A[k];
    A[k] = A[m];
    A[m] = t;
    double inv = dinv[k] = 1.0 / EL(A[k], k);
    m2 kk = {k, k};
    v2 u0 = (v2)((m2)A[k].v[0] & ((m2){0, 1} > kk)), u1 = (v2)((m2)A[k].v[1] & ((m2){2, 3} > kk)),
       u2 = (v2)((m2)A[k].v[2] & ((m2){4, 5} > kk));
    for (int i = k + 1; i < 6; i++) {
        double f = EL(A[i], k) * inv;
        v2 fv = {f, f};
        if (k < 2) A[i].v[0] -= fv * u0; /* pairs wholly left of column k: multipliers, left as they are */
        if (k < 4) A[i].v[1] -= fv * u1;
        A[i].v[2] -= fv * u2;
        EL(A[i], k) = f;
    }
    return 1;
}

static int lu(row6 A[6], int piv[6], double dinv[6]) {
    return lu_column(A, piv, dinv, 0) && lu_column(A, piv, dinv, 1) && lu_column(A, piv, dinv, 2) &&
           lu_column(A, piv, dinv, 3) && lu_column(A, piv, dinv, 4) && lu_column(A, piv, dinv, 5);
}

static void lu_solve(const row6 A[6], const int piv[6], const double dinv[6], double x[6]) {
    for (int k = 0; k < 6; k++) { /* rows were swapped whole (multipliers too): permute first */
        double t = x[k]; x[k] = x[piv[k]]; x[piv[k]] = t;
    }
    for (int k = 0; k < 6; k++)
        for (int i = k + 1; i < 6; i++) x[i] -= EL(A[i], k) * x[k];
    for (int k = 5; k >= 0; k--) {
        for (int j = k + 1; j < 6; j++) x[k] -= EL(A[k], j) * x[j];
        x[k] *= dinv[k]; /* the pivots' reciprocals: no division on the substitution's critical path */
    }
}

/* The inverse by Gauss-Jordan elimination with partial pivoting (the same pivot choice as lu), in place: rows swapped
 * whole, the pivot row scaled by the pivot's reciprocal, every other row cleared, and the pivot's column k, no longer
 * needed for A, takes the inverse's column orig[k] (the pivot row's unit column of [A | I], orig tracking the row
 * swaps): each inverse entry sees exactly the operations of the elimination on [A | I] (0 - f inv for the new
 * column, x - f y for the others), with half the row operations; gj_unscramble puts the columns in order. One pass,
 * half the operations of lu and two triangular solves. 0 when a pivot is exactly zero. A is overwritten. */
static inline int gj_column(row6 A[6], int orig[6], int k) { /* called with constant k: unrolled */
    double big;
    int m = pivot_row(A, k, &big);
    if (big == 0.0) return 0;
    row6 t = A[k];
    A[k] = A[m];
    A[m] = t;
    int o = orig[k];
    orig[k] = orig[m];
    orig[m] = o;
    double inv = 1.0 / EL(A[k], k);
    v2 iv = {inv, inv};
    EL(A[k], k) = 1.0; /* the unit entry of [A | I] */
    for (int q = 0; q < 3; q++) A[k].v[q] *= iv;
    for (int i = 0; i < 6; i++) {
        if (i == k) continue;
        double f = EL(A[i], k);
        v2 fv = {f, f};
        EL(A[i], k) = 0.0;
        for (int q = 0; q < 3; q++) A[i].v[q] -= fv * A[k].v[q];
    }
    return 1;
}

static void gj_unscramble(const row6 A[6], const int orig[6], row6 X[6]) {
    for (int i = 0; i < 6; i++)
        for (int k = 0; k < 6; k++) EL(X[i], orig[k]) = EL(A[i], k);
}

static int gj_inverse(row6 A[6], row6 X[6]) {
    int orig[6] = {0, 1, 2, 3, 4, 5};
    if (!(gj_column(A, orig, 0) && gj_column(A, orig, 1) && gj_column(A, orig, 2) && gj_column(A, orig, 3) &&
          gj_column(A, orig, 4) && gj_column(A, orig, 5)))
        return 0;
    gj_unscramble(A, orig, X);
    return 1;
}

/* R <- exp([w]x) R (Rodrigues, the numpy _exp_so3's series below 1e-6 rad). */
static void rotate(const double w[3], double R[9]) {
    /* th < 1e-6 and th < 1e-2 tested on th^2: the square root only where sin and cos need th */
    double th2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2], A, B;
    if (th2 < 1e-12) { A = 1.0 - th2 / 6.0; B = 0.5 - th2 / 24.0; }
    else if (th2 < 1e-4) { /* the series to th^6: the next terms are below 3e-22, under the rounding of sin, cos */
        A = 1.0 - th2 * (1.0 / 6.0 - th2 * (1.0 / 120.0 - th2 * (1.0 / 5040.0)));
        B = 0.5 - th2 * (1.0 / 24.0 - th2 * (1.0 / 720.0 - th2 * (1.0 / 40320.0)));
    } else { double th = sqrt(th2); A = sin(th) / th; B = (1.0 - cos(th)) / (th * th); }
    /* E = I + A [w]x + B [w]x^2 with [w]x^2 = w w^T - th^2 I written out (the zeros of [w]x not multiplied) */
    double Ax = A * w[0], Ay = A * w[1], Az = A * w[2], Bxy = B * w[0] * w[1], Bxz = B * w[0] * w[2], Byz = B * w[1] * w[2];
    double E[9] = {1.0 - B * (w[1] * w[1] + w[2] * w[2]), Bxy - Az, Bxz + Ay,
                   Bxy + Az, 1.0 - B * (w[0] * w[0] + w[2] * w[2]), Byz - Ax,
                   Bxz - Ay, Byz + Ax, 1.0 - B * (w[0] * w[0] + w[1] * w[1])}, out[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) out[3 * i + j] = E[3 * i] * R[j] + E[3 * i + 1] * R[3 + j] + E[3 * i + 2] * R[6 + j];
    for (int k = 0; k < 9; k++) R[k] = out[k];
}

/* Lipschitz constant of F' on B(y0, rho) in y = (p, a w): per leg, |D l| <= c1 |dy|, |D^2 l| <= |t| E / a^2 |dy|^2
 * with E = e^(rho / a), |l| >= |l0| - c1 rho; |D^2 |l|| <= c1^2 / |l| + |t| E / a^2; gamma = sqrt(sum M_i^2).
 * rt: |t_i|, the plate anchors' distances from the rotation centre. */
static double lipschitz(double a, const double rt[6], const double L0[6], double rho) {
    double ia = 1.0 / a, q = exp(rho * ia) * ia, s = 0.0; /* reciprocals: a few ulps, well inside MARGIN */
    for (int i = 0; i < 6; i++) {
        double c1sq = 1.0 + (rt[i] * q) * (rt[i] * q), lmin = L0[i] - sqrt(c1sq) * rho;
        if (!(lmin > 0)) return INFINITY;
        double M = c1sq / lmin + rt[i] * q * ia;
        s += M * M;
    }
    return sqrt(s) * (1.0 + MARGIN);
}

/* d = X e for a 6x6 X kept in rows (the chord step with the explicit inverse). */
static void matvec(const row6 X[6], const double e[6], double d[6]) {
    v2 e0 = {e[0], e[1]}, e1 = {e[2], e[3]}, e2 = {e[4], e[5]};
    for (int i = 0; i < 6; i++) {
        v2 t = X[i].v[0] * e0 + X[i].v[1] * e1 + X[i].v[2] * e2;
        d[i] = t[0] + t[1];
    }
}

/* The certificate at y0 from the unscaled J(y0) (J0) and its computed inverse Y, the leg lengths L0 at y0, the
 * first Newton step d0 = Y (Lt - L0) and |Lt - L0|: uniqueness radius rho (0 when J(y0) is too badly conditioned
 * to bound) and eta. The scaled J_s = J D^-1, D = diag(1, 1, 1, a, a, a): J_s^-1 = D J^-1. */
static void certificate(const double *g, const row6 J0[6], const row6 Y[6], const double L0[6], const double d0[6],
                        double nf, double *rho_out, double *eta_out) {
    double a = g[G_A], D[6] = {1, 1, 1, a, a, a};
    row6 X[6], Dinv = {{{1, 1}, {1, 1 / a}, {1 / a, 1 / a}}};
    const double *rt = g + G_RT;
    *rho_out = 0.0;
    *eta_out = INFINITY;
    for (int i = 0; i < 6; i++) {
        v2 di = {D[i], D[i]};
        for (int q = 0; q < 3; q++) X[i].v[q] = di * Y[i].v[q]; /* X = J_s^-1 = D J^-1 */
    }
    v2 dfv = {0, 0}, xfv = {0, 0};
    for (int i = 0; i < 6; i++) {
        row6 row = {{{0, 0}, {0, 0}, {0, 0}}}, eye = row;
        EL(eye, i) = 1.0;
        for (int k = 0; k < 6; k++) {
            double x = EL(X[i], k);
            v2 xv = {x, x};
            for (int q = 0; q < 3; q++) row.v[q] += xv * J0[k].v[q];
        }
        for (int q = 0; q < 3; q++) {
            v2 d = eye.v[q] - row.v[q] * Dinv.v[q]; /* I - X J_s */
            dfv += d * d;
            xfv += X[i].v[q] * X[i].v[q];
        }
    }
    double df = dfv[0] + dfv[1], xf = xfv[0] + xfv[1];
    double delta = sqrt(df) * (1.0 + MARGIN) + 1e-15;
    if (!(delta < 0.5)) return;
    double beta = sqrt(xf) * (1.0 + MARGIN) / (1.0 - delta), xd = 0.0;
    for (int i = 0; i < 6; i++) xd += (D[i] * d0[i]) * (D[i] * d0[i]);
    *eta_out = (sqrt(xd) + beta * delta * nf) * (1.0 + MARGIN);
    double lmin = L0[0];
    for (int i = 0; i < 6; i++) lmin = L0[i] < lmin ? L0[i] : lmin;
    /* gamma grows with rho: rho = min(c, rho_s), c = 0.999 / (beta gamma(rho_s)), satisfies beta gamma(rho) rho < 1
     * with one bound; when c > rho_s, c itself (capped at rho_max = |l|min / 4) is tried with a second. */
    double rho_max = 0.25 * lmin, rho_s = 0.2 * a < rho_max ? 0.2 * a : rho_max;
    double c = 0.999 / (beta * lipschitz(a, rt, L0, rho_s)), best = c < rho_s ? c : rho_s;
    if (c > rho_s) {
        c = c < rho_max ? c : rho_max;
        if (beta * lipschitz(a, rt, L0, c) * c < 1.0) best = c;
    }
    /* the branch test asks for 2 eta <= rho: when the radius found is smaller, rho = 2 eta itself is tried (a third
     * bound; gamma(2 eta) < gamma(rho_s) when 2 eta < rho_s, so it can succeed where the fixed trials fell short) */
    double r2 = 2.0 * *eta_out;
    if (best < r2 && r2 <= rho_max && beta * lipschitz(a, rt, L0, r2) * r2 < 1.0) best = r2;
    *rho_out = best;
}

/* Newton from (p, R) to lengths Lt as a state machine, one iteration in three phases: P1 the leg lengths, the
 * residual and the decisions (stop, or which factorisation this iteration needs), P2 the factorisation, P3 the
 * step. newton runs one solve; newton_pair runs two independent solves phase by phase, their factorisations
 * column by column: one solve's chain of dependent operations (pivot, reciprocal, update, next pivot) waits on
 * latencies the other's fills, and each solve sees exactly the operations it sees alone (the same bits). */
enum { NEED_NONE = 0, NEED_GJ = 1, NEED_LU = 2 };
typedef struct {
    const double *Lt;
    double *p, *R, *cert, size, res, res_prev, nf;
    v2 r[3][3], l[3][3];
    double L[6], e[6], dinv[6];
    row6 J[6], J0[6], Y[6];
    int piv[6], its, st, fac, k, max_iter, need, ok, done, fin;
} nstate;

static void nt_init(nstate *S, const geom *G, const double *Lt, int max_iter, double p[3], double R[9], double *cert) {
    S->Lt = Lt; S->p = p; S->R = R; S->cert = cert; S->max_iter = max_iter;
    S->size = G->g[G_SIZE];
    for (int i = 0; i < 6; i++) S->size = Lt[i] > S->size ? Lt[i] : S->size;
    S->its = 0; S->st = MAX_ITER; S->fac = NONE; S->k = 0; S->fin = 0;
    S->res = INFINITY; S->res_prev = INFINITY;
    if (cert) { cert[0] = 0.0; cert[1] = INFINITY; }
}

static void nt_p1(nstate *S, const geom *G, double tol) {
    double *p = S->p;
    legs(G, p, S->R, S->r, S->l, S->L);
    double res = 0.0, nf = 0.0, *e = S->e;
    const double *Lt = S->Lt, *L = S->L;
    for (int i = 0; i < 6; i++) {
        e[i] = Lt[i] - L[i];
        double a = fabs(e[i]);
        res = a > res ? a : res;
        nf += e[i] * e[i];
    }
    if (nf != nf) res = nf; /* a NaN length: nf is NaN exactly then (an infinite one makes res and nf infinite) */
    S->res = res;
    S->nf = nf;
    int done = S->done = res <= tol;
    double pp = p[0] * p[0] + p[1] * p[1] + p[2] * p[2], big = DIVERGENCE_FACTOR * S->size; /* |p| > big, squared */
    S->need = NEED_NONE;
    if (!done && (!isfinite(res) || pp > big * big)) { S->st = DIVERGED; S->fin = 1; return; }
    if (S->k == 0 && S->cert) { /* the certificate needs J(y0), its inverse and the first step even when y0 fits */
        jac(S->r, S->l, S->L, S->J);
        for (int i = 0; i < 6; i++) S->J0[i] = S->J[i];
        S->need = NEED_GJ;
        return;
    }
    if (done) { S->st = CONVERGED; S->fin = 1; return; }
    if (S->k == S->max_iter) { S->fin = 1; return; }
    if (S->fac != LU || REUSE_MARGIN * res * res > tol * S->res_prev) { /* Newton; chord only as said above */
        jac(S->r, S->l, S->L, S->J);
        S->need = NEED_LU;
    }
}

static void nt_p2(nstate *S) {
    if (S->need == NEED_GJ) S->ok = gj_inverse(S->J, S->Y);
    else if (S->need == NEED_LU) S->ok = lu(S->J, S->piv, S->dinv);
}

static void nt_p3(nstate *S, const geom *G) {
    double *e = S->e;
    if (S->need == NEED_GJ) {
        if (S->ok) {
            double d0[6];
            matvec(S->Y, e, d0);
            certificate(G->g, S->J0, S->Y, S->L, d0, sqrt(S->nf), S->cert, S->cert + 1);
            S->fac = INVERSE;
            if (!S->done) for (int i = 0; i < 6; i++) e[i] = d0[i];
        } else if (!S->done) { S->st = SINGULAR; S->fin = 1; return; }
        if (S->done) { S->st = CONVERGED; S->fin = 1; return; }
        if (S->k == S->max_iter) { S->fin = 1; return; }
    } else {
        if (S->need == NEED_LU) {
            if (!S->ok) { S->st = SINGULAR; S->fin = 1; return; }
            S->fac = LU;
        }
        lu_solve(S->J, S->piv, S->dinv, e);
    }
    double ndp2 = e[0] * e[0] + e[1] * e[1] + e[2] * e[2], nw2 = e[3] * e[3] + e[4] * e[4] + e[5] * e[5];
    double s = 1.0; /* min(1, max_step_m / |dp|, max_step_rad / |w|): roots and divisions only when a bound binds */
    if (ndp2 > MAX_STEP_M * MAX_STEP_M) s = MAX_STEP_M / sqrt(ndp2);
    if (nw2 > MAX_STEP_RAD * MAX_STEP_RAD && MAX_STEP_RAD / sqrt(nw2) < s) s = MAX_STEP_RAD / sqrt(nw2);
    for (int j = 0; j < 3; j++) S->p[j] += s * e[j];
    double w[3] = {s * e[3], s * e[4], s * e[5]};
    rotate(w, S->R);
    S->its++;
    S->res_prev = S->res;
    S->k++;
}

/* One solve: (p, R) updated in place; returns the status, writes residual, iterations and (cert != NULL) the
 * certificate at the start (rho, eta), sharing the first iteration's factorisation. */
static int newton(const geom *G, const double *Lt, double tol, int max_iter, double p[3], double R[9], double *res_out,
                  int *its_out, double *cert) {
    nstate S;
    nt_init(&S, G, Lt, max_iter, p, R, cert);
    while (!S.fin) {
        nt_p1(&S, G, tol);
        if (S.fin) break;
        nt_p2(&S);
        nt_p3(&S, G);
    }
    *res_out = S.res;
    *its_out = S.its;
    return S.st;
}

/* Two factorisations of the same kind, interleaved column by column (each as it would run alone). */
static void nt_p2_pair(nstate *A, nstate *B) {
    if (A->need == NEED_GJ) {
        int a = 1, b = 1, oa[6] = {0, 1, 2, 3, 4, 5}, ob[6] = {0, 1, 2, 3, 4, 5};
        /* constant columns (inlined and specialised); a matrix stops at a zero pivot */
#define GJ2(k) a = a && gj_column(A->J, oa, k); b = b && gj_column(B->J, ob, k)
        GJ2(0); GJ2(1); GJ2(2); GJ2(3); GJ2(4); GJ2(5);
#undef GJ2
        if (a) gj_unscramble(A->J, oa, A->Y);
        if (b) gj_unscramble(B->J, ob, B->Y);
        A->ok = a;
        B->ok = b;
    } else {
        int a = 1, b = 1;
#define LU2(k) a = a && lu_column(A->J, A->piv, A->dinv, k); b = b && lu_column(B->J, B->piv, B->dinv, k)
        LU2(0); LU2(1); LU2(2); LU2(3); LU2(4); LU2(5);
#undef LU2
        A->ok = a;
        B->ok = b;
    }
}

/* Two solves at once (see nstate): the same results as two calls of newton. */
static void newton_pair(const geom *G, double tol, nstate *A, nstate *B) {
    while (!A->fin || !B->fin) {
        if (!A->fin) nt_p1(A, G, tol);
        if (!B->fin) nt_p1(B, G, tol);
        if (!A->fin && !B->fin && A->need == B->need && A->need != NEED_NONE) nt_p2_pair(A, B);
        else {
            if (!A->fin) nt_p2(A);
            if (!B->fin) nt_p2(B);
        }
        if (!A->fin) nt_p3(A, G);
        if (!B->fin) nt_p3(B, G);
    }
}

/* Distance sqrt(|dp|^2 + (a theta)^2) between two poses, theta the angle of R1 R0^T. */
static double distance(double a, const double p0[3], const double R0[9], const double p1[3], const double R1[9]) {
    double M[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) M[3 * i + j] = R1[3 * i] * R0[3 * j] + R1[3 * i + 1] * R0[3 * j + 1] + R1[3 * i + 2] * R0[3 * j + 2];
    double vx = M[7] - M[5], vy = M[2] - M[6], vz = M[3] - M[1];
    double s = 0.5 * sqrt(vx * vx + vy * vy + vz * vz), c = 0.5 * (M[0] + M[4] + M[8] - 1.0), th;
    if (c > 0.0 && s <= 0.1 * c) { /* atan(s / c) by its series to x^15: the rest is below 1e-18 relative */
        double x = s / c, x2 = x * x;
        th = x * (1.0 - x2 * (1.0 / 3 - x2 * (1.0 / 5 - x2 * (1.0 / 7 - x2 * (1.0 / 9 - x2 * (1.0 / 11 - x2 * (1.0 / 13 - x2 / 15)))))));
    } else {
        th = atan2(s, c);
    }
    double dx = p1[0] - p0[0], dy = p1[1] - p0[1], dz = p1[2] - p0[2];
    return sqrt(dx * dx + dy * dy + dz * dz + a * a * th * th);
}

/* The info of a step from (p0, R0) that Newton took to (p, R): status, residual, iterations, the certificate c. */
static void step_info(const geom *G, const double p0[3], const double R0[9], const double p[3], const double R[9],
                      int st, double res, int its, const double c[2], double *info) {
    double rho = c[0], eta = c[1];
    double d = distance(G->g[G_A], p0, R0, p, R);
    info[I_RES] = res;
    info[I_ITER] += its;
    info[I_STATUS] = st;
    info[I_RADIUS] = rho;
    info[I_ETA] = eta;
    info[I_STEP] = d;
    info[I_CERT] = (st == CONVERGED && 2.0 * eta <= rho && d < rho) ? 1.0 : 0.0;
}

/* One certified step from (p, R) to Lt (both updated in place on success of Newton). */
static int step(const geom *G, const double *Lt, double tol, int max_iter, double p[3], double R[9], double *info) {
    double p0[3] = {p[0], p[1], p[2]}, R0[9], c[2], res;
    int its;
    for (int k = 0; k < 9; k++) R0[k] = R[k];
    int st = newton(G, Lt, tol, max_iter, p, R, &res, &its, c);
    step_info(G, p0, R0, p, R, st, res, its, c, info);
    return st;
}

static void subdivide(const geom *G, const double *Lt, double tol, int max_iter, int max_sub, double pk[3], double Rk[9],
                      double p[3], double R[9], double *info);

/* Solve from (p, R) to Lt; with max_sub > 0, an uncertified step is split along the straight length path
 * L(s) = L(y0) + s (Lt - L(y0)) (halving, at most max_sub accepted sub-steps): certified when every sub-step is. */
static void solve_one(const geom *G, const double *Lt, double tol, int max_iter, int max_sub, double p[3], double R[9],
                      double *info) {
    for (int k = 0; k < N_INFO; k++) info[k] = 0.0;
    double pk[3] = {p[0], p[1], p[2]}, Rk[9];
    for (int k = 0; k < 9; k++) Rk[k] = R[k];
    step(G, Lt, tol, max_iter, p, R, info);
    info[I_SUB] = 1;
    if (info[I_CERT] == 1.0 || max_sub <= 0) return;
    subdivide(G, Lt, tol, max_iter, max_sub, pk, Rk, p, R, info);
}

/* The halving of solve_one for an uncertified first step from (pk, Rk) (the start, copied): on success every
 * sub-step certified, (p, R) and info replaced. */
static void subdivide(const geom *G, const double *Lt, double tol, int max_iter, int max_sub, double pk[3], double Rk[9],
                      double p[3], double R[9], double *info) {
    v2 r[3][3], l[3][3];
    double L0[6];
    legs(G, pk, Rk, r, l, L0);
    double s = 0.0, ds = 0.5, sub[N_INFO], rho0 = -1.0, eta_total = 0.0;
    int n = 0, iters = (int)info[I_ITER];
    while (s < 1.0 && n < max_sub && ds > 1e-6) {
        double sn = s + ds > 1.0 ? 1.0 : s + ds, Ls[6], pt[3] = {pk[0], pk[1], pk[2]}, Rt[9];
        for (int i = 0; i < 6; i++) Ls[i] = sn >= 1.0 ? Lt[i] : L0[i] + sn * (Lt[i] - L0[i]);
        for (int k = 0; k < 9; k++) Rt[k] = Rk[k];
        for (int k = 0; k < N_INFO; k++) sub[k] = 0.0;
        step(G, Ls, tol, max_iter, pt, Rt, sub);
        iters += (int)sub[I_ITER];
        if (sub[I_CERT] == 1.0) {
            if (rho0 < 0) rho0 = sub[I_RADIUS];
            eta_total += sub[I_STEP];
            s = sn;
            n++;
            for (int k = 0; k < 3; k++) pk[k] = pt[k];
            for (int k = 0; k < 9; k++) Rk[k] = Rt[k];
            ds *= 2.0;
        } else {
            ds *= 0.5;
        }
    }
    if (s >= 1.0) { /* every sub-step certified: the branch of the previous pose */
        for (int k = 0; k < 3; k++) p[k] = pk[k];
        for (int k = 0; k < 9; k++) R[k] = Rk[k];
        info[I_RES] = sub[I_RES];
        info[I_STATUS] = CONVERGED;
        info[I_CERT] = 1.0;
        info[I_RADIUS] = rho0;
        info[I_STEP] = eta_total;
        info[I_SUB] = n;
    }
    info[I_ITER] = iters;
}

/* n length sets; initial pose q0 (Euler, conv) per row (q0_stride 6) or one for all (0); track = 1: row k
 * starts from row k-1's result (kept as a matrix, no angle round trip) when that converged. */
void sd_rtfk(int64_t n, const double *g, int conv, const double *L, const double *q0, int64_t q0_stride, int track,
             double tol, int max_iter, int max_sub, double *q_out, double *info) {
    double p[3] = {0, 0, 0}, R[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    int have = 0;
    geom G;
    geom_init(&G, g);
    int64_t k = 0;
    if (!track) /* independent sets: two at a time (newton_pair), each as solve_one would solve it */
        for (; k + 1 < n; k += 2) {
            double P[2][3], RR[2][9], P0[2][3], R0[2][9], c[2][2];
            nstate S[2];
            for (int h = 0; h < 2; h++) {
                const double *q = q0 + (k + h) * q0_stride;
                P[h][0] = P0[h][0] = q[0]; P[h][1] = P0[h][1] = q[1]; P[h][2] = P0[h][2] = q[2];
                rotation(conv, q + 3, RR[h]);
                for (int j = 0; j < 9; j++) R0[h][j] = RR[h][j];
                nt_init(&S[h], &G, L + 6 * (k + h), max_iter, P[h], RR[h], c[h]);
            }
            newton_pair(&G, tol, &S[0], &S[1]);
            for (int h = 0; h < 2; h++) {
                double *inf = info + N_INFO * (k + h);
                for (int j = 0; j < N_INFO; j++) inf[j] = 0.0;
                step_info(&G, P0[h], R0[h], P[h], RR[h], S[h].st, S[h].res, S[h].its, c[h], inf);
                inf[I_SUB] = 1;
                if (inf[I_CERT] != 1.0 && max_sub > 0)
                    subdivide(&G, L + 6 * (k + h), tol, max_iter, max_sub, P0[h], R0[h], P[h], RR[h], inf);
                double *q = q_out + 6 * (k + h);
                q[0] = P[h][0]; q[1] = P[h][1]; q[2] = P[h][2];
                angles(conv, RR[h], q + 3);
            }
        }
    for (; k < n; k++) {
        if (!(track && have)) {
            const double *q = q0 + k * q0_stride;
            p[0] = q[0]; p[1] = q[1]; p[2] = q[2];
            rotation(conv, q + 3, R);
        }
        double pp[3] = {p[0], p[1], p[2]}, RR[9];
        for (int j = 0; j < 9; j++) RR[j] = R[j];
        double *inf = info + N_INFO * k;
        solve_one(&G, L + 6 * k, tol, max_iter, max_sub, pp, RR, inf);
        double *q = q_out + 6 * k;
        q[0] = pp[0]; q[1] = pp[1]; q[2] = pp[2];
        angles(conv, RR, q + 3);
        if (track && inf[I_STATUS] == CONVERGED) {
            for (int j = 0; j < 3; j++) p[j] = pp[j];
            for (int j = 0; j < 9; j++) R[j] = RR[j];
            have = 1;
        }
    }
}
