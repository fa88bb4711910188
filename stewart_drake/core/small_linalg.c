/* Batched small-matrix algebra of stewart_drake.core.small_linalg, with the operations, in the order and with the
 * fused multiply-adds, of what numpy runs per matrix for it (its OpenBLAS on x86-64 with FMA; the module checks the
 * bits against numpy at load and uses numpy where they differ):
 *
 * - the Gram matrix G = B^T B of a k x 2 matrix B (numpy's matmul: the dsyrk kernel sums over k as a fused chain
 *   from +0, fma(b_k0, b_k1, ... fma(b_00, b_01, +0)));
 * - A x = y by dgesv for 2 x 2 A (dgetf2 with partial pivoting: the pivot of larger magnitude, the multiplier
 *   l = c * (1/a), u = d - l b unfused; dgetrs: z1 = fma(-l, y0, y1), x1 = z1 / u, x0 = fma(-b, x1, y0) / a);
 * - the same for 3 x 3 (dgetf2's second column u = b - l a unfused, its third c - fma(l21, u12, l20 u02), the
 *   rows swapped in the columns already factored; dgetrs's substitutions as fused axpys).
 *
 * Only LAPACK's usual branch is written: a pivot that is zero, below DBL_MIN or not finite makes a function return
 * 1, and the caller runs numpy on the batch (which raises or takes LAPACK's other branches itself). Built with
 * -ffp-contract=off: every product and sum not written as fma() is rounded on its own, as in the kernels.
 * sd_inverse is not numpy's: an approximate inverse for an a-posteriori bound (any inverse will do).
 */
#include <float.h>
#include <math.h>
#include <stdint.h>

/* G (n, 2, 2) = B^T B for B (n, k, 2), both row-major. */
void sd_gram2(int64_t n, int64_t k, const double *B, double *G) {
    for (int64_t i = 0; i < n; i++, B += 2 * k, G += 4) {
        double g00 = 0.0, g01 = 0.0, g11 = 0.0; /* from +0, as the kernels' accumulators */
        for (int64_t j = 0; j < k; j++) {
            double b0 = B[2 * j], b1 = B[2 * j + 1];
            g00 = fma(b0, b0, g00);
            g01 = fma(b0, b1, g01);
            g11 = fma(b1, b1, g11);
        }
        G[0] = g00;
        G[1] = g01;
        G[2] = g01;
        G[3] = g11;
    }
}

/* LU factors F (n, 5) = (pivot a, b, l, u, swapped) of A (n, 2, 2) row-major; 1 if a pivot needs LAPACK's
 * other branches (zero, subnormal, not finite), else 0. */
int sd_lu2(int64_t n, const double *A, double *F) {
    int unusual = 0;
    for (int64_t i = 0; i < n; i++, A += 4, F += 5) {
        double a = A[0], b = A[1], c = A[2], d = A[3];
        int swapped = fabs(c) > fabs(a); /* idamax: the first of equal magnitudes */
        if (swapped) {
            double t = a;
            a = c;
            c = t;
            t = b;
            b = d;
            d = t;
        }
        double l = c * (1.0 / a);
        double u = d - l * b;
        if (!(isfinite(a) && isfinite(b) && isfinite(l) && isfinite(u) && fabs(a) >= DBL_MIN && fabs(u) >= DBL_MIN))
            unusual = 1;
        F[0] = a;
        F[1] = b;
        F[2] = l;
        F[3] = u;
        F[4] = swapped;
    }
    return unusual;
}

/* x (n, 2) with A x = y (n, 2) from sd_lu2's factors; 1 if a solution is not finite (numpy decides), else 0. */
int sd_solve2(int64_t n, const double *F, const double *y, double *x) {
    int unusual = 0;
    for (int64_t i = 0; i < n; i++, F += 5, y += 2, x += 2) {
        double y0 = y[0], y1 = y[1];
        if (F[4] != 0.0) {
            y0 = y[1];
            y1 = y[0];
        }
        double x1 = fma(-F[2], y0, y1) / F[3];
        double x0 = fma(-F[1], x1, y0) / F[0];
        if (!(isfinite(x0) && isfinite(x1)))
            unusual = 1;
        x[0] = x0;
        x[1] = x1;
    }
    return unusual;
}

/* x (n, 3) with A x = y for A (n, 3, 3) row-major, y (n, 3); 1 if a pivot needs LAPACK's other branches or a
 * solution is not finite (numpy decides), else 0. */
