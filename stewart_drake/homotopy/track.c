/* Compiled path tracker of stewart_drake.homotopy.track: the same predictor-corrector, step control and
 * end states as the numpy reference (track.py, which documents the algorithm), one path at a time, so a
 * path costs its own number of steps (the numpy tracker advances all paths in lockstep and pays the
 * per-call overhead of numpy for every step of the slowest path).
 *
 * Complex numbers are C99 double complex in memory (numpy complex128 layout); products and quotients
 * of two complex numbers go through cmul/cdiv (plain formulas: C99 Annex G's NaN/overflow recovery is
 * a library call per product and the iterates are of order one).
 *
 * System (study.py): x = (e, g) in C^8; leg i: u_i = g + B_i(tau) e, B_i(tau) = B0_i + tau dB_i,
 * F_i = u_i.u_i - s_i e.e with s = s0 + tau ds; F_6 = g.e; F_7 = v.x - 1; tau(t) = gamma t / (gamma t + 1 - t).
 */
#include <complex.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>

typedef double complex cplx;

enum { ACTIVE = 0, DONE = 1, STALLED = 2, FAILED = 3 };

/* r + i·I without C11's CMPLX (C99: a complex is laid out as two doubles, real part first). */
static inline cplx mk(double r, double i) {
    cplx z;
    ((double *)&z)[0] = r;
    ((double *)&z)[1] = i;
    return z;
}

static inline cplx cmul(cplx a, cplx b) {
    double ar = creal(a), ai = cimag(a), br = creal(b), bi = cimag(b);
    return mk(ar * br - ai * bi, ar * bi + ai * br);
}

static inline cplx cdiv(cplx a, cplx b) {
    double br = creal(b), bi = cimag(b), d = br * br + bi * bi;
    double ar = creal(a), ai = cimag(a);
    return mk((ar * br + ai * bi) / d, (ai * br - ar * bi) / d);
}

static inline double cabs1(cplx a) { return fabs(creal(a)) + fabs(cimag(a)); }

typedef struct {
    const cplx *B0, *dB; /* (6, 4, 4) row-major */
    int fixed;           /* dB == 0: only the lengths move */
    const cplx *v;       /* (8,) chart */
    double Br[6][4][4];  /* real parts of B0, used when fixed and B0 is real (a real platform's anchors) */
    int real;
} System;

/* evaluate() for a fixed real B (the second stage: this platform's own anchors): the products with B
 * are real × complex, a third of the arithmetic. */
static void evaluate_real(const System *S, const cplx *s0, const cplx *ds, cplx gamma, const cplx *x, double t,
                          cplx J[8][8], cplx R[8][2]) {
    cplx d = gamma * t + (1.0 - t);
    cplx tau = cdiv(gamma * t, d);
    cplx dtau = cdiv(gamma, cmul(d, d));
    const cplx *e = x, *g = x + 4;
    cplx ee = cmul(e[0], e[0]) + cmul(e[1], e[1]) + cmul(e[2], e[2]) + cmul(e[3], e[3]);
    for (int i = 0; i < 6; i++) {
        const double(*B)[4] = S->Br[i];
        cplx u[4];
        for (int r = 0; r < 4; r++) u[r] = g[r] + B[r][0] * e[0] + B[r][1] * e[1] + B[r][2] * e[2] + B[r][3] * e[3];
        cplx s = s0[i] + cmul(tau, ds[i]);
        cplx uu = cmul(u[0], u[0]) + cmul(u[1], u[1]) + cmul(u[2], u[2]) + cmul(u[3], u[3]);
        R[i][0] = uu - cmul(s, ee);
        R[i][1] = cmul(-cmul(ds[i], ee), dtau);
        for (int c = 0; c < 4; c++) {
            cplx BTu = B[0][c] * u[0] + B[1][c] * u[1] + B[2][c] * u[2] + B[3][c] * u[3];
            J[i][c] = 2.0 * (BTu - cmul(s, e[c]));
            J[i][4 + c] = 2.0 * u[c];
        }
    }
    cplx ge = 0, vx = 0;
    for (int k = 0; k < 4; k++) {
        ge += cmul(g[k], e[k]);
        J[6][k] = g[k];
        J[6][4 + k] = e[k];
    }
    for (int k = 0; k < 8; k++) {
        vx += cmul(S->v[k], x[k]);
        J[7][k] = S->v[k];
    }
    R[6][0] = ge;
    R[7][0] = vx - 1.0;
    R[6][1] = R[7][1] = 0;
}

