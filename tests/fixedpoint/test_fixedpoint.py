"""The Q15/Q31 intrinsics (stewart_drake.fixedpoint.q15): edge cases pinned one by one, and the
vectorised implementation equal bit for bit to the independent scalar one (fixedpoint.scalar) on
10^5 random inputs per operator, drawn with a bias toward the saturation edges."""

import math
import re

import numpy as np
import pytest

from stewart_drake.errors import FixedPointError
from stewart_drake.fixedpoint import q15
from stewart_drake.fixedpoint import scalar as s
from stewart_drake.fixedpoint.q15 import (
    FRAC16,
    MAX16,
    MAX32,
    MIN16,
    MIN32,
    L_add,
    L_mult,
    L_negate,
    L_shl,
    L_shr,
    L_sub,
    SaturationCounter,
    abs_s,
    add,
    div_s,
    extract_h,
    extract_l,
    mac_r,
    mfr32Sqrt,
    mult,
    mult_r,
    negate,
    round_,
    shl,
    shr,
    sub,
    tfr16CosPIx,
    tfr16SinPIx,
)

N = 100_000


def words16(rng, n):
    """Uniform words with 10 % of them at or next to the extremes (where saturation lives)."""
    x = rng.integers(MIN16, MAX16 + 1, n)
    edge = rng.random(n) < 0.1
    x[edge] = rng.choice([MIN16, MIN16 + 1, -1, 0, 1, MAX16 - 1, MAX16], edge.sum())
    return x


def words32(rng, n):
    x = rng.integers(MIN32, MAX32 + 1, n, dtype=np.int64)
    edge = rng.random(n) < 0.1
    x[edge] = rng.choice([MIN32, MIN32 + 1, -1, 0, 1, MAX32 - 1, MAX32], edge.sum())
    return x


# ------------------------------------------------------------------------------------------------
# Edge cases (values from the ETSI/CodeWarrior definitions)


def test_L_mult_min_times_min_saturates():
    assert L_mult(MIN16, MIN16) == MAX32  # 2 * 2^30 = 2^31 does not fit
    assert L_mult(MIN16, MAX16) == -2 * 32768 * 32767
    assert L_mult(MAX16, MAX16) == 2 * 32767**2


def test_mult_and_mult_r_min_times_min():
    assert mult(MIN16, MIN16) == MAX16 and mult_r(MIN16, MIN16) == MAX16


def test_add_sub_saturate():
    assert add(MAX16, 1) == MAX16 and add(MIN16, -1) == MIN16 and add(20000, 20000) == MAX16
    assert sub(MIN16, 1) == MIN16 and sub(MAX16, -1) == MAX16
    assert L_add(MAX32, 1) == MAX32 and L_sub(MIN32, 1) == MIN32


def test_negate_and_abs_of_min():
    assert negate(MIN16) == MAX16 and abs_s(MIN16) == MAX16 and negate(MAX16) == -MAX16
    assert L_negate(MIN32) == MAX32


def test_extract_h_truncates_toward_minus_infinity():
    assert extract_h(0x0001FFFF) == 1
    assert extract_h(-1) == -1  # floor(-1 / 2^16) = -1, not 0
    assert extract_h(-0x10000) == -1 and extract_h(-0x10001) == -2
    assert extract_l(0x12348765) == 0x8765 - 0x10000  # low word, signed


def test_rounding_ties_go_toward_plus_infinity():
    # two's-complement rounding (OMR R bit set, as the CodeWarrior intrinsics assume)
    assert round_(0x00018000) == 2 and round_(0x00008000) == 1
    assert round_(-0x8000) == 0  # -0.5 LSB rounds up to 0
    assert round_(-0x18000) == -1  # -1.5 LSB rounds up to -1
    assert round_(MAX32) == MAX16  # the +0x8000 saturates first
    assert mult_r(1, 16384) == 1  # 1 * 0.5 = 0.5 LSB -> 1
    assert mult_r(-1, 16384) == 0  # -0.5 LSB -> 0
    assert mult(-1, 16384) == -1  # truncation goes down


def test_shifts():
    assert shl(1, 14) == 16384 and shl(1, 15) == MAX16 and shl(-1, 15) == MIN16 and shl(-2, 15) == MIN16
    assert shl(0x4000, -14) == 1 and shr(-1, 20) == -1 and shr(12345, 20) == 0 and shr(1, -15) == MAX16
    assert L_shl(1, 31) == MAX32 and L_shl(-1, 31) == MIN32 and L_shr(MIN32, 40) == -1 and L_shl(8, -3) == 1


