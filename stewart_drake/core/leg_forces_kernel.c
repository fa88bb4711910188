/* The inverse dynamics of stewart_drake.core.leg_forces_kernel: dynamics.leg_forces_with_legs (plate and legs)
 * for (n, 6) poses, rates and accelerations, one row at a time.
 *
 * The same formulas in the same order as the numpy path (dynamics.plate_motion, _generalized_force, the legs'
 * universal-joint rates, J_tip^T f = tau_leg, J^T F = Q), not its bits: libm's sine and cosine, sums in written
 * order, the 2 x 2 and 3 x 3 solves by LU with partial pivoting and J^T F = Q through the Gauss-Jordan inverse of
 * the scaled J that also proves its condition (numpy: LAPACK/BLAS with fused multiply-adds).
 * The condition test of dynamics.leg_forces_from_jacobians is kinematics.condition_at_most's a-posteriori bound:
 * with X a Gauss-Jordan inverse of the scaled J (A), r = |I - X A|_F <= 1/2 and |A|_F |X|_F / (1 - r) <= limit/4
 * proves cond_2(A) <= limit. A row that fails it, has a zero or non-finite pivot, a non-finite input or result is
 * left to numpy (the return value says which), which raises SingularPoseError or answers as it always did.
 */
#include <math.h>
#include <stdint.h>

/* The layout of g, the platform's constants (leg_forces_kernel.platform_constants). */
enum {
    G_MASS = 0,     /* plate mass, kg */
    G_INERTIA = 1,  /* (3, 3) plate inertia about its centre of mass, kg m^2 */
    G_COM = 10,     /* (3,) com - rotation centre, in T, m */
    G_TOP = 13,     /* (6, 3) plate anchors - rotation centre, in T, m */
    G_BASE = 31,    /* (6, 3) base anchors, m */
    G_AXIS = 49,    /* (6, 3) first universal-joint axis of each leg (home frame x), base frame */
    G_BODIES = 67,  /* cylinder mass, radius, length; piston mass, radius, length (kg, m) */
    G_GRAVITY = 73, /* m/s^2 */
    G_SCALE = 74,   /* anchor radius: the rotation columns of J are divided by it for the condition, m */
    G_LIMIT = 75,   /* MAX_CONDITION */
    G_SIZE = 76
};

