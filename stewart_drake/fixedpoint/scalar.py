"""A second, independent emulation of the intrinsics and of ``tp17.C``: plain Python integers, one
scalar at a time, written straight from the library sources (``tfr16.c``, the rtlib ``mfr32Sqrt``
bit search) rather than from :mod:`.q15`.

It exists for three reasons: the tests compare it with the vectorised :mod:`.q15`/:mod:`.tp17` on
many random inputs (two implementations agreeing bit for bit); the benchmark measures it as "the
scalar emulation"; and, with ``count_ops=True``, it counts the intrinsics one evaluation of the
firmware's loop body executes, which :mod:`.cycles` turns into cycles.
"""

from __future__ import annotations

from collections import Counter

from stewart_drake.errors import FixedPointError

MIN16, MAX16 = -32768, 32767
MIN32, MAX32 = -(2**31), 2**31 - 1

OPS: Counter = Counter()
_COUNTING = [False]


def _c(name: str) -> None:
    if _COUNTING[0]:
        OPS[name] += 1


def _s16(x: int) -> int:
    return MIN16 if x < MIN16 else MAX16 if x > MAX16 else x


def _s32(x: int) -> int:
    return MIN32 if x < MIN32 else MAX32 if x > MAX32 else x


def FRAC16(x: float) -> int:
    _c("FRAC16")
    if x >= 1.0:
        return MAX16
    if x < -1.0:
        return MIN16
    return int(x * 32768.0)  # int() truncates toward zero, like the C cast


def add(a, b):
    _c("add")
    return _s16(a + b)


def sub(a, b):
    _c("sub")
    return _s16(a - b)


def negate(a):
    _c("negate")
    return _s16(-a)


def abs_s(a):
    _c("abs_s")
    return _s16(abs(a))


def mult(a, b):
    _c("mult")
    return _s16((a * b) >> 15)


def mult_r(a, b):
    _c("mult_r")
    return _s16((a * b + 0x4000) >> 15)


def shl(a, n):
    _c("shl")
    if n < 0:
        return a >> min(-n, 15)
    return _s16(a << min(n, 16))


def shr(a, n):
    _c("shr")
    if n < 0:
        return _s16(a << min(-n, 16))
    return a >> min(n, 15)


def L_add(a, b):
    _c("L_add")
    return _s32(a + b)


def L_sub(a, b):
    _c("L_sub")
    return _s32(a - b)


def L_negate(a):
    _c("L_negate")
    return _s32(-a)


def L_abs(a):
    _c("L_abs")
    return _s32(abs(a))


def L_mult(a, b):
    _c("L_mult")
    return _s32(2 * a * b)


def L_mac(acc, a, b):
    return L_add(acc, L_mult(a, b))


def L_msu(acc, a, b):
    return L_sub(acc, L_mult(a, b))


def L_shl(a, n):
    _c("L_shl")
    if n < 0:
        return a >> min(-n, 31)
    return _s32(a << min(n, 32))


def L_shr(a, n):
    _c("L_shr")
    if n < 0:
        return _s32(a << min(-n, 32))
    return a >> min(n, 31)


def extract_h(L):
    _c("extract_h")
    return L >> 16


def extract_l(L):
    _c("extract_l")
    return ((L & 0xFFFF) ^ 0x8000) - 0x8000


def L_deposit_h(a):
    _c("L_deposit_h")
    return a << 16


def L_deposit_l(a):
    _c("L_deposit_l")
    return a


def round_(L):
    _c("round")
    return _s32(L + 0x8000) >> 16


def mac_r(acc, a, b):
    return round_(L_mac(acc, a, b))


def msu_r(acc, a, b):
    return round_(L_msu(acc, a, b))


def div_s(a, b):
    _c("div_s")
    if not (0 <= a <= b and b > 0):
        raise FixedPointError(FixedPointError.DIV_S.format(a=a, b=b))
    if a == b:
        return MAX16
    q = 0
    for _ in range(15):  # ETSI restoring division
        q <<= 1
        a <<= 1
        if a >= b:
            a -= b
            q += 1
    return q


