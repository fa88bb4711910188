/* dsp56800e.c -- the DSP56800E library functions the firmware calls, bit-exact on the host:
 * mfr32Sqrt (Freescale rtlib) and tfr16SinPIx / tfr16CosPIx (Motorola tfr16.c), plus the counters of
 * the instrumented build. Same arithmetic as stewart_drake.fixedpoint.q15 / .scalar. */
#include "dsp56800e.h"

#ifdef DSP_COUNT_OPS
long dsp_op_counts[DSP_OP_N];
int dsp_op_counting = 1;
#endif
#ifdef DSP_COUNT_SATURATIONS
long dsp_saturations;
#endif

/* Inside the library functions nothing is counted: their cost is one entry of the cycle table, and the
 * emulation builds their results without recording saturations. */
static int32_t s16(int64_t x) { return x > DSP_MAX16 ? DSP_MAX16 : x < DSP_MIN16 ? DSP_MIN16 : (int32_t)x; }
static int32_t s32(int64_t x) { return x > DSP_MAX32 ? (int32_t)DSP_MAX32 : x < DSP_MIN32 ? (int32_t)DSP_MIN32 : (int32_t)x; }

/* rtlib mfr32Sqrt: 15 trial bits, 2y^2 compared with L in a wide accumulator (mpy, no saturation), then
 * the nearer of y and y + 1, y + 1 saturated (mfr32SqrtC uses add): sqrt(0x7FFFFFFF) = 32767. */
Word16 mfr32Sqrt(Frac32 L)
{
    int32_t y = 0, yr;
    int k;
    int64_t dy, dr;
    DSP_OP(mfr32Sqrt);
    for (k = 14; k >= 0; k--) {
        int32_t t = y | ((int32_t)1 << k);
        if (2 * (int64_t)t * t <= (int64_t)L) y = t;
    }
    yr = y + 1 > DSP_MAX16 ? DSP_MAX16 : y + 1;
    dy = (int64_t)L - 2 * (int64_t)y * y;
    dr = (int64_t)L - 2 * (int64_t)yr * yr;
    if (dy < 0) dy = -dy;
    if (dr < 0) dr = -dr;
    return (Word16)(dr < dy ? yr : y);
}

/* tfr16.c: FRAC16 of the coefficients c_k / 8 of sin(pi x) = sum c_k x^(2k+1) (compile-time words) */
static const int32_t SINE_COEF[7] = {
    12867,  /* FRAC16(0.39269908169872)  */
    -21166, /* FRAC16(-0.64596409750625) */
    10445,  /* FRAC16(0.31877050498467)  */
    -2440,  /* FRAC16(-0.07446482317004) */
    336,    /* FRAC16(0.01026823582639)  */
    -30,    /* FRAC16(-0.00092130386821) */
    1       /* FRAC16(0.00005828785072)  */
};

/* mac_r(L_deposit_h(c), a, b) without counting */
static int32_t horner(int32_t c, int32_t a, int32_t b)
{
    return dsp_asr32(s32((int64_t)s32((int64_t)c * 65536 + s32(2 * (int64_t)a * b)) + 0x8000), 16);
}

Frac16 tfr16SinPIx(Frac16 x0)
{
    int32_t x = x0, z, t, r;
    int64_t acc;
    int i, sign = 0;
    DSP_OP(tfr16SinPIx);
    if (x < 0) { sign = 1; x = s16(-(int64_t)x); }
    if (x > 16384) x = s16((int64_t)DSP_MAX16 - x);                 /* sub(FRAC16(1.0), x) */
    z = s16(dsp_asr32(x * x + 0x4000, 15));                         /* mult_r(x, x) */
    t = horner(SINE_COEF[5], z, SINE_COEF[6]);
    for (i = 4; i >= 0; i--) t = horner(SINE_COEF[i], t, z);
    acc = s32(2 * (int64_t)t * x);                                  /* L_mult(t, x) */
    acc = s32(acc * 8);                                             /* L_shl(., 3) */
    r = dsp_asr32(s32(acc + 0x8000), 16);                           /* round */
    return (Frac16)(sign ? s16(-(int64_t)r) : r);
}

Frac16 tfr16CosPIx(Frac16 x0)
{
    int32_t x = x0, z;
    int sign = 0;
    Frac16 r;
#ifdef DSP_COUNT_OPS
    int was = dsp_op_counting;
#endif
    DSP_OP(tfr16CosPIx);
    if (x < 0) x = s16(-(int64_t)x);
    if (x > 16384) { x = s16((int64_t)DSP_MAX16 - x); sign = 1; }
    x = s16(16384 - (int64_t)x);
    if (sign) x = s16((int64_t)x + 1);
#ifdef DSP_COUNT_OPS
    dsp_op_counting = 0; /* the inner sine is part of CosPIx's cost */
#endif
    r = tfr16SinPIx((Frac16)x);
#ifdef DSP_COUNT_OPS
    dsp_op_counting = was;
#endif
    z = r;
    return (Frac16)(sign ? s16(-(int64_t)z) : z);
}