static inline void cross(const double *a, const double *b, double *c) {
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

static inline double dot(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static inline void matvec(const double *M, const double *v, double *out) { /* M (3, 3) row-major */
    for (int i = 0; i < 3; i++) out[i] = M[3 * i] * v[0] + M[3 * i + 1] * v[1] + M[3 * i + 2] * v[2];
}

static inline void matTvec(const double *M, const double *v, double *out) { /* M^T v */
    for (int i = 0; i < 3; i++) out[i] = M[i] * v[0] + M[3 + i] * v[1] + M[6 + i] * v[2];
}

/* x with A x = b, A (m, m) row-major (overwritten), b (m,) (overwritten), by LU with partial pivoting; 1 on a
 * zero or non-finite pivot. */
static inline int lu_solve(int m, double *A, double *b, double *x) {
    for (int k = 0; k < m; k++) {
        int p = k;
        for (int i = k + 1; i < m; i++)
            if (fabs(A[i * m + k]) > fabs(A[p * m + k])) p = i;
        if (p != k) {
            for (int j = 0; j < m; j++) {
                double t = A[k * m + j];
                A[k * m + j] = A[p * m + j];
                A[p * m + j] = t;
            }
            double t = b[k];
            b[k] = b[p];
            b[p] = t;
        }
        double piv = A[k * m + k];
        if (piv == 0.0 || !isfinite(piv)) return 1;
        for (int i = k + 1; i < m; i++) {
            double l = A[i * m + k] / piv;
            for (int j = k + 1; j < m; j++) A[i * m + j] -= l * A[k * m + j];
            b[i] -= l * b[k];
        }
    }
    for (int i = m - 1; i >= 0; i--) {
        double s = b[i];
        for (int j = i + 1; j < m; j++) s -= A[i * m + j] * x[j];
        x[i] = s / A[i * m + i];
    }
    return 0;
}

/* The LU factors (a, b, l, u, swapped) of the 2 x 2 A (row-major) with partial pivoting; 1 on a zero or
 * non-finite pivot. */
static inline int lu2(const double *A, double *f) {
    int sw = fabs(A[2]) > fabs(A[0]);
    double a = sw ? A[2] : A[0], b = sw ? A[3] : A[1], c = sw ? A[0] : A[2], d = sw ? A[1] : A[3];
    double l = c / a, u = d - l * b;
    f[0] = a, f[1] = b, f[2] = l, f[3] = u, f[4] = sw;
    return !(a != 0.0 && u != 0.0 && isfinite(a) && isfinite(u));
}

static inline void solve2(const double *f, const double *y, double *x) {
    double y0 = f[4] != 0.0 ? y[1] : y[0], y1 = f[4] != 0.0 ? y[0] : y[1];
    x[1] = (y1 - f[2] * y0) / f[3];
    x[0] = (y0 - f[1] * x[1]) / f[0];
}

/* X (6, 6) = A^-1 for the 6 x 6 A (both row-major) by Gauss-Jordan with partial pivoting, and whether it proves
 * cond_2(A) <= limit (see the header); 0 on a zero or non-finite pivot. */
static int inverse_within(const double *A, double limit, double X[6][6]) {
    double W[6][12];
    for (int i = 0; i < 6; i++)
        for (int j = 0; j < 6; j++) {
            W[i][j] = A[6 * i + j];
            W[i][6 + j] = i == j;
        }
    for (int k = 0; k < 6; k++) {
        int p = k;
        for (int i = k + 1; i < 6; i++)
            if (fabs(W[i][k]) > fabs(W[p][k])) p = i;
        for (int j = k; j < 12; j++) {
            double t = W[k][j];
            W[k][j] = W[p][j];
            W[p][j] = t;
        }
        double piv = W[k][k];
        if (piv == 0.0 || !isfinite(piv)) return 0;
        for (int j = k; j < 12; j++) W[k][j] /= piv;
        for (int i = 0; i < 6; i++) {
            if (i == k) continue;
            double l = W[i][k];
            for (int j = k; j < 12; j++) W[i][j] -= l * W[k][j];
        }
    }
    double r2 = 0.0, a2 = 0.0, x2 = 0.0;
    for (int i = 0; i < 6; i++)
        for (int j = 0; j < 6; j++) X[i][j] = W[i][6 + j];
    for (int i = 0; i < 6; i++)
        for (int j = 0; j < 6; j++) {
            double s = 0.0;
            for (int k = 0; k < 6; k++) s += X[i][k] * A[6 * k + j];
            double e = (i == j) - s;
            r2 += e * e;
            a2 += A[6 * i + j] * A[6 * i + j];
            x2 += X[i][j] * X[i][j];
        }
    double r = sqrt(r2);
    return r <= 0.5 && sqrt(a2) * sqrt(x2) / (1.0 - r) <= limit / 4;
}

/* R_BT and E_W of the angles (conventions 0 = utn, 1 = zyx: rotations.CONVENTIONS), both (3, 3) row-major. */
static void rotation_and_rate_map(const double *ang, int conv, double *R, double *E) {
    double ca = cos(ang[0]), cb = cos(ang[1]), cg = cos(ang[2]);
    double sa = sin(ang[0]), sb = sin(ang[1]), sg = sin(ang[2]);
    if (conv == 0) { /* Ry(beta) Rx(alpha) Rz(gamma) */
        double r[9] = {cb * cg + sa * sb * sg, sa * sb * cg - cb * sg, ca * sb, ca * sg, ca * cg, -sa,
                       sa * cb * sg - sb * cg, sb * sg + sa * cb * cg, ca * cb};
        double e[9] = {cb, 0.0, sb * ca, 0.0, 1.0, -sa, -sb, 0.0, cb * ca};
        for (int i = 0; i < 9; i++) R[i] = r[i], E[i] = e[i];
    } else { /* Rz(psi) Ry(theta) Rx(phi) */
        double r[9] = {cb * cg, sa * sb * cg - ca * sg, ca * sb * cg + sa * sg, cb * sg, sa * sb * sg + ca * cg,
                       ca * sb * sg - sa * cg, -sb, sa * cb, ca * cb};
        double e[9] = {cg * cb, -sg, 0.0, sg * cb, cg, 0.0, -sb, 0.0, 1.0};
        for (int i = 0; i < 9; i++) R[i] = r[i], E[i] = e[i];
    }
}

/* 0 when every row's F is computed here; else 1 + the index of the first row left to numpy. */
int64_t sd_leg_forces(int64_t n, const double *g, int conv, const double *q, const double *qd, const double *qdd,
                      double *F) {
    static const int ORDER[2][3] = {{1, 0, 2}, {2, 1, 0}}; /* dynamics._ORDER: outermost rotation first */
    const double mass = g[G_MASS], grav = g[G_GRAVITY], scale = g[G_SCALE], limit = g[G_LIMIT];
    for (int64_t row = 0; row < n; row++, q += 6, qd += 6, qdd += 6, F += 6) {
        for (int k = 0; k < 6; k++)
            if (!(isfinite(q[k]) && isfinite(qd[k]) && isfinite(qdd[k]))) return row + 1;
        double R[9], E[9], w[3], wd[3], bias[3] = {0.0, 0.0, 0.0}, before[3] = {0.0, 0.0, 0.0};
        rotation_and_rate_map(q + 3, conv, R, E);
        matvec(E, qd + 3, w);
        for (int j = 0; j < 3; j++) { /* Euler-rate term: dynamics.euler_rate_derivative */
            int k = ORDER[conv][j];
            double wk[3] = {E[k] * qd[3 + k], E[3 + k] * qd[3 + k], E[6 + k] * qd[3 + k]}, c[3];
            cross(before, wk, c);
            for (int i = 0; i < 3; i++) bias[i] += c[i], before[i] += wk[i];
        }
        matvec(E, qdd + 3, wd);
        for (int i = 0; i < 3; i++) wd[i] += bias[i];
        /* The plate: Newton-Euler about its centre of mass, projected on q (dynamics._generalized_force). */
        double rcm[3], t1[3], t2[3], acm[3], f[3], IW[9], RI[9], Iw[3], tau[3], tauC[3];
        matvec(R, g + G_COM, rcm);
        cross(w, rcm, t1);
        cross(w, t1, t2);
        cross(wd, rcm, t1);
        for (int i = 0; i < 3; i++) acm[i] = qdd[i] + t1[i] + t2[i];
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                RI[3 * i + j] = R[3 * i] * g[G_INERTIA + j] + R[3 * i + 1] * g[G_INERTIA + 3 + j] +
                                R[3 * i + 2] * g[G_INERTIA + 6 + j];
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                IW[3 * i + j] = RI[3 * i] * R[3 * j] + RI[3 * i + 1] * R[3 * j + 1] + RI[3 * i + 2] * R[3 * j + 2];
        for (int i = 0; i < 3; i++) f[i] = mass * (acm[i] + (i == 2 ? grav : 0.0));
        matvec(IW, wd, tau);
        matvec(IW, w, Iw);
        cross(w, Iw, t1);
        cross(rcm, f, t2);
        for (int i = 0; i < 3; i++) tauC[i] = tau[i] + t1[i] + t2[i];
        /* The legs: each adds f_tip at its plate anchor (J_tip^T f_tip = tau_leg). */
        double fsum[3] = {0.0, 0.0, 0.0}, msum[3] = {0.0, 0.0, 0.0}, J[36];
        int bad = 0;
        for (int leg = 0; leg < 6 && !bad; leg++) {
            double r[3], l[3], ld[3], ldd[3], u[3], ud[3], udd[3];
            matvec(R, g + G_TOP + 3 * leg, r);
            cross(w, r, t1);
            cross(w, t1, t2);
            double t3[3];
            cross(wd, r, t3);
            for (int i = 0; i < 3; i++) {
                l[i] = q[i] + r[i] - g[G_BASE + 3 * leg + i];
                ld[i] = qd[i] + t1[i];
                ldd[i] = qdd[i] + t3[i] + t2[i];
            }
            double L = sqrt(dot(l, l));
            for (int i = 0; i < 3; i++) u[i] = l[i] / L;
            double Ld = dot(u, ld);
            for (int i = 0; i < 3; i++) ud[i] = (ld[i] - Ld * u[i]) / L;
            double Ldd = dot(ud, ld) + dot(u, ldd);
            for (int i = 0; i < 3; i++) udd[i] = (ldd[i] - Ldd * u[i] - 2 * Ld * ud[i]) / L;
            const double *a1 = g + G_AXIS + 3 * leg;
            double a2[3], b0[3], b1[3], a12v[3];
            cross(u, a1, a2);
            double na2 = sqrt(dot(a2, a2));
            for (int i = 0; i < 3; i++) a2[i] /= na2;
            cross(a1, u, b0);
            cross(a2, u, b1);
            /* The universal joint's rates and accelerations: (B^T B) x = B^T y, B = [a1 x u, a2 x u]. */
            double G2[4] = {dot(b0, b0), dot(b0, b1), dot(b1, b0), dot(b1, b1)}, f2[5], y2[2], rates[2], acc[2];
            if (lu2(G2, f2)) {
                bad = 1;
                break;
            }
            y2[0] = dot(b0, ud), y2[1] = dot(b1, ud);
            solve2(f2, y2, rates);
            double oc[3], t4[3], rhs[3], ocd[3];
            for (int i = 0; i < 3; i++) oc[i] = rates[0] * a1[i] + rates[1] * a2[i];
            cross(a1, a2, a12v);
            for (int i = 0; i < 3; i++) a12v[i] *= rates[0] * rates[1];
            cross(a12v, u, t1);
            cross(oc, u, t3);
            cross(oc, t3, t4);
            for (int i = 0; i < 3; i++) rhs[i] = udd[i] - t1[i] - t4[i];
            y2[0] = dot(b0, rhs), y2[1] = dot(b1, rhs);
            solve2(f2, y2, acc);
            for (int i = 0; i < 3; i++) ocd[i] = acc[0] * a1[i] + acc[1] * a2[i] + a12v[i];
            /* Cylinder and piston: uniform rods about the base anchor. */
            double MB[3] = {0.0, 0.0, 0.0}, fp[3] = {0.0, 0.0, 0.0};
            for (int body = 0; body < 2; body++) {
                const double *b = g + G_BODIES + 3 * body;
                double m = b[0], rad = b[1], len = b[2];
                double tp = m * (3 * rad * rad + len * len) / 12, ta = m * rad * rad / 2;
                double e = body ? L - len / 2 : len / 2, ed = body ? Ld : 0.0, edd = body ? Ldd : 0.0;
                double I[9], Io[3], Iod[3], ab[3], fb[3], c1[3], c2[3], eu[3];
                for (int i = 0; i < 3; i++)
                    for (int j = 0; j < 3; j++) I[3 * i + j] = tp * ((i == j) - u[i] * u[j]) + ta * (u[i] * u[j]);
                for (int i = 0; i < 3; i++) {
                    ab[i] = edd * u[i] + 2 * ed * ud[i] + e * udd[i];
                    fb[i] = m * (ab[i] + (i == 2 ? grav : 0.0));
                    eu[i] = e * u[i];
                }
                matvec(I, ocd, Iod);
                matvec(I, oc, Io);
                cross(oc, Io, c1);
                cross(eu, fb, c2);
                for (int i = 0; i < 3; i++) MB[i] += Iod[i] + c1[i] + c2[i], fp[i] = fb[i];
            }
            double Jt[9], tl[3], ftip[3], c1[3], c2[3];
            cross(a1, l, c1);
            cross(a2, l, c2);
            for (int i = 0; i < 3; i++) Jt[i] = c1[i], Jt[3 + i] = c2[i], Jt[6 + i] = u[i]; /* J_tip^T rows */
            tl[0] = dot(a1, MB), tl[1] = dot(a2, MB), tl[2] = dot(u, fp);
            if (lu_solve(3, Jt, tl, ftip)) {
                bad = 1;
                break;
            }
            cross(r, ftip, c1);
            for (int i = 0; i < 3; i++) fsum[i] += ftip[i], msum[i] += c1[i];
            /* Row leg of J = dL/dq: [u, (r x u)^T E_W] (kinematics.length_jacobian_of). */
            cross(r, u, c2);
            double ce[3];
            matTvec(E, c2, ce);
            for (int i = 0; i < 3; i++) J[6 * leg + i] = u[i], J[6 * leg + 3 + i] = ce[i];
        }
        if (bad) return row + 1;
        double Q[6], A[36], X[6][6], et[3];
        double em[3];
        matTvec(E, tauC, et);
        matTvec(E, msum, em);
        for (int i = 0; i < 3; i++) Q[i] = f[i] + fsum[i], Q[3 + i] = et[i] + em[i];
        for (int i = 0; i < 6; i++)
            for (int j = 0; j < 6; j++) A[6 * i + j] = j < 3 ? J[6 * i + j] : J[6 * i + j] / scale;
        if (!inverse_within(A, limit, X)) return row + 1;
        for (int k = 3; k < 6; k++) Q[k] /= scale;
        for (int i = 0; i < 6; i++) { /* J = A diag(1, 1, 1, s, s, s): F = J^-T Q = X^T (Q / diag) */
            double s = 0.0;
            for (int k = 0; k < 6; k++) s += X[k][i] * Q[k];
            if (!isfinite(s)) return row + 1;
            F[i] = s;
        }
    }
    return 0;
}