def mfr32Sqrt(L):
    """The rtlib assembly: 15 bit-trial steps with ``mpy`` (2y^2 in a 36-bit accumulator, no
    saturation), then the nearer of y and y + 1 (y + 1 saturated as in ``mfr32SqrtC``)."""
    _c("mfr32Sqrt")
    y = 0
    for k in range(14, -1, -1):
        y |= 1 << k
        if 2 * y * y > L:
            y &= ~(1 << k)
    yr = min(y + 1, MAX16)
    return yr if abs(2 * yr * yr - L) < abs(2 * y * y - L) else y


SINE_COEFS = (
    0.39269908169872,
    -0.64596409750625,
    0.31877050498467,
    -0.07446482317004,
    0.01026823582639,
    -0.00092130386821,
    0.00005828785072,
)
_SC = [int(c * 32768.0) for c in SINE_COEFS]  # FRAC16 of the tfr16.c table (compile-time)


def tfr16SinPIx(x):
    """``tfr16.c`` line by line."""
    _c("tfr16SinPIx")
    sign = 0
    if x < 0:
        sign = 1
        x = _s16(-x)
    if x > 16384:  # FRAC16(0.5)
        x = _s16(MAX16 - x)  # sub(FRAC16(1), x)
    z = _s16((x * x + 0x4000) >> 15)  # mult_r
    t = _s32(_s32((_SC[5] << 16) + _s32(2 * z * _SC[6])) + 0x8000) >> 16  # mac_r(L_deposit_h(c5), z, c6)
    for i in range(4, -1, -1):
        t = _s32(_s32((_SC[i] << 16) + _s32(2 * t * z)) + 0x8000) >> 16
    acc = _s32(_s32(2 * t * x) * 8)  # L_shl(L_mult(t, x), 3)
    z = _s32(acc + 0x8000) >> 16  # round
    return _s16(-z) if sign else z


def tfr16CosPIx(x):
    """``tfr16.c`` line by line: cos(pi x) = sin(pi (0.5 - x)), folded."""
    _c("tfr16CosPIx")
    sign = 0
    if x < 0:
        x = _s16(-x)
    if x > 16384:
        x = _s16(MAX16 - x)
        sign = 1
    x = _s16(16384 - x)
    if sign:
        x = _s16(x + 1)
    was = _COUNTING[0]
    _COUNTING[0] = False  # the inner call is part of CosPIx's cost
    try:
        z = tfr16SinPIx(x)
    finally:
        _COUNTING[0] = was
    return _s16(-z) if sign else z


# ------------------------------------------------------------------------------------------------
# tp17.C, line by line (the Yt1 and co32 lines are garbled in the seed's print; restored by symmetry)


def tp17_constants(a=612, b=925, d=150):
    """The words computed once before the firmware's ``for(;;)`` loop: the plate anchors xt*, yt*."""
    xt1 = extract_h(L_mult(FRAC16(0.2886), a))
    yt1 = extract_h(L_mult(FRAC16(0.5), a))
    xt2 = extract_h(L_mult(FRAC16(-0.5773), a))
    yt2 = 0
    xt3 = extract_h(L_mult(FRAC16(0.2886), a))
    yt3 = extract_h(L_mult(FRAC16(-0.5), a))
    return (xt1, yt1, 0), (xt2, yt2, 0), (xt3, yt3, 0)


