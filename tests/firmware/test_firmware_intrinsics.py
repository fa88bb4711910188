"""The host C intrinsics (fixedpoint/c/dsp56800e.h, .c) against the numpy emulation (fixedpoint.q15),
bit for bit: every edge-case combination and 10^6 random operands per intrinsic; sin/cos on all 65,536
words; and the compiled tp17.C against the Python port (the seed table, random poses, op counts)."""

import os
from itertools import product

import numpy as np
import pytest

from stewart_drake.firmware.host import BATCH_OPS, frac, intrinsic, op_counts_tp17, tp17_leg_lengths_c
from stewart_drake.fixedpoint import q15, scalar, tp17_leg_lengths
from stewart_drake.fixedpoint.tp17 import SEED_DSP_MM, SEED_DSP_POSES
from stewart_drake.system import c_build as build
from tests.firmware.firmware_cache import firmware_cache  # noqa: F401

E16 = [-32768, -32767, -16385, -16384, -2, -1, 0, 1, 2, 16383, 16384, 16385, 32766, 32767]
E32 = [
    -(2**31),
    -(2**31) + 1,
    -(2**30),
    -65536,
    -32769,
    -32768,
    -1,
    0,
    1,
    0x7FFF,
    0x8000,
    65535,
    2**30,
    2**31 - 2,
    2**31 - 1,
]
SHIFTS = [-40, -33, -32, -31, -17, -16, -15, -1, 0, 1, 3, 15, 16, 17, 31, 32, 33, 40]
N = 1_000_000

# operand kinds per intrinsic: w = Word16, L = Word32, n = shift count
KINDS = {
    "add": "ww",
    "sub": "ww",
    "negate": "w",
    "abs_s": "w",
    "mult": "ww",
    "mult_r": "ww",
    "shl": "wn",
    "shr": "wn",
    "L_add": "LL",
    "L_sub": "LL",
    "L_negate": "L",
    "L_abs": "L",
    "L_mult": "ww",
    "L_mac": "Lww",
    "L_msu": "Lww",
    "L_shl": "Ln",
    "L_shr": "Ln",
    "extract_h": "L",
    "extract_l": "L",
    "L_deposit_h": "w",
    "L_deposit_l": "w",
    "round_": "L",
    "mac_r": "Lww",
    "msu_r": "Lww",
    "mfr32Sqrt": "L",
}


def _edge_operands(kinds):
    pools = [{"w": E16, "L": E32, "n": SHIFTS}[k] for k in kinds]
    return [np.array(col, dtype=np.int64) for col in zip(*product(*pools))]


def _random_operands(kinds, rng, n=N):
    out = []
    for k in kinds:
        if k == "w":
            out.append(rng.integers(-32768, 32768, n))
        elif k == "L":
            # half uniform over the 32-bit range, half small (where rounding and products matter)
            out.append(
                np.where(rng.random(n) < 0.5, rng.integers(-(2**31), 2**31, n), rng.integers(-(2**17), 2**17, n))
            )
        else:
            out.append(rng.integers(-40, 41, n))
    return out


def test_batch_table_covers_every_intrinsic():
    assert set(KINDS) | {"div_s", "tfr16SinPIx", "tfr16CosPIx"} == set(BATCH_OPS)


@pytest.mark.parametrize("name", sorted(KINDS))
def test_intrinsic_equals_emulation(name):
    kinds = KINDS[name]
    rng = np.random.default_rng(sum(map(ord, name)))
    for ops in (_edge_operands(kinds), _random_operands(kinds, rng)):
        want = getattr(q15, name)(*ops)
        got = intrinsic(name, *ops)
        bad = np.flatnonzero(got != want)
        assert bad.size == 0, f"{name}{tuple(int(o[bad[0]]) for o in ops)}: C {got[bad[0]]}, emulation {want[bad[0]]}"