/* H_x (8x8, row-major) and the right-hand sides [H | dH/dt] (8x2) at (x, t) for a path with s0, ds (6,)
 * and gamma. */
static void evaluate(const System *S, const cplx *s0, const cplx *ds, cplx gamma, const cplx *x, double t,
                     cplx J[8][8], cplx R[8][2]) {
    cplx d = gamma * t + (1.0 - t);
    cplx tau = cdiv(gamma * t, d);
    cplx dtau = cdiv(gamma, cmul(d, d));
    const cplx *e = x, *g = x + 4;
    cplx ee = cmul(e[0], e[0]) + cmul(e[1], e[1]) + cmul(e[2], e[2]) + cmul(e[3], e[3]);
    for (int i = 0; i < 6; i++) {
        cplx B[4][4], u[4], dBe[4];
        const cplx *B0 = S->B0 + 16 * i, *dB = S->dB + 16 * i;
        for (int r = 0; r < 4; r++) {
            cplx acc = g[r], acc2 = 0;
            for (int c = 0; c < 4; c++) {
                if (S->fixed) {
                    B[r][c] = B0[4 * r + c];
                } else {
                    B[r][c] = B0[4 * r + c] + cmul(tau, dB[4 * r + c]);
                    acc2 += cmul(dB[4 * r + c], e[c]);
                }
                acc += cmul(B[r][c], e[c]);
            }
            u[r] = acc;
            dBe[r] = acc2;
        }
        cplx s = s0[i] + cmul(tau, ds[i]);
        cplx uu = 0, udBe = 0;
        for (int r = 0; r < 4; r++) {
            uu += cmul(u[r], u[r]);
            udBe += cmul(u[r], dBe[r]);
        }
        R[i][0] = uu - cmul(s, ee);
        cplx Ht = -cmul(ds[i], ee);
        if (!S->fixed) Ht += 2.0 * udBe;
        R[i][1] = cmul(Ht, dtau);
        for (int c = 0; c < 4; c++) {
            cplx BTu = 0;
            for (int r = 0; r < 4; r++) BTu += cmul(B[r][c], u[r]);
            J[i][c] = 2.0 * (BTu - cmul(s, e[c]));
            J[i][4 + c] = 2.0 * u[c];
        }
    }
    cplx ge = 0, vx = 0;
    for (int k = 0; k < 4; k++) {
        ge += cmul(g[k], e[k]);
        J[6][k] = g[k];
        J[6][4 + k] = e[k];
    }
    for (int k = 0; k < 8; k++) {
        vx += cmul(S->v[k], x[k]);
        J[7][k] = S->v[k];
    }
    R[6][0] = ge;
    R[7][0] = vx - 1.0;
    R[6][1] = R[7][1] = 0;
}

/* Solve J X = R in place (R becomes X) by Gaussian elimination with partial pivoting (largest
 * |re| + |im|, as LAPACK's zgetrf). A zero pivot gives non-finite X, which the step test rejects. */
