"""The DSP IK port (tp17.C), the generic fixed-point IK, the cycle model and ``stewart-drake dsp-ik``."""

import json
import re

import numpy as np
import pytest

from stewart_drake.cli import main
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.rotations import rotation_matrix
from stewart_drake.core.sampling import random_poses
from stewart_drake.errors import SHAPE, DspPoseError, FixedPointError
from stewart_drake.fixedpoint import (
    CYCLE_TABLE,
    ERROR_STAGES,
    QFormat,
    SaturationCounter,
    dsp_poses_from_si,
    dsp_poses_to_si,
    estimate_cycles,
    fixed_point_leg_lengths,
    fixed_point_rotation,
    ik_latency_s,
    scalar,
    tp17_cycles,
    tp17_error_stages,
    tp17_leg_lengths,
    tp17_trace,
)
from stewart_drake.fixedpoint.tp17 import SEED_DSP_MM, SEED_DSP_POSES


def random_dsp_poses(n, seed):
    rng = np.random.default_rng(seed)
    return np.c_[rng.integers(-150, 151, (n, 2)), rng.integers(0, 400, n), rng.uniform(-0.3, 0.3, (n, 3))]


def test_seed_table_dsp_block_reproduced_exactly():
    # Done-when asks for ±1 mm; the emulation gives every one of the 24 values exactly.
    assert np.array_equal(tp17_leg_lengths(SEED_DSP_POSES), SEED_DSP_MM)


def test_scalar_port_equals_vectorised_port():
    q = random_dsp_poses(3000, 5)
    vec = tp17_leg_lengths(q)
    sca = np.array([scalar.tp17_loop(*p) for p in q.tolist()])
    assert np.array_equal(vec, sca)


def test_chunked_batch_equals_single_pass(monkeypatch):
    from stewart_drake.fixedpoint import tp17

    q = random_dsp_poses(5000, 6).reshape(50, 100, 6)
    whole = tp17_leg_lengths(q)
    monkeypatch.setattr(tp17, "CHUNK", 777)
    assert whole.shape == (50, 100, 6) and np.array_equal(tp17_leg_lengths(q), whole)
    assert np.array_equal(tp17_leg_lengths(q[3, 4]), whole[3, 4])  # a single pose: same bits


def test_trace_matrix_is_the_rotation():
    q = random_dsp_poses(200, 7)
    tr = tp17_trace(q)
    R = rotation_matrix(q[:, 3:] * np.pi, "utn")
    # each entry: library sin/cos (< 8 LSB) and up to three truncating products: well under 2e-3
    assert np.abs(tr.R / 32768 - R).max() < 2e-3
    assert tr.top_T.tolist() == [[176, 306, 0], [-354, 0, 0], [176, -306, 0]]  # a = 612, FRAC16 constants


def test_dsp_within_6mm_of_float_ik_over_a_workspace_sample():
    # positions are whole mm (as the firmware stores them); the float IK is the exact platform
    p = load_preset("utn-kinematic")
    q = random_dsp_poses(20000, 8)
    dsp = tp17_leg_lengths(q)
    ref = leg_lengths(p, dsp_poses_to_si(q)) * 1e3
    # bound from the error budget: a = 612 (< 0.4), anchor words (< 1.7: FRAC16 and extract_h of the
    # anchors), R·anchor truncation (two floors of < 1 mm per component: |e| < 2·sqrt(3)), sqrt
    # rounding (0.5), trig and matrix words (< 0.3): 6.3 mm; the worst seen here is 5.05 mm
    e = np.abs(dsp - ref)
    assert e.max() < 6.3 and np.median(e) < 2.0


def test_error_stages_sum_to_the_total_and_trig_is_small():
    r = tp17_error_stages(SEED_DSP_POSES)
    total = sum(r["stages"].values())
    np.testing.assert_allclose(total, r["dsp"] - r["float"], atol=1e-9)
    assert list(r["stages"]) == [name for name, _ in ERROR_STAGES]
    assert np.array_equal(r["dsp"], SEED_DSP_MM)
    p = load_preset("utn-kinematic")
    np.testing.assert_allclose(r["float"], leg_lengths(p, dsp_poses_to_si(SEED_DSP_POSES)) * 1e3, atol=1e-9)
    # the seed blames sine/cosine precision; on its own table that stage is below 0.05 mm
    assert np.abs(r["stages"]["sin/cos library"]).max() < 0.05
    assert np.abs(r["stages"]["anchor words"]).max() > 1.0


def test_saturation_counter_through_the_port():
    # 2 (32700^2 + ~5000^2) > 2^31: the sum of squares saturates in L_add for the second pose
    q = np.array([[0, 0, 100, 0, 0, 0], [5000, 0, 32700, 0, 0, 0]])
    with SaturationCounter(shape=(2,)) as sat:
        tp17_leg_lengths(q)
    assert sat.mask.tolist() == [False, True] and sat.counts["L_add"] > 0


def test_pose_validation_messages():
    with pytest.raises(
        DspPoseError, match=re.escape(DspPoseError.ANGLES.format(name="pose 1", values=[1.5, 0.0, 0.0]))
    ):
        tp17_leg_lengths([[0, 0, 100, 0, 0, 0], [0, 0, 100, 1.5, 0, 0]])
    with pytest.raises(
        DspPoseError, match=re.escape(DspPoseError.POSITION.format(name="pose", values=[0.0, 0.0, 40000.0]))
    ):
        tp17_leg_lengths([0, 0, 40000, 0, 0, 0])
    with pytest.raises(DspPoseError, match=re.escape(SHAPE.format(name="DSP poses", shape="(..., 6)", got="(3,)"))):
        tp17_leg_lengths([0, 0, 100])


