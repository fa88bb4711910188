/* Inverse kinematics of stewart_drake.core.ik_kernel: (n, 6) poses -> (n, 6) leg lengths.
 *
 * L_i = | p + R(angles) t_i - b_i |, t_i the plate anchor relative to the rotation centre, with R written out
 * as kinematics.leg_lengths / rotations.rotation_matrix write it (conventions utn and zyx).
 *
 * Why its own sine and cosine: three libm sincos calls cost more than the rest of a pose. sd_sincos is
 * fdlibm's kernel polynomials (|x| <= pi/4, < 1 ulp) after a Cody-Waite reduction by pi/2 in three parts,
 * exact for |x| < 2^19 pi/2 (fdlibm's medium range, e_rem_pio2.c); larger angles go to libm.
 */
#include <math.h>
#include <stdint.h>
#if defined(__SSE2__)
#include <emmintrin.h> /* two legs per instruction; the same operations in the same order as the scalar loop */
#endif

static const double S1 = -1.66666666666666324348e-01, S2 = 8.33333333332248946124e-03,
                    S3 = -1.98412698298579493134e-04, S4 = 2.75573137070700676789e-06,
                    S5 = -2.50507602534068634195e-08, S6 = 1.58969099521155010221e-10;
static const double C1 = 4.16666666666666019037e-02, C2 = -1.38888888888741095749e-03,
                    C3 = 2.48015872894767294178e-05, C4 = -2.75573143513906633035e-07,
                    C5 = 2.08757232129817482790e-09, C6 = -1.13596475577881948265e-11;
static const double INVPIO2 = 6.36619772367581382433e-01, PIO2_1 = 1.57079632673412561417e+00,
                    PIO2_1T = 6.07710050650619224932e-11, PIO2_2 = 6.07710050630396597660e-11,
                    PIO2_2T = 2.02226624879595063154e-21, PIO2_3 = 2.02226624871116645580e-21,
                    PIO2_3T = 8.47842766036889956997e-32;

/* sin and cos of r + y, |r + y| <= pi/4 (fdlibm k_sin.c / k_cos.c, FreeBSD form). */
static inline double ksin(double x, double y) {
    double z = x * x, w = z * z, r = S2 + z * (S3 + z * S4) + z * w * (S5 + z * S6), v = z * x;
    return x - ((z * (0.5 * y - v * r) - y) - v * S1);
}

static inline double kcos(double x, double y) {
    double z = x * x, w = z * z, r = z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * C6));
    double hz = 0.5 * z, u = 1.0 - hz;
    return u + (((1.0 - u) - hz) + (z * r - x * y));
}

static void sd_sincos(double x, double *s, double *c) {
    if (fabs(x) <= 0.785398163397448279) { /* pi/4: no reduction */
        *s = ksin(x, 0.0);
        *c = kcos(x, 0.0);
        return;
    }
    if (!(fabs(x) < 823550.0)) { /* 2^19 pi/2 and beyond (or NaN): libm */
        *s = sin(x);
        *c = cos(x);
        return;
    }
    const double big = 6755399441055744.0; /* 1.5 * 2^52: adding it rounds to an integer (round to nearest; C99 does not reassociate) */
    double fn = (x * INVPIO2 + big) - big;
    int64_t n = (int64_t)fn;
    /* fdlibm's three rounds (its second and third taken always: more bits of pi/2, never fewer); fn * PIO2_k
     * is exact (33-bit constants, |fn| < 2^19) */
    double r = x - fn * PIO2_1, w = fn * PIO2_1T, t = r;
    w = fn * PIO2_2;
    r = t - w;
    w = fn * PIO2_2T - ((t - r) - w);
    t = r;
    w = fn * PIO2_3;
    r = t - w;
    w = fn * PIO2_3T - ((t - r) - w);
    double y0 = r - w, y1 = (r - y0) - w, sn = ksin(y0, y1), cs = kcos(y0, y1);
    switch (n & 3) {
    case 0: *s = sn; *c = cs; break;
    case 1: *s = cs; *c = -sn; break;
    case 2: *s = -sn; *c = -cs; break;
    default: *s = -cs; *c = sn; break;
    }
}

