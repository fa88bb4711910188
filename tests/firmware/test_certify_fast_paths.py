"""The certificate's fast paths give the same bits as the plain ones: the outward rounding by bit arithmetic on
large arrays is ``np.nextafter`` exactly; the six legs evaluated at once (large batches) give the words, flags
and error enclosures of the same cells evaluated a few at a time (small batches, ``np.nextafter``); and the
integer-only words at single poses (``points.point_words``: the samples and the witness search) are those of
``evaluate`` on one-pose cells, clamps included."""

from __future__ import annotations

import importlib
import warnings

import numpy as np
import pytest

from stewart_drake.core.geometry import load_preset
from stewart_drake.fixedpoint.generic import QFormat

intervals = importlib.import_module("stewart_drake.firmware.certify.intervals")
recipe = importlib.import_module("stewart_drake.firmware.certify.recipe")
box_mod = importlib.import_module("stewart_drake.firmware.certify.box")
points = importlib.import_module("stewart_drake.firmware.certify.points")

SPECIAL = [0.0, -0.0, np.inf, -np.inf, np.nan, 5e-324, -5e-324, 2.0**-1022, -(2.0**-1022), 1.0, -1.0, 0.5, -2.0]
SPECIAL += [np.finfo(float).max, -np.finfo(float).max, 1e-310, -1e-310]


def _bits(x):
    return np.ascontiguousarray(x, dtype=np.float64).view(np.int64)


def test_bit_rounding_is_nextafter_on_every_class_of_float():
    rng = np.random.default_rng(0)
    patterns = rng.integers(np.iinfo(np.int64).min, np.iinfo(np.int64).max, 20_000, dtype=np.int64).view(np.float64)
    x = np.r_[SPECIAL * 100, patterns, rng.standard_normal(5_000) * 10.0 ** rng.integers(-300, 300, 5_000)]
    assert x.size >= intervals._BITS_FROM  # the bit path, not nextafter itself
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # nextafter warns on overflow to inf
        for fast, direction in ((intervals.down, -np.inf), (intervals.up, np.inf)):
            ref, got = np.nextafter(x, direction), fast(x)
            nan = np.isnan(ref)
            assert np.array_equal(nan, np.isnan(got))
            assert np.array_equal(_bits(ref)[~nan], _bits(got)[~nan])


@pytest.mark.parametrize("special", [None, *SPECIAL])
def test_bit_rounding_of_finite_values_with_one_special_class(special):
    """Finite non-zero values alone take the fast path (no special case checked element by element); one
    special value among them (±0, ±inf, NaN, subnormals, extremes) must still round as nextafter does."""
    rng = np.random.default_rng(1)
    x = rng.standard_normal(4_000) * 10.0 ** rng.integers(-300, 300, 4_000)
    if special is not None:
        x[1234] = special
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for fast, direction in ((intervals.down, -np.inf), (intervals.up, np.inf)):
            ref, got = np.nextafter(x, direction), fast(x)
            nan = np.isnan(ref)
            assert np.array_equal(nan, np.isnan(got))
            assert np.array_equal(_bits(ref)[~nan], _bits(got)[~nan])


def test_range_table_positions_serve_every_table_of_its_size():
    """One ``positions`` (the angle words' runs) gives each table's own exact min and max, at run lengths of
    every power of two and between (the level choice), as slicing the values does."""
    rng = np.random.default_rng(7)
    values = [rng.integers(-(2**20), 2**20, 1000) for _ in range(3)]
    tables = [intervals.RangeTable(v, offset=-500) for v in values]
    a = rng.integers(-500, 500, 400)
    n = np.r_[1 << rng.integers(0, 9, 200), rng.integers(1, 500, 200)]
    b = np.minimum(a + n - 1, 499)
    pos = tables[0].positions(a, b)
    for v, t in zip(values, tables, strict=True):
        mn, mx = t.min_at(pos), t.max_at(pos)
        assert mn.dtype == mx.dtype == np.int64
        assert all(mn[k] == v[a[k] + 500 : b[k] + 501].min() for k in range(a.size))
        assert all(mx[k] == v[a[k] + 500 : b[k] + 501].max() for k in range(a.size))