def test_si_round_trip():
    q = np.array([0.0105, -0.02, 0.13, 0.3, -0.2, 0.1])
    d = dsp_poses_from_si(q)
    np.testing.assert_allclose(d, [10.5, -20, 130, 0.3 / np.pi, -0.2 / np.pi, 0.1 / np.pi])
    np.testing.assert_allclose(dsp_poses_to_si(d), [0.010, -0.02, 0.13, 0.3, -0.2, 0.1])  # mm truncated


# ------------------------------------------------------------------------------------------------
# generic fixed-point IK


@pytest.mark.parametrize("convention", ["utn", "zyx"])
def test_generic_rotation_matches_float(convention):
    a = np.random.default_rng(1).uniform(-1.0, 1.0, (500, 3))
    R31 = fixed_point_rotation(a, QFormat(word_bits=31), convention) / 2**30
    # 31-bit words: every entry within a few 2^-30 of the float matrix
    assert np.abs(R31 - rotation_matrix(a, convention)).max() < 1e-8


def test_generic_error_shrinks_with_word_length(preset):
    q = random_poses(preset, 2000, seed=2)
    ref = leg_lengths(preset, q)
    reach = np.abs(np.r_[preset.base_anchors.ravel(), preset.top_anchors.ravel()]).max() + ref.max()
    errs = []
    for w in (12, 16, 20, 24):
        lsb = 2.0 ** np.ceil(np.log2(reach)) / 2 ** (w - 1)
        errs.append(np.abs(fixed_point_leg_lengths(preset, q, QFormat(w, lsb)) - ref).max() / lsb)
    # in LSB of each format the error stays a few LSB (products truncated, roots rounded)
    assert max(errs) < 8
    lengths = [e * 2.0 ** -(w - 1) for e, w in zip(errs, (12, 16, 20, 24))]
    assert all(a > b for a, b in zip(lengths, lengths[1:]))


def test_generic_16bit_mm_close_to_the_dsp():
    # the generic recipe at the DSP's format (16 bits, 1 mm, tfr16 trig), on the firmware geometry
    p = load_preset("utn-kinematic")
    q = random_dsp_poses(3000, 9)
    gen = fixed_point_leg_lengths(p, dsp_poses_to_si(q), QFormat(16, 1e-3, "tfr16")) * 1e3
    assert np.abs(gen - tp17_leg_lengths(q)).max() <= 5  # different constants/rounding, same arithmetic


def test_generic_qformat_validation():
    with pytest.raises(FixedPointError, match=re.escape(FixedPointError.WORD_BITS.format(value=40))):
        QFormat(word_bits=40)
    with pytest.raises(FixedPointError, match=re.escape(FixedPointError.TFR16_BITS.format(value=20))):
        QFormat(word_bits=20, trig="tfr16")
    p = load_preset("utn-kinematic")
    with pytest.raises(FixedPointError, match="does not fit a 10-bit word"):  # FixedPointError.LENGTH_WORD
        fixed_point_leg_lengths(p, p.home_pose(), QFormat(10, 1e-3))


# ------------------------------------------------------------------------------------------------
# cycle model


def test_op_counts_match_the_listing():
    c = scalar.tp17_op_counts()
    # six sqrt, three sin + three cos, six run-time FRAC16 of the double angles
    assert c["mfr32Sqrt"] == 6 and c["tfr16SinPIx"] == 3 and c["tfr16CosPIx"] == 3 and c["FRAC16"] == 6
    # 9 products x 3 joints for Xt (27) + 13 for the matrix + 6 legs x (3 squares + 2 offset products
    # + 1 or 2 for the y half-sides): 81 L_mult in total
    assert c["L_mult"] == 81


def test_cycle_estimate():
    e = tp17_cycles()
    assert e.cycles == sum(c for _, c in e.breakdown.values())
    assert 40 < e.microseconds < 80 and ik_latency_s() == pytest.approx(e.seconds)
    # doubling the clock halves the latency; a custom table is honoured
    assert ik_latency_s(clock_hz=120e6) == pytest.approx(e.seconds / 2)
    cheap = dict(CYCLE_TABLE, mfr32Sqrt=50.0)
    assert tp17_cycles(cheap).cycles == pytest.approx(e.cycles - 6 * 100)
    with pytest.raises(FixedPointError, match=re.escape(FixedPointError.NO_CYCLES.format(op="fft"))):
        estimate_cycles({"fft": 1})


# ------------------------------------------------------------------------------------------------
# CLI


def test_cli_dsp_ik_json(capsys):
    rc = main(["dsp-ik", "--pose", "10", "10", "140", "36", "0", "18", "--angle-unit", "deg", "--json"])
    d = json.loads(capsys.readouterr().out)
    assert rc == 0 and d["dsp_lengths_mm"] == SEED_DSP_MM[3].tolist()
    np.testing.assert_allclose(d["float_lengths_mm"], [638.659, 523.069, 546.870, 392.446, 610.997, 322.617], atol=1e-3)
    assert d["pose"]["angle_words"] == [6553, 0, 3276] and d["saturations"] == {}


def test_cli_dsp_ik_pi_default_and_table(capsys):
    rc = main(["dsp-ik", "--pose", "0", "0", "120", "0.1", "0", "0"])
    out = capsys.readouterr().out
    assert rc == 0 and "   1      504" in out and "   6      458" in out


def test_cli_dsp_ik_bad_angle(capsys):
    rc = main(["dsp-ik", "--pose", "0", "0", "120", "4", "0", "0", "--angle-unit", "rad"])
    assert rc == 2 and "angle A = 4 rad is beyond ±180°" in capsys.readouterr().err
