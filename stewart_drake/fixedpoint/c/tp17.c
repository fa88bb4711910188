/* tp17.c -- the inverse kinematics of the seed firmware tp17.C (seed 000, MC56F8367, 26/04/2011),
 * transcribed as a function from the listing's main(): the set-up before for(;;) (the plate joints
 * xt*, yt*, zt*) and one pass of the loop body (six leg lengths L1..L6 in integer mm).
 *
 * Units are the firmware's: px, py, pz integer mm (Frac16 variables holding integers), alpha, beta,
 * gama fractions of pi as C doubles (0.1 = 18 deg), a, b, d integer mm (the seed: a = 1225/2 = 612,
 * b = 925, d = 150). The statements are the listing's, in its order, with its intrinsics (dsp56800e.h).
 *
 * Left out: the base anchors Xb1..Zb6 the listing computes first are never read (the leg formulas
 * recompute their offsets from b and d into aux32), so they are dead code and not transcribed; the
 * Processor Expert start-up and the printf test arrays likewise.
 *
 * Two lines of the listing are garbled by its print and are restored, as the Python port
 * (stewart_drake.fixedpoint.tp17) restores them, by the symmetry of the other eight lines:
 *   - Yt1 repeats "extract_h(L_mult(co21,xt1))" many times and ends in "3,zt1))),co24)": restored as
 *     add(add(add(extract_h(L_mult(co21,xt1)),extract_h(L_mult(co22,yt1))),extract_h(L_mult(co23,zt1))),co24)
 *   - the co32 assignment lost its left-hand side ("add(extract h(L mult(sinB,sinG)),..." stands alone
 *     between co31 and co33): restored as "co32 = add(...)".
 * The Xt2 and Xt3 lines also lost "Xt2 =" / "Xt3 =" in the print; their position between Zt1/Yt2 and
 * Zt2/Yt3 leaves no other reading.
 *
 * The six FRAC16(double) conversions of the angles happen at run time on the DSP (software float); they
 * are marked RT_FRAC16 so that the instrumented build counts them, while FRAC16 of a literal is folded
 * by the compiler and not counted (as in fixedpoint.scalar.tp17_op_counts).
 */
#include "dsp56800e.h"

#define RT_FRAC16(x) (DSP_OP(FRAC16), FRAC16(x))