#if defined(__SSE2__)
/* ksin(x, 0) and kcos(x, 0) of two angles at once: the scalar kernels' operations in the same order */
static inline void ksincos2(double x0, double x1, double *s0, double *c0, double *s1, double *c1) {
    const __m128d zero = _mm_setzero_pd(), half = _mm_set1_pd(0.5), one = _mm_set1_pd(1.0);
    __m128d x = _mm_set_pd(x1, x0), y = zero;
    __m128d z = _mm_mul_pd(x, x), w = _mm_mul_pd(z, z);
    /* sin: r = S2 + z (S3 + z S4) + z w (S5 + z S6); x - ((z (0.5 y - v r) - y) - v S1), v = z x */
    __m128d r = _mm_add_pd(
        _mm_add_pd(_mm_set1_pd(S2), _mm_mul_pd(z, _mm_add_pd(_mm_set1_pd(S3), _mm_mul_pd(z, _mm_set1_pd(S4))))),
        _mm_mul_pd(_mm_mul_pd(z, w), _mm_add_pd(_mm_set1_pd(S5), _mm_mul_pd(z, _mm_set1_pd(S6)))));
    __m128d v = _mm_mul_pd(z, x);
    __m128d t = _mm_sub_pd(_mm_mul_pd(z, _mm_sub_pd(_mm_mul_pd(half, y), _mm_mul_pd(v, r))), y);
    __m128d sn = _mm_sub_pd(x, _mm_sub_pd(t, _mm_mul_pd(v, _mm_set1_pd(S1))));
    /* cos: r = z (C1 + z (C2 + z C3)) + w w (C4 + z (C5 + z C6)); u + (((1 - u) - hz) + (z r - x y)) */
    __m128d rc = _mm_add_pd(
        _mm_mul_pd(z, _mm_add_pd(_mm_set1_pd(C1), _mm_mul_pd(z, _mm_add_pd(_mm_set1_pd(C2), _mm_mul_pd(z, _mm_set1_pd(C3)))))),
        _mm_mul_pd(_mm_mul_pd(w, w),
                   _mm_add_pd(_mm_set1_pd(C4), _mm_mul_pd(z, _mm_add_pd(_mm_set1_pd(C5), _mm_mul_pd(z, _mm_set1_pd(C6)))))));
    __m128d hz = _mm_mul_pd(half, z), u = _mm_sub_pd(one, hz);
    __m128d cs = _mm_add_pd(u, _mm_add_pd(_mm_sub_pd(_mm_sub_pd(one, u), hz), _mm_sub_pd(_mm_mul_pd(z, rc), _mm_mul_pd(x, y))));
    double out[2];
    _mm_storeu_pd(out, sn);
    *s0 = out[0]; *s1 = out[1];
    _mm_storeu_pd(out, cs);
    *c0 = out[0]; *c1 = out[1];
}
#endif

