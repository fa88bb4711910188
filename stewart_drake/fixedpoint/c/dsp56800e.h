/* dsp56800e.h -- host implementation of the DSP56800E (MC56F8367) fractional intrinsics.
 *
 * C99, no floating point except the run-time FRAC16/FRAC32 of a double (as CodeWarrior's macros).
 * Semantics are the CodeWarrior intrinsics with the OMR's SA bit set (saturation on) and R bit set
 * (two's-complement rounding: add 0x8000 and truncate, ties toward +inf), i.e. the ETSI/ITU-T basic
 * operators; they equal stewart_drake.fixedpoint.q15 bit for bit (see its module table):
 *
 *   add/sub/negate/abs_s      sat16;  negate(-32768) = abs_s(-32768) = 32767
 *   L_add/L_sub/L_negate/L_abs sat32
 *   L_mult(a, b)              sat32(2ab): only -32768 * -32768 saturates
 *   mult, mult_r              sat16((ab) >> 15), sat16((ab + 2^14) >> 15)
 *   extract_h / extract_l     L >> 16 (arithmetic) / the low 16 bits, wrapped
 *   L_deposit_h / _l          a << 16 / a sign-extended
 *   round                     extract_h(L_add(L, 0x8000))
 *   L_mac, L_msu, mac_r, msu_r  ETSI compositions (two saturations)
 *   shl, shr, L_shl, L_shr    arithmetic shifts, left saturating, negative counts shift the other way
 *   div_s(a, b)               floor(a 2^15 / b) for 0 <= a <= b, b > 0; 32767 when a == b
 *   mfr32Sqrt(L)              rtlib: 15-step bit search for the largest y with 2y^2 <= L, then the nearer
 *                             of y, sat16(y + 1); L <= 0 gives 0
 *   tfr16SinPIx/tfr16CosPIx   Motorola tfr16.c: fold, 7-term odd polynomial (Horner with mac_r), L_shl 3
 *
 * Every right shift of a negative value goes through dsp_asr32/dsp_asr64 (floor division by a power of
 * two written without implementation-defined behaviour; compilers emit one arithmetic shift).
 *
 * The ETSI names (add, sub, round, ...) are function-like macros over dsp_* inline functions, so they do
 * not collide with libc's round(); firmware including this header must not also use <math.h>'s round.
 *
 * Build options:
 *   DSP_COUNT_OPS          count every intrinsic call in dsp_op_counts[DSP_OP_<name>] (instrumented
 *                          build for the cycle model cross-check; L_mac etc. count their parts)
 *   DSP_COUNT_SATURATIONS  count every saturation (clipped result) in dsp_saturations
 */
#ifndef DSP56800E_H
#define DSP56800E_H

#include <stdint.h>

typedef int16_t Word16;
typedef int32_t Word32;
typedef int16_t Frac16;
typedef int32_t Frac32;
typedef int16_t Int16;
typedef int32_t Int32;

#define DSP_MIN16 (-32768)
#define DSP_MAX16 32767
#define DSP_MIN32 (-2147483647L - 1L)
#define DSP_MAX32 2147483647L

/* operation indices of the instrumented build (names as in fixedpoint.cycles) */
enum {
    DSP_OP_add, DSP_OP_sub, DSP_OP_negate, DSP_OP_abs_s, DSP_OP_L_add, DSP_OP_L_sub, DSP_OP_L_negate,
    DSP_OP_L_abs, DSP_OP_L_mult, DSP_OP_extract_h, DSP_OP_extract_l, DSP_OP_L_deposit_h, DSP_OP_L_deposit_l,
    DSP_OP_round, DSP_OP_mult, DSP_OP_mult_r, DSP_OP_shl, DSP_OP_shr, DSP_OP_L_shl, DSP_OP_L_shr,
    DSP_OP_div_s, DSP_OP_mfr32Sqrt, DSP_OP_tfr16SinPIx, DSP_OP_tfr16CosPIx, DSP_OP_FRAC16,
    DSP_OP_N
};
#define DSP_OP_NAMES "add sub negate abs_s L_add L_sub L_negate L_abs L_mult extract_h extract_l " \
    "L_deposit_h L_deposit_l round mult mult_r shl shr L_shl L_shr div_s mfr32Sqrt tfr16SinPIx tfr16CosPIx FRAC16"

#ifdef DSP_COUNT_OPS
extern long dsp_op_counts[DSP_OP_N];
extern int dsp_op_counting;
#define DSP_OP(name) (dsp_op_counts[DSP_OP_##name] += dsp_op_counting)
#else
#define DSP_OP(name) ((void)0)
#endif