def test_div_s_on_its_domain():
    rng = np.random.default_rng(7)
    b = rng.integers(1, 32768, N)
    a = (rng.random(N) * (b + 1)).astype(np.int64)  # 0 <= a <= b
    edges = np.array([(0, 1), (1, 1), (32767, 32767), (0, 32767), (1, 32767), (16384, 32767), (32766, 32767)])
    a = np.r_[a, edges[:, 0]]
    b = np.r_[b, edges[:, 1]]
    assert np.array_equal(intrinsic("div_s", a, b), q15.div_s(a, b))


@pytest.mark.parametrize("name", ["tfr16SinPIx", "tfr16CosPIx"])
def test_sin_cos_on_all_words(name):
    x = np.arange(-32768, 32768)
    want = getattr(q15, name)(x)
    assert np.array_equal(intrinsic(name, x), want)
    # and the independent scalar port of tfr16.c at a spread of words (the emulation's own cross-check)
    xs = x[::97]
    assert np.array_equal(want[::97], [getattr(scalar, name)(int(v)) for v in xs])


def test_frac16_frac32_truncate_and_saturate_like_the_emulation():
    rng = np.random.default_rng(3)
    x = np.r_[
        rng.uniform(-1.2, 1.2, N), [-1.0, 1.0, -1.0 - 2**-16, 1.0 - 2**-16, 0.5, -0.5, 2.0, -2.0, 0.0, -0.0, 0.99999]
    ]
    assert np.array_equal(frac(x, 16), q15.FRAC16(x))
    assert np.array_equal(frac(x, 32), q15.FRAC32(x))


# ------------------------------------------------------------------------------------------------
# tp17.C compiled


def workspace_dsp_poses(n, seed):
    """Firmware poses around the seed platform's workspace (mm, pi-fractions), some with large angles."""
    rng = np.random.default_rng(seed)
    ang = np.where(rng.random((n, 1)) < 0.9, rng.uniform(-0.3, 0.3, (n, 3)), rng.uniform(-1, 1, (n, 3)))
    return np.c_[rng.uniform(-300, 300, (n, 2)), rng.uniform(0, 600, n), ang]


def test_compiled_tp17_reproduces_the_seed_table():
    assert np.array_equal(tp17_leg_lengths_c(SEED_DSP_POSES), SEED_DSP_MM)


def test_compiled_tp17_equals_the_python_port():
    q = workspace_dsp_poses(100_000, 11)
    assert np.array_equal(tp17_leg_lengths_c(q), tp17_leg_lengths(q))


def test_compiled_tp17_counts_the_cycle_models_operations():
    # the instrumented build counts each intrinsic called in one pass; the cycle model's counts come
    # from the independent scalar port (fixedpoint.scalar.tp17_op_counts)
    c = op_counts_tp17()
    assert c == scalar.tp17_op_counts()
    assert c["mfr32Sqrt"] == 6 and c["FRAC16"] == 6


def test_cache_is_outside_the_source_tree_and_reused(firmware_cache):  # noqa: F811 (the fixture)
    p1 = build.build(build.library_sources("dsp56800e.c", "dsp_batch.c"))
    assert p1.parent == firmware_cache and p1.exists()
    mtime = p1.stat().st_mtime_ns
    assert build.build(build.library_sources("dsp56800e.c", "dsp_batch.c")) == p1
    assert p1.stat().st_mtime_ns == mtime  # not rebuilt
    # another flag set is another entry
    p2 = build.build(build.library_sources("dsp56800e.c", "dsp_batch.c"), defines=("DSP_COUNT_OPS",))
    assert p2 != p1
    src = os.path.dirname(build.C_DIR)
    assert not str(p1).startswith(src)


def test_zig_cc_build_agrees_when_available():
    zig = build.zig_compiler()
    if zig is None:
        pytest.skip("the ziglang wheel is not installed")
    x = np.arange(-32768, 32768)
    assert np.array_equal(intrinsic("tfr16CosPIx", x, compiler=zig), q15.tfr16CosPIx(x))
    q = workspace_dsp_poses(2000, 4)
    assert np.array_equal(tp17_leg_lengths_c(q, compiler=zig), tp17_leg_lengths(q))