static void solve8(cplx J[8][8], cplx R[8][2]) {
    for (int k = 0; k < 8; k++) {
        int p = k;
        double best = cabs1(J[k][k]);
        for (int r = k + 1; r < 8; r++) {
            double a = cabs1(J[r][k]);
            if (a > best) best = a, p = r;
        }
        if (p != k) {
            for (int c = k; c < 8; c++) {
                cplx tmp = J[k][c];
                J[k][c] = J[p][c];
                J[p][c] = tmp;
            }
            for (int c = 0; c < 2; c++) {
                cplx tmp = R[k][c];
                R[k][c] = R[p][c];
                R[p][c] = tmp;
            }
        }
        cplx inv = cdiv(1.0, J[k][k]);
        for (int r = k + 1; r < 8; r++) {
            cplx f = cmul(J[r][k], inv);
            for (int c = k + 1; c < 8; c++) J[r][c] -= cmul(f, J[k][c]);
            R[r][0] -= cmul(f, R[k][0]);
            R[r][1] -= cmul(f, R[k][1]);
        }
    }
    for (int k = 7; k >= 0; k--) {
        cplx inv = cdiv(1.0, J[k][k]);
        for (int c = 0; c < 2; c++) {
            cplx acc = R[k][c];
            for (int j = k + 1; j < 8; j++) acc -= cmul(J[k][j], R[j][c]);
            R[k][c] = cmul(acc, inv);
        }
    }
}

/* One Newton step at (x, t) into xn, and the tangent dx/dt there into xd (may be NULL). */
static void newton_tangent(const System *S, const cplx *s0, const cplx *ds, cplx gamma, const cplx *x, double t,
                           cplx *xn, cplx *xd) {
    cplx J[8][8], R[8][2];
    if (S->real)
        evaluate_real(S, s0, ds, gamma, x, t, J, R);
    else
        evaluate(S, s0, ds, gamma, x, t, J, R);
    solve8(J, R);
    for (int k = 0; k < 8; k++) {
        xn[k] = x[k] - R[k][0];
        if (xd) xd[k] = -R[k][1];
    }
}

static double maxabs(const cplx *z) {
    double m = 0;
    for (int k = 0; k < 8; k++) {
        double a = sqrt(creal(z[k]) * creal(z[k]) + cimag(z[k]) * cimag(z[k]));
        if (a > m || isnan(a)) m = a;
        if (isnan(m)) return m;
    }
    return m;
}

static double maxabs_diff(const cplx *a, const cplx *b) {
    cplx d[8];
    for (int k = 0; k < 8; k++) d[k] = a[k] - b[k];
    return maxabs(d);
}

static double clip(double v, double lo, double hi) { return v < lo ? lo : (v > hi ? hi : v); }

/* Track n paths; see track.py for the meaning of every option.
 * opts: h0, h_max, h_min, target, tol, max_jump, contraction, endgame.
 * x0, x_out (n, 8); B0, dB (6, 4, 4); s0, ds (n, 6); v (8,); gamma (n,) -- complex, as interleaved doubles.
 * cap (n,) step limits; outputs t_out, state_out, steps_out (n,). */