#ifdef DSP_COUNT_SATURATIONS
extern long dsp_saturations;
#define DSP_SAT_HIT() (dsp_saturations++)
#else
#define DSP_SAT_HIT() ((void)0)
#endif

/* floor(x / 2^n), n >= 0: the arithmetic right shift, without relying on implementation-defined >> */
static inline int32_t dsp_asr32(int32_t x, int n) { return x >= 0 ? (int32_t)(x >> n) : (int32_t)(-((-(x + 1)) >> n) - 1); }
static inline int64_t dsp_asr64(int64_t x, int n) { return x >= 0 ? (x >> n) : (-((-(x + 1)) >> n) - 1); }

static inline Word16 dsp_sat16(int64_t x)
{
    if (x > DSP_MAX16) { DSP_SAT_HIT(); return (Word16)DSP_MAX16; }
    if (x < DSP_MIN16) { DSP_SAT_HIT(); return (Word16)DSP_MIN16; }
    return (Word16)x;
}

static inline Word32 dsp_sat32(int64_t x)
{
    if (x > DSP_MAX32) { DSP_SAT_HIT(); return (Word32)DSP_MAX32; }
    if (x < DSP_MIN32) { DSP_SAT_HIT(); return (Word32)DSP_MIN32; }
    return (Word32)x;
}

/* ---- conversions (CodeWarrior macros: truncation toward zero, saturating at +-1) ---- */
static inline Frac16 dsp_FRAC16(double x)
{
    double t = x * 32768.0;
    if (!(t == t)) return 0; /* NaN: undefined on the DSP */
    if (t >= 32768.0) { DSP_SAT_HIT(); return (Frac16)DSP_MAX16; }
    if (t <= -32769.0) { DSP_SAT_HIT(); return (Frac16)DSP_MIN16; }
    return (Frac16)t; /* the C cast truncates toward zero */
}

static inline Frac32 dsp_FRAC32(double x)
{
    double t = x * 2147483648.0;
    if (!(t == t)) return 0;
    if (t >= 2147483648.0) { DSP_SAT_HIT(); return (Frac32)DSP_MAX32; }
    if (t <= -2147483649.0) { DSP_SAT_HIT(); return (Frac32)DSP_MIN32; }
    return (Frac32)t;
}

/* ---- 16-bit operators ---- */
static inline Word16 dsp_add(Word16 a, Word16 b) { DSP_OP(add); return dsp_sat16((int32_t)a + b); }
static inline Word16 dsp_sub(Word16 a, Word16 b) { DSP_OP(sub); return dsp_sat16((int32_t)a - b); }
static inline Word16 dsp_negate(Word16 a) { DSP_OP(negate); return dsp_sat16(-(int32_t)a); }
static inline Word16 dsp_abs_s(Word16 a) { DSP_OP(abs_s); return dsp_sat16(a < 0 ? -(int32_t)a : (int32_t)a); }
static inline Word16 dsp_mult(Word16 a, Word16 b) { DSP_OP(mult); return dsp_sat16(dsp_asr32((int32_t)a * b, 15)); }
static inline Word16 dsp_mult_r(Word16 a, Word16 b) { DSP_OP(mult_r); return dsp_sat16(dsp_asr32((int32_t)a * b + 0x4000, 15)); }

static inline Word16 dsp_shl(Word16 a, Word16 n)
{
    DSP_OP(shl);
    if (n < 0) return (Word16)dsp_asr32(a, n < -15 ? 15 : -n);
    return dsp_sat16((int64_t)a * ((int64_t)1 << (n > 16 ? 16 : n)));
}

static inline Word16 dsp_shr(Word16 a, Word16 n)
{
    DSP_OP(shr);
    if (n < 0) return dsp_sat16((int64_t)a * ((int64_t)1 << (n < -16 ? 16 : -n)));
    return (Word16)dsp_asr32(a, n > 15 ? 15 : n);
}

/* ---- 32-bit operators ---- */
static inline Word32 dsp_L_add(Word32 a, Word32 b) { DSP_OP(L_add); return dsp_sat32((int64_t)a + b); }
static inline Word32 dsp_L_sub(Word32 a, Word32 b) { DSP_OP(L_sub); return dsp_sat32((int64_t)a - b); }
static inline Word32 dsp_L_negate(Word32 a) { DSP_OP(L_negate); return dsp_sat32(-(int64_t)a); }
static inline Word32 dsp_L_abs(Word32 a) { DSP_OP(L_abs); return dsp_sat32(a < 0 ? -(int64_t)a : (int64_t)a); }
static inline Word32 dsp_L_mult(Word16 a, Word16 b) { DSP_OP(L_mult); return dsp_sat32(2 * (int64_t)a * b); }
static inline Word32 dsp_L_mac(Word32 acc, Word16 a, Word16 b) { return dsp_L_add(acc, dsp_L_mult(a, b)); }
static inline Word32 dsp_L_msu(Word32 acc, Word16 a, Word16 b) { return dsp_L_sub(acc, dsp_L_mult(a, b)); }