int sd_solve3(int64_t n, const double *A, const double *y, double *x) {
    int unusual = 0;
    for (int64_t i = 0; i < n; i++, A += 9, y += 3, x += 3) {
        double c0[3] = {A[0], A[3], A[6]}, c1[3] = {A[1], A[4], A[7]}, c2[3] = {A[2], A[5], A[8]};
        double r[3] = {y[0], y[1], y[2]}, t;
        int p0 = 0; /* idamax of the first column: the first of equal magnitudes */
        if (fabs(c0[1]) > fabs(c0[p0]))
            p0 = 1;
        if (fabs(c0[2]) > fabs(c0[p0]))
            p0 = 2;
        t = c0[0], c0[0] = c0[p0], c0[p0] = t;
        double u00 = c0[0], inv0 = 1.0 / u00, l10 = c0[1] * inv0, l20 = c0[2] * inv0;
        t = c1[0], c1[0] = c1[p0], c1[p0] = t;
        double u01 = c1[0], b1 = c1[1] - l10 * u01, b2 = c1[2] - l20 * u01;
        int p1 = fabs(b2) > fabs(b1);
        if (p1) {
            t = l10, l10 = l20, l20 = t;
            t = b1, b1 = b2, b2 = t;
        }
        double u11 = b1, l21 = b2 * (1.0 / u11);
        t = c2[0], c2[0] = c2[p0], c2[p0] = t;
        if (p1)
            t = c2[1], c2[1] = c2[2], c2[2] = t;
        double u02 = c2[0], u12 = c2[1] - l10 * u02, u22 = c2[2] - fma(l21, u12, l20 * u02);
        t = r[0], r[0] = r[p0], r[p0] = t;
        if (p1)
            t = r[1], r[1] = r[2], r[2] = t;
        double z1 = fma(-r[0], l10, r[1]), z2 = fma(-r[0], l20, r[2]);
        z2 = fma(-z1, l21, z2);
        double x2 = z2 / u22;
        double w0 = fma(-x2, u02, r[0]), w1 = fma(-x2, u12, z1);
        double x1 = w1 / u11;
        double x0 = fma(-x1, u01, w0) / u00;
        if (!(fabs(u00) >= DBL_MIN && fabs(u11) >= DBL_MIN && fabs(u22) >= DBL_MIN && isfinite(u00) && isfinite(u11) &&
              isfinite(u22) && isfinite(l10) && isfinite(l20) && isfinite(l21) && isfinite(x0) && isfinite(x1) &&
              isfinite(x2)))
            unusual = 1;
        x[0] = x0;
        x[1] = x1;
        x[2] = x2;
    }
    return unusual;
}

/* X (nb, n, n) ~ A^-1 of A (nb, n, n) row-major, n <= 8, by Gauss-Jordan elimination with partial pivoting (an
 * approximate inverse for an a-posteriori bound: not numpy's bits); 1 if a pivot is zero or a result not finite. */
int sd_inverse(int64_t nb, int64_t n, const double *A, double *X) {
    int unusual = 0;
    double M[8][16];
    for (int64_t b = 0; b < nb; b++, A += n * n, X += n * n) {
        for (int64_t i = 0; i < n; i++)
            for (int64_t j = 0; j < n; j++) {
                M[i][j] = A[i * n + j];
                M[i][n + j] = i == j ? 1.0 : 0.0;
            }
        for (int64_t c = 0; c < n; c++) {
            int64_t p = c;
            for (int64_t i = c + 1; i < n; i++)
                if (fabs(M[i][c]) > fabs(M[p][c]))
                    p = i;
            if (!(M[p][c] != 0.0 && isfinite(M[p][c]))) {
                unusual = 1;
                break;
            }
            if (p != c)
                for (int64_t j = 0; j < 2 * n; j++) {
                    double t = M[c][j];
                    M[c][j] = M[p][j];
                    M[p][j] = t;
                }
            double inv = 1.0 / M[c][c];
            for (int64_t j = 0; j < 2 * n; j++)
                M[c][j] *= inv;
            for (int64_t i = 0; i < n; i++) {
                double f = M[i][c];
                if (i == c || f == 0.0)
                    continue;
                for (int64_t j = 0; j < 2 * n; j++)
                    M[i][j] -= f * M[c][j];
            }
        }
        for (int64_t i = 0; i < n; i++)
            for (int64_t j = 0; j < n; j++) {
                X[i * n + j] = M[i][n + j];
                if (!isfinite(M[i][n + j]))
                    unusual = 1;
            }
    }
    return unusual;
}