def test_frac16_truncates_toward_zero_and_saturates():
    assert FRAC16(0.2886) == 9456  # 9456.9 truncated: the seed's sqrt(3)/6 is 9459.2 exactly
    assert FRAC16(0.5773) == 18916 and FRAC16(-0.5773) == -18916 and FRAC16(0.1) == 3276
    assert FRAC16(1.0) == MAX16 and FRAC16(-1.0) == MIN16 and FRAC16(5.0) == MAX16 and FRAC16(-3.0) == MIN16
    with pytest.raises(FixedPointError, match=re.escape(FixedPointError.FRAC16_NOT_FINITE.format(value=np.nan))):
        FRAC16(np.nan)


def test_sqrt_edges():
    assert mfr32Sqrt(0) == 0 and mfr32Sqrt(-5) == 0
    assert mfr32Sqrt(MAX32) == MAX16  # sqrt(1 - 2^-31) -> 32767 (Est + 1 saturates)
    assert mfr32Sqrt(L_mult(473, 473)) == 473  # tp17's use: 2 x^2 -> x
    assert mfr32Sqrt(1 << 29) == 16384  # sqrt(0.25) = 0.5
    # nearer of y, y+1 by the residual |2y^2 - L| (not by |sqrt - y|): 2*473^2 = 447458 and
    # 2*474^2 = 449352 are equally far from 448405, and a tie keeps y (the asm's strict blt)
    assert mfr32Sqrt(448406) == 474 and mfr32Sqrt(448405) == 473


