/* dsp_batch.c -- array wrappers over the intrinsics, for the host's property tests and benchmarks:
 * one call applies intrinsic `op` (DSP_OP_* order, see dsp_batch_op below) elementwise to n inputs. */
#include "dsp56800e.h"

enum {
    B_add, B_sub, B_negate, B_abs_s, B_mult, B_mult_r, B_shl, B_shr, B_L_add, B_L_sub, B_L_negate, B_L_abs,
    B_L_mult, B_L_mac, B_L_msu, B_L_shl, B_L_shr, B_extract_h, B_extract_l, B_L_deposit_h, B_L_deposit_l,
    B_round, B_mac_r, B_msu_r, B_div_s, B_mfr32Sqrt, B_tfr16SinPIx, B_tfr16CosPIx
};

/* out[i] = op(a[i], b[i], c[i]) with the operands narrowed to the intrinsic's argument types (the caller
 * passes in-range words); returns 0, or -1 for an unknown op */
int dsp_batch(int op, const int64_t *a, const int64_t *b, const int64_t *c, int64_t *out, long n)
{
    long i;
#define LOOP(expr) for (i = 0; i < n; i++) out[i] = (expr); return 0
    switch (op) {
    case B_add: LOOP(add((Word16)a[i], (Word16)b[i]));
    case B_sub: LOOP(sub((Word16)a[i], (Word16)b[i]));
    case B_negate: LOOP(negate((Word16)a[i]));
    case B_abs_s: LOOP(abs_s((Word16)a[i]));
    case B_mult: LOOP(mult((Word16)a[i], (Word16)b[i]));
    case B_mult_r: LOOP(mult_r((Word16)a[i], (Word16)b[i]));
    case B_shl: LOOP(shl((Word16)a[i], (Word16)b[i]));
    case B_shr: LOOP(shr((Word16)a[i], (Word16)b[i]));
    case B_L_add: LOOP(L_add((Word32)a[i], (Word32)b[i]));
    case B_L_sub: LOOP(L_sub((Word32)a[i], (Word32)b[i]));
    case B_L_negate: LOOP(L_negate((Word32)a[i]));
    case B_L_abs: LOOP(L_abs((Word32)a[i]));
    case B_L_mult: LOOP(L_mult((Word16)a[i], (Word16)b[i]));
    case B_L_mac: LOOP(L_mac((Word32)a[i], (Word16)b[i], (Word16)c[i]));
    case B_L_msu: LOOP(L_msu((Word32)a[i], (Word16)b[i], (Word16)c[i]));
    case B_L_shl: LOOP(L_shl((Word32)a[i], (Word16)b[i]));
    case B_L_shr: LOOP(L_shr((Word32)a[i], (Word16)b[i]));
    case B_extract_h: LOOP(extract_h((Word32)a[i]));
    case B_extract_l: LOOP(extract_l((Word32)a[i]));
    case B_L_deposit_h: LOOP(L_deposit_h((Word16)a[i]));
    case B_L_deposit_l: LOOP(L_deposit_l((Word16)a[i]));
    case B_round: LOOP(round((Word32)a[i]));
    case B_mac_r: LOOP(mac_r((Word32)a[i], (Word16)b[i], (Word16)c[i]));
    case B_msu_r: LOOP(msu_r((Word32)a[i], (Word16)b[i], (Word16)c[i]));
    case B_div_s: LOOP(div_s((Word16)a[i], (Word16)b[i]));
    case B_mfr32Sqrt: LOOP(mfr32Sqrt((Frac32)a[i]));
    case B_tfr16SinPIx: LOOP(TFR1_tfr16SinPIx((Frac16)a[i]));
    case B_tfr16CosPIx: LOOP(TFR1_tfr16CosPIx((Frac16)a[i]));
    default: return -1;
    }
#undef LOOP
}

/* FRAC16 (which = 0) or FRAC32 (which = 1) of n doubles */
void dsp_batch_frac(int which, const double *x, int64_t *out, long n)
{
    long i;
    for (i = 0; i < n; i++) out[i] = which ? (int64_t)FRAC32(x[i]) : (int64_t)FRAC16(x[i]);
}