void sd_track(int64_t n, const double *x0_, const double *B0_, const double *dB_, int fixed, const double *s0_,
              const double *ds_, const double *v_, const double *gamma_, const int64_t *cap, const double *opts,
              int64_t end_newton, double *x_out_, double *t_out, int64_t *state_out, int64_t *steps_out) {
    const cplx *x0 = (const cplx *)x0_, *s0a = (const cplx *)s0_, *dsa = (const cplx *)ds_, *gam = (const cplx *)gamma_;
    cplx *x_out = (cplx *)x_out_;
    System S = {(const cplx *)B0_, (const cplx *)dB_, fixed, (const cplx *)v_, {{{0}}}, fixed};
    for (int k = 0; k < 96; k++) {
        if (B0_[2 * k + 1] != 0) S.real = 0;
        S.Br[k / 16][(k / 4) % 4][k % 4] = B0_[2 * k];
    }
    const double h0 = opts[0], h_max = opts[1], h_min = opts[2], target = opts[3], tol = opts[4], max_jump = opts[5],
                 contraction = opts[6], endgame = opts[7];
    for (int64_t p = 0; p < n; p++) {
        const cplx *s0 = s0a + 6 * p, *ds = dsa + 6 * p;
        cplx gamma = gam[p];
        cplx x[8], xd[8], xp[8], xdp[8], xhat[8], x1[8], x2[8], xd2[8], junk[8];
        for (int k = 0; k < 8; k++) x[k] = x0[8 * p + k];
        double t = 0, h = h0;
        int64_t steps = 0, state = ACTIVE;
        newton_tangent(&S, s0, ds, gamma, x, t, junk, xd);
        /* A fictitious previous point on the tangent line: the first Hermite prediction is Euler's. */
        for (int k = 0; k < 8; k++) {
            xp[k] = x[k] - h * xd[k];
            xdp[k] = xd[k];
        }
        double tp = t - h;
        while (state == ACTIVE) {
            double ha = h < 1 - t ? h : 1 - t;
            double tn = t + ha;
            /* Predictor: cubic Hermite through (tp, xp, xdp) and (t, x, xd), evaluated at tn. */
            double D = t - tp, sg = (ha + D) / D, sg2 = sg * sg, sg3 = sg2 * sg;
            double c0 = 2 * sg3 - 3 * sg2 + 1, c1 = (sg3 - 2 * sg2 + sg) * D, c2 = 3 * sg2 - 2 * sg3, c3 = (sg3 - sg2) * D;
            for (int k = 0; k < 8; k++) xhat[k] = c0 * xp[k] + c1 * xdp[k] + c2 * x[k] + c3 * xd[k];
            newton_tangent(&S, s0, ds, gamma, xhat, tn, x1, NULL);
            newton_tangent(&S, s0, ds, gamma, x1, tn, x2, xd2);
            double norm = maxabs(x);
            norm = norm > 1.0 ? norm : 1.0;
            double d1 = maxabs_diff(x1, xhat), d2 = maxabs_diff(x2, x1);
            int good = d1 <= max_jump * norm && d2 <= contraction * d1 + 1e-14 * norm && d2 <= tol * norm && isfinite(d2);
            for (int k = 0; k < 8 && good; k++) good = isfinite(creal(xd2[k])) && isfinite(cimag(xd2[k]));
            steps++;
            double ratio = d1 > 0 ? pow(target * norm / d1, 0.25) : 4.0;
            if (good) {
                for (int k = 0; k < 8; k++) {
                    xp[k] = x[k];
                    xdp[k] = xd[k];
                    x[k] = x2[k];
                    xd[k] = xd2[k];
                }
                tp = t;
                t = 1 - tn <= 1e-14 ? 1.0 : tn;
                h = ha * clip(0.8 * ratio, 0.5, 2.0);
                if (h > h_max) h = h_max;
                if (t >= 1.0) state = DONE;
            } else {
                h = ha * clip(0.8 * ratio, 0.1, 0.5);
                if (h < h_min) state = 1 - t <= endgame ? STALLED : FAILED;
            }
            if (steps >= cap[p] && state == ACTIVE) state = FAILED;
        }
        if (state == DONE) { /* Newton refinement at t = 1, kept when it stays finite */
            cplx xe[8], xn[8];
            for (int k = 0; k < 8; k++) xe[k] = x[k];
            for (int64_t it = 0; it < end_newton; it++) {
                newton_tangent(&S, s0, ds, gamma, xe, 1.0, xn, NULL);
                for (int k = 0; k < 8; k++) xe[k] = xn[k];
            }
            int fin = 1;
            for (int k = 0; k < 8; k++) fin &= isfinite(creal(xe[k])) && isfinite(cimag(xe[k]));
            if (fin)
                for (int k = 0; k < 8; k++) x[k] = xe[k];
        }
        for (int k = 0; k < 8; k++) x_out[8 * p + k] = x[k];
        t_out[p] = t;
        state_out[p] = state;
        steps_out[p] = steps;
    }
}