@pytest.mark.parametrize(
    ("name", "fmt"),
    [("utn-kinematic", QFormat(16, 1e-3, "tfr16")), ("utn-dynamic", QFormat(16, 2e-5, "tfr16"))],
)  # utn's y offsets: 4 legs of 6 non-zero (both branches of the leg term); 20 µm saturates
def test_a_large_batch_gives_the_bits_of_small_batches(name, fmt):
    p = load_preset(name)
    model = recipe.Model.build(p, fmt)
    lo, hi = box_mod.workspace_box(p).words(fmt)
    rng = np.random.default_rng(3)
    n = 400  # 6 × 400 leg entries: above the bit path's threshold in the leg arrays
    a = lo + (rng.random((n, 6)) * (hi - lo)).astype(np.int64)
    b = np.minimum(a + (rng.random((n, 6)) * 3000).astype(np.int64), hi)
    big = recipe.evaluate(model, a, b)
    assert 6 * n >= intervals._BITS_FROM
    small = [recipe.evaluate(model, a[k : k + 8], b[k : k + 8]) for k in range(0, 48, 8)]  # 48 < threshold
    for key in ("pre_lo", "pre_hi", "possible", "certain", "err_lo", "err_hi"):
        got = getattr(big, key)[:48]
        ref = np.concatenate([getattr(s, key) for s in small])
        if got.dtype == np.float64:
            assert np.array_equal(_bits(got), _bits(ref)), key
        else:
            assert np.array_equal(got, ref), key
    if fmt.length_lsb == 2e-5:
        assert big.possible.any()  # the saturating format exercises the clamp flags


@pytest.mark.parametrize(
    ("name", "fmt"),
    [
        ("utn-kinematic", QFormat(16, 1e-3, "tfr16")),
        ("utn-kinematic", QFormat(14, 9e-5, "exact")),  # the simulation-only choice: overflows at some poses
        ("utn-dynamic", QFormat(16, 2e-5, "tfr16")),  # saturates almost everywhere
        ("gonzalez-dutra-2009", QFormat(12, 1e-3, "exact")),
    ],
)
def test_point_words_are_evaluate_on_one_pose_cells(name, fmt):
    p = load_preset(name)
    model = recipe.Model.build(p, fmt)
    lo, hi = box_mod.workspace_box(p).words(fmt)
    rng = np.random.default_rng(4)
    w = lo + np.floor(rng.random((1500, 6)) * (hi - lo + 1)).astype(np.int64)
    w = np.r_[w, [[hi[k] if (c >> k) & 1 else lo[k] for k in range(6)] for c in range(64)]]  # the corners
    ref, got = recipe.evaluate(model, w, w), points.point_words(model, w)
    for key in ("pre_lo", "pre_hi", "possible", "certain"):
        assert np.array_equal(getattr(got, key), getattr(ref, key)), key
    arith = np.array([n not in recipe.BENIGN for n in recipe.word_names()])
    if fmt.length_lsb < 1e-4:
        assert (ref.possible & arith).any()  # arithmetic clamps are exercised, not only the benign trig ones


def test_fmul_in_place_is_the_four_corner_formula():
    """``fmul`` reuses its products' buffers; its ends are still down(min of the four corner products) and
    up(max), operand order included (signed zeros, infinities, 0 × inf = NaN), on large and small arrays."""
    rng = np.random.default_rng(8)
    for n in (3000, 40):
        a0 = np.r_[rng.standard_normal(n - len(SPECIAL)), SPECIAL]
        b0 = np.r_[SPECIAL, rng.standard_normal(n - len(SPECIAL))]
        a, b = (a0, a0 + np.abs(rng.standard_normal(n))), (b0, np.where(rng.random(n) < 0.2, b0, b0 + 1.0))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            p = (a[0] * b[0], a[0] * b[1], a[1] * b[0], a[1] * b[1])
            ref = (
                np.nextafter(np.minimum(np.minimum(p[0], p[1]), np.minimum(p[2], p[3])), -np.inf),
                np.nextafter(np.maximum(np.maximum(p[0], p[1]), np.maximum(p[2], p[3])), np.inf),
            )
            got = intervals.fmul(a, b)
        for r, g in zip(ref, got, strict=True):
            nan = np.isnan(r)
            assert np.array_equal(nan, np.isnan(g)) and np.array_equal(_bits(r)[~nan], _bits(g)[~nan])