def tp17_loop(px, py, pz, alpha, beta, gama, a=612, b=925, d=150, consts=None):
    """One pass of the loop body: six leg lengths (integer mm). px, py, pz are Word16 mm; the angles
    are the C ``double`` fractions of pi."""
    (xt1, yt1, zt1), (xt2, yt2, zt2), (xt3, yt3, zt3) = consts or tp17_constants(a, b, d)
    cosA = tfr16CosPIx(FRAC16(alpha))
    cosB = tfr16CosPIx(FRAC16(beta))
    cosG = tfr16CosPIx(FRAC16(gama))
    sinA = tfr16SinPIx(FRAC16(alpha))
    sinB = tfr16SinPIx(FRAC16(beta))
    sinG = tfr16SinPIx(FRAC16(gama))
    co11 = add(extract_h(L_mult(cosB, cosG)), extract_h(L_mult(extract_h(L_mult(sinA, sinB)), sinG)))
    co12 = add(extract_h(L_mult(negate(cosB), sinG)), extract_h(L_mult(extract_h(L_mult(sinA, sinB)), cosG)))
    co13 = extract_h(L_mult(cosA, sinB))
    co14 = px
    co21 = extract_h(L_mult(cosA, sinG))
    co22 = extract_h(L_mult(cosA, cosG))
    co23 = negate(sinA)
    co24 = py
    co31 = add(extract_h(L_mult(negate(sinB), cosG)), extract_h(L_mult(extract_h(L_mult(sinA, cosB)), sinG)))
    co32 = add(extract_h(L_mult(sinB, sinG)), extract_h(L_mult(extract_h(L_mult(sinA, cosB)), cosG)))
    co33 = extract_h(L_mult(cosA, cosB))
    co34 = pz

    def top(x, y, z):
        X = add(add(add(extract_h(L_mult(co11, x)), extract_h(L_mult(co12, y))), extract_h(L_mult(co13, z))), co14)
        Y = add(add(add(extract_h(L_mult(co21, x)), extract_h(L_mult(co22, y))), extract_h(L_mult(co23, z))), co24)
        Z = add(add(add(extract_h(L_mult(co31, x)), extract_h(L_mult(co32, y))), extract_h(L_mult(co33, z))), co34)
        return X, Y, Z

    Xt1, Yt1, Zt1 = top(xt1, yt1, zt1)
    Xt2, Yt2, Zt2 = top(xt2, yt2, zt2)
    Xt3, Yt3, Zt3 = top(xt3, yt3, zt3)

    def length(aux32, X, ys, Y, Z):
        aux16 = add(extract_h(aux32), X)
        L32 = L_mult(aux16, aux16)
        aux16 = Y
        for term in ys:
            aux16 = add(aux16, term())
        L32 = L_add(L_mult(aux16, aux16), L32)
        L32 = L_add(L_mult(Z, Z), L32)
        return mfr32Sqrt(L32)

    h, t, half = FRAC16(0.2886), FRAC16(0.5773), FRAC16(0.5)
    L1 = length(
        L_add(L_negate(L_mult(d, h)), L_negate(L_mult(b, t))),
        Xt1,
        [lambda: negate(extract_h(L_mult(half, d)))],
        Yt1,
        Zt1,
    )
    L2 = length(
        L_add(L_negate(L_mult(d, h)), L_mult(b, h)),
        Xt1,
        [lambda: negate(extract_h(L_mult(half, d))), lambda: negate(extract_h(L_mult(half, b)))],
        Yt1,
        Zt1,
    )
    L3 = length(L_add(L_mult(d, t), L_mult(b, h)), Xt2, [lambda: negate(extract_h(L_mult(half, b)))], Yt2, Zt2)
    L4 = length(L_add(L_mult(d, t), L_mult(b, h)), Xt2, [lambda: extract_h(L_mult(half, b))], Yt2, Zt2)
    L5 = length(
        L_add(L_negate(L_mult(d, h)), L_mult(b, h)),
        Xt3,
        [lambda: extract_h(L_mult(half, d)), lambda: extract_h(L_mult(half, b))],
        Yt3,
        Zt3,
    )
    L6 = length(
        L_add(L_negate(L_mult(d, h)), L_negate(L_mult(b, t))), Xt3, [lambda: extract_h(L_mult(half, d))], Yt3, Zt3
    )
    return [L1, L2, L3, L4, L5, L6]


def tp17_op_counts(a=612, b=925, d=150) -> Counter:
    """Intrinsic calls in one pass of the loop body (the constants FRAC16(0.2886) etc. are folded by
    the compiler and not counted; FRAC16 of the ``double`` angles is a run-time conversion and is)."""
    consts = tp17_constants(a, b, d)
    OPS.clear()
    _COUNTING[0] = True
    try:
        _tp17_counted(consts, a, b, d)
    finally:
        _COUNTING[0] = False
    counts = Counter(OPS)
    OPS.clear()
    return counts


def _tp17_counted(consts, a, b, d):
    # Compile-time constants: FRAC16 with a literal argument is folded; count only the six run-time ones.
    global FRAC16
    runtime = FRAC16

    def folded(x):
        _COUNTING[0] = False
        try:
            return runtime(x)
        finally:
            _COUNTING[0] = True

    lits = {0.2886, 0.5773, 0.5}
    FRAC16 = lambda x: folded(x) if x in lits else runtime(x)  # noqa: E731
    try:
        tp17_loop(0, 0, 100, 0.1, 0.05, 0.02, a, b, d, consts)
    finally:
        FRAC16 = runtime