static inline Word32 dsp_L_shl(Word32 a, Word16 n)
{
    DSP_OP(L_shl);
    if (n < 0) return dsp_asr32(a, n < -31 ? 31 : -n);
    return dsp_sat32((int64_t)a * ((int64_t)1 << (n > 32 ? 32 : n)));
}

static inline Word32 dsp_L_shr(Word32 a, Word16 n)
{
    DSP_OP(L_shr);
    if (n < 0) return dsp_sat32((int64_t)a * ((int64_t)1 << (n < -32 ? 32 : -n)));
    return dsp_asr32(a, n > 31 ? 31 : n);
}

static inline Word16 dsp_extract_h(Word32 L) { DSP_OP(extract_h); return (Word16)dsp_asr32(L, 16); }
static inline Word16 dsp_extract_l(Word32 L)
{
    int32_t low = (int32_t)((uint32_t)L & 0xFFFFu);
    DSP_OP(extract_l);
    return (Word16)((low ^ 0x8000) - 0x8000);
}
static inline Word32 dsp_L_deposit_h(Word16 a) { DSP_OP(L_deposit_h); return (Word32)a * 65536; }
static inline Word32 dsp_L_deposit_l(Word16 a) { DSP_OP(L_deposit_l); return (Word32)a; }
static inline Word16 dsp_round(Word32 L) { DSP_OP(round); return (Word16)dsp_asr32(dsp_sat32((int64_t)L + 0x8000), 16); }
static inline Word16 dsp_mac_r(Word32 acc, Word16 a, Word16 b) { return dsp_round(dsp_L_mac(acc, a, b)); }
static inline Word16 dsp_msu_r(Word32 acc, Word16 a, Word16 b) { return dsp_round(dsp_L_msu(acc, a, b)); }

/* Q15 quotient for 0 <= a <= b, b > 0 (undefined on the hardware elsewhere: returns 0 here) */
static inline Word16 dsp_div_s(Word16 a, Word16 b)
{
    DSP_OP(div_s);
    if (a < 0 || b <= 0 || a > b) return 0;
    if (a == b) return (Word16)DSP_MAX16;
    return (Word16)(((int32_t)a << 15) / b);
}

/* ---- library functions (dsp56800e.c) ---- */
Word16 mfr32Sqrt(Frac32 L);
Frac16 tfr16SinPIx(Frac16 x);
Frac16 tfr16CosPIx(Frac16 x);

/* ---- the DSP names ---- */
#define FRAC16(x) dsp_FRAC16(x)
#define FRAC32(x) dsp_FRAC32(x)
#define add(a, b) dsp_add((a), (b))
#define sub(a, b) dsp_sub((a), (b))
#define negate(a) dsp_negate(a)
#define abs_s(a) dsp_abs_s(a)
#define mult(a, b) dsp_mult((a), (b))
#define mult_r(a, b) dsp_mult_r((a), (b))
#define shl(a, n) dsp_shl((a), (n))
#define shr(a, n) dsp_shr((a), (n))
#define L_add(a, b) dsp_L_add((a), (b))
#define L_sub(a, b) dsp_L_sub((a), (b))
#define L_negate(a) dsp_L_negate(a)
#define L_abs(a) dsp_L_abs(a)
#define L_mult(a, b) dsp_L_mult((a), (b))
#define L_mac(c, a, b) dsp_L_mac((c), (a), (b))
#define L_msu(c, a, b) dsp_L_msu((c), (a), (b))
#define L_shl(a, n) dsp_L_shl((a), (n))
#define L_shr(a, n) dsp_L_shr((a), (n))
#define extract_h(L) dsp_extract_h(L)
#define extract_l(L) dsp_extract_l(L)
#define L_deposit_h(a) dsp_L_deposit_h(a)
#define L_deposit_l(a) dsp_L_deposit_l(a)
#define round(L) dsp_round(L)
#define mac_r(c, a, b) dsp_mac_r((c), (a), (b))
#define msu_r(c, a, b) dsp_msu_r((c), (a), (b))
#define div_s(a, b) dsp_div_s((a), (b))
/* the Processor Expert bean names tp17.C calls */
#define TFR1_tfr16SinPIx(x) tfr16SinPIx(x)
#define TFR1_tfr16CosPIx(x) tfr16CosPIx(x)

#endif /* DSP56800E_H */