void tp17_ik(Frac16 px, Frac16 py, Frac16 pz, double alpha, double beta, double gama,
             Frac16 a, Frac16 b, Frac16 d, Word16 L[6])
{
    Frac16 cosA, cosB, cosG, sinA, sinB, sinG;
    Frac16 co11, co12, co13, co14, co21, co22, co23, co24, co31, co32, co33, co34;
    Word16 Xt1, Xt2, Xt3, Yt1, Yt2, Yt3, Zt1, Zt2, Zt3;
    Word16 xt1, xt2, xt3, yt1, yt2, yt3, zt1, zt2, zt3;
    Word32 aux32, L1_32, L2_32, L3_32, L4_32, L5_32, L6_32;
    Word16 aux16;
    int was;

#ifdef DSP_COUNT_OPS
    was = dsp_op_counting;
    dsp_op_counting = 0; /* the set-up runs once, before for(;;): not part of a pass */
#else
    was = 0;
#endif
    (void)was;
    /* xt1 = (sqrt(3)/6)*a; */
    aux16 = FRAC16(0.2886);
    aux32 = L_mult(aux16, a);
    xt1 = extract_h(aux32);
    /* yt1 = (1/2)*a; */
    aux16 = FRAC16(0.5);
    aux32 = L_mult(aux16, a);
    yt1 = extract_h(aux32);
    zt1 = 0;
    /* xt2 = -(sqrt(3)/3)*a; */
    aux16 = FRAC16(-0.5773);
    aux32 = L_mult(aux16, a);
    xt2 = extract_h(aux32);
    yt2 = 0;
    zt2 = 0;
    /* xt3 = (sqrt(3)/6)*a; */
    aux16 = FRAC16(0.2886);
    aux32 = L_mult(aux16, a);
    xt3 = extract_h(aux32);
    /* yt3 = -(1/2)*a; */
    aux16 = FRAC16(-0.5);
    aux32 = L_mult(aux16, a);
    yt3 = extract_h(aux32);
    zt3 = 0;
#ifdef DSP_COUNT_OPS
    dsp_op_counting = was;
#endif

    /* for(;;) { -- one pass */
    cosA = TFR1_tfr16CosPIx(RT_FRAC16(alpha));
    cosB = TFR1_tfr16CosPIx(RT_FRAC16(beta));
    cosG = TFR1_tfr16CosPIx(RT_FRAC16(gama));
    sinA = TFR1_tfr16SinPIx(RT_FRAC16(alpha));
    sinB = TFR1_tfr16SinPIx(RT_FRAC16(beta));
    sinG = TFR1_tfr16SinPIx(RT_FRAC16(gama));
    co11 = add(extract_h(L_mult(cosB, cosG)), extract_h(L_mult(extract_h(L_mult(sinA, sinB)), sinG)));
    co12 = add(extract_h(L_mult(negate(cosB), sinG)), extract_h(L_mult(extract_h(L_mult(sinA, sinB)), cosG)));
    co13 = extract_h(L_mult(cosA, sinB));
    co14 = px;
    co21 = extract_h(L_mult(cosA, sinG));
    co22 = extract_h(L_mult(cosA, cosG));
    co23 = negate(sinA);
    co24 = py;
    co31 = add(extract_h(L_mult(negate(sinB), cosG)), extract_h(L_mult(extract_h(L_mult(sinA, cosB)), sinG)));
    /* restored: the listing prints this right-hand side without "co32 =" */
    co32 = add(extract_h(L_mult(sinB, sinG)), extract_h(L_mult(extract_h(L_mult(sinA, cosB)), cosG)));
    co33 = extract_h(L_mult(cosA, cosB));
    co34 = pz;
    /* co41..co44 = 0, 0, 0, 1: the homogeneous row, never read */

    /* Posicion de los vertices de la plataforma TOP respecto de la base. */
    Xt1 = add(add(add(extract_h(L_mult(co11, xt1)), extract_h(L_mult(co12, yt1))), extract_h(L_mult(co13, zt1))), co14);
    /* restored: the listing repeats extract_h(L_mult(co21,xt1)) here; the third product is co23*zt1 */
    Yt1 = add(add(add(extract_h(L_mult(co21, xt1)), extract_h(L_mult(co22, yt1))), extract_h(L_mult(co23, zt1))), co24);
    Zt1 = add(add(add(extract_h(L_mult(co31, xt1)), extract_h(L_mult(co32, yt1))), extract_h(L_mult(co33, zt1))), co34);
    Xt2 = add(add(add(extract_h(L_mult(co11, xt2)), extract_h(L_mult(co12, yt2))), extract_h(L_mult(co13, zt2))), co14);
    Yt2 = add(add(add(extract_h(L_mult(co21, xt2)), extract_h(L_mult(co22, yt2))), extract_h(L_mult(co23, zt2))), co24);
    Zt2 = add(add(add(extract_h(L_mult(co31, xt2)), extract_h(L_mult(co32, yt2))), extract_h(L_mult(co33, zt2))), co34);
    Xt3 = add(add(add(extract_h(L_mult(co11, xt3)), extract_h(L_mult(co12, yt3))), extract_h(L_mult(co13, zt3))), co14);
    Yt3 = add(add(add(extract_h(L_mult(co21, xt3)), extract_h(L_mult(co22, yt3))), extract_h(L_mult(co23, zt3))), co24);
    Zt3 = add(add(add(extract_h(L_mult(co31, xt3)), extract_h(L_mult(co32, yt3))), extract_h(L_mult(co33, zt3))), co34);

    /* L1 = sqrt((Xt1 - d/(2*sqrt(3)) - b/sqrt(3))^2 + (Yt1 - d/2)^2 + Zt1^2); */
    aux32 = L_add(L_negate(L_mult(d, FRAC16(0.2886))), L_negate(L_mult(b, FRAC16(0.5773))));
    aux16 = add(extract_h(aux32), Xt1);
    L1_32 = L_mult(aux16, aux16);
    aux16 = add(Yt1, negate(extract_h(L_mult(FRAC16(0.5), d))));
    L1_32 = L_add(L_mult(aux16, aux16), L1_32);
    L1_32 = L_add(L_mult(Zt1, Zt1), L1_32);
    L[0] = mfr32Sqrt(L1_32);
    /* L2 = sqrt((Xt1 - d/(2*sqrt(3)) + b/(2*sqrt(3)))^2 + (Yt1 - d/2 - b/2)^2 + Zt1^2); */
    aux32 = L_add(L_negate(L_mult(d, FRAC16(0.2886))), L_mult(b, FRAC16(0.2886)));
    aux16 = add(extract_h(aux32), Xt1);
    L2_32 = L_mult(aux16, aux16);
    aux16 = add(Yt1, negate(extract_h(L_mult(FRAC16(0.5), d))));
    aux16 = add(aux16, negate(extract_h(L_mult(FRAC16(0.5), b))));
    L2_32 = L_add(L_mult(aux16, aux16), L2_32);
    L2_32 = L_add(L_mult(Zt1, Zt1), L2_32);
    L[1] = mfr32Sqrt(L2_32);
    /* L3 = sqrt((Xt2 + d/(sqrt(3)) + b/(2*sqrt(3)))^2 + (Yt2 - b/2)^2 + Zt2^2); */
    aux32 = L_add(L_mult(d, FRAC16(0.5773)), L_mult(b, FRAC16(0.2886)));
    aux16 = add(extract_h(aux32), Xt2);
    L3_32 = L_mult(aux16, aux16);
    aux16 = add(Yt2, negate(extract_h(L_mult(FRAC16(0.5), b))));
    L3_32 = L_add(L_mult(aux16, aux16), L3_32);
    L3_32 = L_add(L_mult(Zt2, Zt2), L3_32);
    L[2] = mfr32Sqrt(L3_32);
    /* L4 = sqrt((Xt2 + d/(sqrt(3)) + b/(2*sqrt(3)))^2 + (Yt2 + b/2)^2 + Zt2^2); */
    aux32 = L_add(L_mult(d, FRAC16(0.5773)), L_mult(b, FRAC16(0.2886)));
    aux16 = add(extract_h(aux32), Xt2);
    L4_32 = L_mult(aux16, aux16);
    aux16 = add(Yt2, extract_h(L_mult(FRAC16(0.5), b)));
    L4_32 = L_add(L_mult(aux16, aux16), L4_32);
    L4_32 = L_add(L_mult(Zt2, Zt2), L4_32);
    L[3] = mfr32Sqrt(L4_32);
    /* L5 = sqrt((Xt3 - d/(2*sqrt(3)) + b/(2*sqrt(3)))^2 + (Yt3 + b/2 + d/2)^2 + Zt3^2); */
    aux32 = L_add(L_negate(L_mult(d, FRAC16(0.2886))), L_mult(b, FRAC16(0.2886)));
    aux16 = add(extract_h(aux32), Xt3);
    L5_32 = L_mult(aux16, aux16);
    aux16 = add(Yt3, extract_h(L_mult(FRAC16(0.5), d)));
    aux16 = add(aux16, extract_h(L_mult(FRAC16(0.5), b)));
    L5_32 = L_add(L_mult(aux16, aux16), L5_32);
    L5_32 = L_add(L_mult(Zt3, Zt3), L5_32);
    L[4] = mfr32Sqrt(L5_32);
    /* L6 = sqrt((Xt3 - d/(2*sqrt(3)) - b/sqrt(3))^2 + (Yt3 + d/2)^2 + Zt3^2); */
    aux32 = L_add(L_negate(L_mult(d, FRAC16(0.2886))), L_negate(L_mult(b, FRAC16(0.5773))));
    aux16 = add(extract_h(aux32), Xt3);
    L6_32 = L_mult(aux16, aux16);
    aux16 = add(Yt3, extract_h(L_mult(FRAC16(0.5), d)));
    L6_32 = L_add(L_mult(aux16, aux16), L6_32);
    L6_32 = L_add(L_mult(Zt3, Zt3), L6_32);
    L[5] = mfr32Sqrt(L6_32);
}

/* n poses [px, py, pz mm, alpha, beta, gama pi-fractions] (row-major doubles, validated by the caller:
 * positions fit a Word16, angles in [-1, 1]) -> n x 6 lengths (mm). Positions are truncated toward zero,
 * as the C assignment of a double to the firmware's Frac16 px, py, pz. */
void tp17_ik_batch(const double *poses, long n, int a, int b, int d, int16_t *out)
{
    long i;
    for (i = 0; i < n; i++) {
        const double *q = poses + 6 * i;
        tp17_ik((Frac16)q[0], (Frac16)q[1], (Frac16)q[2], q[3], q[4], q[5], (Frac16)a, (Frac16)b, (Frac16)d, out + 6 * i);
    }
}