def test_sqrt_against_math_isqrt():
    rng = np.random.default_rng(3)
    L = rng.integers(0, MAX32, 20000)
    got = mfr32Sqrt(L)
    for x, y in zip(L[:2000].tolist(), got[:2000].tolist()):
        fl = math.isqrt(x // 2)
        best = min((fl, fl + 1), key=lambda c: (abs(2 * c * c - x), c))  # nearest; ties keep the lower
        assert y == min(best, MAX16), x
    # the squared-residual rule is within 0.5 + 1/(8y) LSB of the true root (y > 1000 here: 1e-3),
    # except above 32767 where the result saturates
    ok = (L < 2 * 32767**2) & (L > 2 * 1000**2)
    np.testing.assert_allclose(got[ok], np.sqrt(L[ok] / 2), rtol=0, atol=0.5 + 1e-3)


def test_sin_cos_edges():
    assert tfr16SinPIx(0) == 0 and tfr16CosPIx(0) == MAX16  # cos 0 = 1.0 saturates to 32767
    assert tfr16SinPIx(16384) == MAX16 and tfr16SinPIx(-16384) == -MAX16 and tfr16CosPIx(16384) == 0
    # cos(-pi) folds to sin(pi (0.5 + 1 LSB)), where the polynomial is 4 LSB short of 1.0
    assert tfr16CosPIx(MIN16) == -32764 and tfr16CosPIx(MAX16) == -32764 and tfr16SinPIx(MIN16) == 0
    # the words tp17 uses for 18°, 27°, 36°
    assert [int(tfr16SinPIx(FRAC16(v))) for v in (0.1, 0.15, 0.2)] == [10122, 14875, 19257]
    assert [int(tfr16CosPIx(FRAC16(v))) for v in (0.1, 0.15, 0.2)] == [31160, 29193, 26510]


def test_sin_cos_accuracy_over_all_inputs():
    x = np.arange(MIN16, MAX16 + 1)
    es = tfr16SinPIx(x) - np.sin(np.pi * x / 32768) * 32768
    ec = tfr16CosPIx(x) - np.cos(np.pi * x / 32768) * 32768
    # a 7-term polynomial with Q15 coefficients and Horner rounding: a few LSB, never more than 8
    assert np.abs(es).max() < 8 and np.abs(ec[x != 0]).max() < 8
    assert np.array_equal(tfr16SinPIx(-x[1:]), -tfr16SinPIx(x[1:]))  # odd (except at -32768)
    assert np.array_equal(tfr16CosPIx(-x[1:]), tfr16CosPIx(x[1:]))  # even


def test_lookup_table_equals_the_polynomial():
    x = np.arange(MIN16, MAX16 + 1)
    assert np.array_equal(tfr16SinPIx(x), q15._sinpix_poly(x))
    assert np.array_equal(tfr16CosPIx(x), q15._cospix_poly(x))


def test_div_s():
    assert div_s(1, 2) == 16384 and div_s(5, 5) == MAX16 and div_s(0, 7) == 0 and div_s(1, 3) == 10922
    with pytest.raises(FixedPointError, match=re.escape(FixedPointError.DIV_S.format(a=3, b=2))):
        div_s(3, 2)


# ------------------------------------------------------------------------------------------------
# Vectorised == scalar (independent implementation), 10^5 inputs per operator

BINARY16 = ["add", "sub", "mult", "mult_r", "L_mult"]
UNARY16 = ["negate", "abs_s", "tfr16SinPIx", "tfr16CosPIx", "L_deposit_h"]
BINARY32 = ["L_add", "L_sub"]
UNARY32 = ["L_negate", "L_abs", "extract_h", "extract_l", "round_", "mfr32Sqrt"]


@pytest.mark.parametrize("name", BINARY16)
def test_vector_equals_scalar_binary16(name):
    rng = np.random.default_rng(11)
    a, b = words16(rng, N), words16(rng, N)
    got = getattr(q15, name)(a, b)
    f = getattr(s, name)
    assert np.array_equal(got, [f(x, y) for x, y in zip(a.tolist(), b.tolist())])
    assert getattr(q15, name)(int(a[7]), int(b[7])) == got[7]  # a scalar gives the same bits


@pytest.mark.parametrize("name", UNARY16)
def test_vector_equals_scalar_unary16(name):
    rng = np.random.default_rng(12)
    a = words16(rng, N)
    got = getattr(q15, name)(a)
    f = getattr(s, name)
    assert np.array_equal(got, [f(x) for x in a.tolist()])


@pytest.mark.parametrize("name", BINARY32)
def test_vector_equals_scalar_binary32(name):
    rng = np.random.default_rng(13)
    a, b = words32(rng, N), words32(rng, N)
    f = getattr(s, name)
    assert np.array_equal(getattr(q15, name)(a, b), [f(x, y) for x, y in zip(a.tolist(), b.tolist())])


@pytest.mark.parametrize("name", UNARY32)
def test_vector_equals_scalar_unary32(name):
    rng = np.random.default_rng(14)
    a = words32(rng, N)
    f = getattr(s, name)
    assert np.array_equal(getattr(q15, name)(a), [f(x) for x in a.tolist()])


@pytest.mark.parametrize("name", ["shl", "shr", "L_shl", "L_shr"])
def test_vector_equals_scalar_shifts(name):
    rng = np.random.default_rng(15)
    a = words32(rng, N) if name.startswith("L_") else words16(rng, N)
    n = rng.integers(-40, 41, N)
    f = getattr(s, name)
    assert np.array_equal(getattr(q15, name)(a, n), [f(x, k) for x, k in zip(a.tolist(), n.tolist())])


def test_mac_r_and_div_s_vector_equals_scalar():
    rng = np.random.default_rng(16)
    acc, a, b = words32(rng, N), words16(rng, N), words16(rng, N)
    assert np.array_equal(mac_r(acc, a, b), [s.mac_r(*t) for t in zip(acc.tolist(), a.tolist(), b.tolist())])
    den = rng.integers(1, MAX16 + 1, 20000)
    num = (rng.random(20000) * (den + 1)).astype(np.int64)
    assert np.array_equal(div_s(num, den), [s.div_s(x, y) for x, y in zip(num.tolist(), den.tolist())])


def test_frac16_vector_equals_scalar():
    rng = np.random.default_rng(17)
    x = rng.uniform(-1.2, 1.2, N)
    assert np.array_equal(FRAC16(x), [s.FRAC16(v) for v in x.tolist()])


# ------------------------------------------------------------------------------------------------
# Saturation counter


def test_saturation_counter_counts_and_maps():
    a = np.array([[MAX16, 0, 1], [MIN16, 5, -5]])
    with SaturationCounter(shape=a.shape) as sat:
        add(a, 1)
        negate(a)
        L_mult(a, a)  # only MIN16 * MIN16 saturates
    assert sat.counts == {"add": 1, "negate": 1, "L_mult": 1} and sat.total == 3
    assert sat.mask.tolist() == [[True, False, False], [True, False, False]]
    add(MAX16, 1)  # outside the block: not counted
    assert sat.total == 3


def test_saturation_counters_nest():
    with SaturationCounter() as outer:
        with SaturationCounter() as inner:
            sub(MIN16, 1)
        add(MAX16, 1)
    assert inner.total == 1 and outer.total == 2


def test_word16_validation_names_the_value():
    assert q15.word16([1, -2]).dtype == np.int64
    with pytest.raises(
        FixedPointError,
        match=re.escape(FixedPointError.RANGE.format(name="gain", value=40000, bits=16, lo=MIN16, hi=MAX16)),
    ):
        q15.word16([1, 40000], "gain")
    with pytest.raises(
        FixedPointError, match=re.escape(FixedPointError.NOT_INTEGER_16.format(name="gain", value=np.float64(1.5)))
    ):
        q15.word16([1.5], "gain")