/* g: base anchors b_i (6x3) then plate anchors relative to the rotation centre t_i (6x3), metres. */
void sd_ik(int64_t n, const double *restrict g, int conv, const double *restrict q, double *restrict L) {
    double bx[6], by[6], bz[6], tx[6], ty[6], tz[6];
    for (int i = 0; i < 6; i++) {
        bx[i] = g[3 * i]; by[i] = g[3 * i + 1]; bz[i] = g[3 * i + 2];
        tx[i] = g[18 + 3 * i]; ty[i] = g[18 + 3 * i + 1]; tz[i] = g[18 + 3 * i + 2];
    }
    for (int64_t k = 0; k < n; k++) {
        const double *p = q + 6 * k;
        double sa, ca, sb, cb, sg, cg, R[9];
#if defined(__SSE2__)
        if (fabs(p[3]) <= 0.785398163397448279 && fabs(p[4]) <= 0.785398163397448279) {
            ksincos2(p[3], p[4], &sa, &ca, &sb, &cb);
        } else {
            sd_sincos(p[3], &sa, &ca);
            sd_sincos(p[4], &sb, &cb);
        }
#else
        sd_sincos(p[3], &sa, &ca);
        sd_sincos(p[4], &sb, &cb);
#endif
        sd_sincos(p[5], &sg, &cg);
        if (conv == 0) { /* utn: Ry(b) Rx(a) Rz(g) */
            R[0] = cb * cg + sa * sb * sg; R[1] = sa * sb * cg - cb * sg; R[2] = ca * sb;
            R[3] = ca * sg; R[4] = ca * cg; R[5] = -sa;
            R[6] = sa * cb * sg - sb * cg; R[7] = sb * sg + sa * cb * cg; R[8] = ca * cb;
        } else { /* zyx: Rz(psi) Ry(theta) Rx(phi) */
            R[0] = cb * cg; R[1] = sa * sb * cg - ca * sg; R[2] = ca * sb * cg + sa * sg;
            R[3] = cb * sg; R[4] = sa * sb * sg + ca * cg; R[5] = ca * sb * sg - sa * cg;
            R[6] = -sb; R[7] = sa * cb; R[8] = ca * cb;
        }
        double *out = L + 6 * k;
#if defined(__SSE2__)
        __m128d r0 = _mm_set1_pd(R[0]), r1 = _mm_set1_pd(R[1]), r2 = _mm_set1_pd(R[2]), r3 = _mm_set1_pd(R[3]);
        __m128d r4 = _mm_set1_pd(R[4]), r5 = _mm_set1_pd(R[5]), r6 = _mm_set1_pd(R[6]), r7 = _mm_set1_pd(R[7]);
        __m128d r8 = _mm_set1_pd(R[8]), px = _mm_set1_pd(p[0]), py = _mm_set1_pd(p[1]), pz = _mm_set1_pd(p[2]);
        for (int i = 0; i < 6; i += 2) {
            __m128d X = _mm_loadu_pd(tx + i), Y = _mm_loadu_pd(ty + i), Z = _mm_loadu_pd(tz + i);
            __m128d x = _mm_add_pd(_mm_add_pd(_mm_add_pd(_mm_mul_pd(r0, X), _mm_mul_pd(r1, Y)), _mm_mul_pd(r2, Z)),
                                   _mm_sub_pd(px, _mm_loadu_pd(bx + i)));
            __m128d y = _mm_add_pd(_mm_add_pd(_mm_add_pd(_mm_mul_pd(r3, X), _mm_mul_pd(r4, Y)), _mm_mul_pd(r5, Z)),
                                   _mm_sub_pd(py, _mm_loadu_pd(by + i)));
            __m128d z = _mm_add_pd(_mm_add_pd(_mm_add_pd(_mm_mul_pd(r6, X), _mm_mul_pd(r7, Y)), _mm_mul_pd(r8, Z)),
                                   _mm_sub_pd(pz, _mm_loadu_pd(bz + i)));
            __m128d s2 = _mm_add_pd(_mm_add_pd(_mm_mul_pd(x, x), _mm_mul_pd(y, y)), _mm_mul_pd(z, z));
            _mm_storeu_pd(out + i, _mm_sqrt_pd(s2));
        }
#else
        for (int i = 0; i < 6; i++) { /* the numpy order: ((R0 t0 + R1 t1) + R2 t2) + (p - b) */
            double x = R[0] * tx[i] + R[1] * ty[i] + R[2] * tz[i] + (p[0] - bx[i]);
            double y = R[3] * tx[i] + R[4] * ty[i] + R[5] * tz[i] + (p[1] - by[i]);
            double z = R[6] * tx[i] + R[7] * ty[i] + R[8] * tz[i] + (p[2] - bz[i]);
            out[i] = sqrt(x * x + y * y + z * z);
        }
#endif
    }
}
