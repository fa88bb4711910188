"""Fixed-point arithmetic of the seed's DSP56800E firmware, emulated bit-exactly (plain numpy).

Public API (names are stable; other modules build on them):

Intrinsics — :mod:`stewart_drake.fixedpoint.q15` (vectorised over int64 arrays; see its table for
the exact saturation/truncation/rounding of each)::

    FRAC16 FRAC32 add sub negate abs_s mult mult_r shl shr
    L_add L_sub L_negate L_abs L_mult L_mac L_msu L_shl L_shr
    extract_h extract_l L_deposit_h L_deposit_l round_ mac_r msu_r div_s
    mfr32Sqrt tfr16SinPIx tfr16CosPIx
    sat16 sat32 word16 word32 to_float16 to_float32 MIN16 MAX16 MIN32 MAX32
    SaturationCounter        # with SaturationCounter(shape=S) as sat: ...; sat.counts, sat.mask

  A fixed-point PID, say, is written with these exactly as in C::

      e = sub(ref, meas); acc = L_mac(acc, ki, e); u = round_(L_mac(acc, kp, e))

The DSP's IK — :mod:`.tp17`::

    tp17_leg_lengths(poses_mm_pi, a=612, b=925, d=150, counter=None) -> (..., 6) int64 mm
    tp17_trace(poses_mm_pi) -> Tp17Trace          # every intermediate word
    tp17_error_stages(poses_mm_pi) -> dict        # DSP - float split into ERROR_STAGES (sums exactly)
    dsp_poses_from_si(poses_si) / dsp_poses_to_si(poses_dsp); check_dsp_poses(poses)

  Firmware poses are [px, py, pz in mm, alpha, beta, gamma as fractions of pi] (tp17.C's units).

Generic fixed-point IK for any Platform — :mod:`.generic`::

    QFormat(word_bits=16, length_lsb=1e-3, trig="exact")
    fixed_point_leg_lengths(platform, poses_si, fmt=QFormat(), convention="utn", return_words=False)
        -> (..., 6) metres (integer multiples of length_lsb)
    fixed_point_rotation(angles_rad, fmt, convention) -> (..., 3, 3) Q(word_bits-1) words
    pose_words(poses_si, fmt) -> (..., 6) words; leg_length_words(platform, words, fmt, convention) -> (..., 6)
      (the same IK split at the firmware's interface: the C firmware takes pose words; see ``firmware``)

Cycle model (MC56F8367 at 60 MHz) — :mod:`.cycles`::

    tp17_cycles(table=None, clock_hz=CLOCK_HZ) -> CycleEstimate (.cycles, .seconds, .microseconds, .breakdown)
    ik_latency_s(table=None, clock_hz=CLOCK_HZ) -> float   # latency of one IK evaluation, seconds (~56 µs)
    estimate_cycles(op_counts, table=None) -> CycleEstimate  # for your own operation counts (e.g. a PID)
    CYCLE_TABLE (operation -> cycles per call, documented in cycles.py), CLOCK_HZ = 60e6

A pure-Python scalar emulation of the same intrinsics and of tp17.C (independent code, used by the
tests, the benchmark and the operation count) is in :mod:`.scalar`.
"""

from stewart_drake.fixedpoint.cycles import (
    CLOCK_HZ,
    CYCLE_TABLE,
    CycleEstimate,
    estimate_cycles,
    ik_latency_s,
    tp17_cycles,
)
from stewart_drake.fixedpoint.generic import QFormat, fixed_point_leg_lengths, fixed_point_rotation
from stewart_drake.fixedpoint.q15 import (
    FRAC16,
    FRAC32,
    MAX16,
    MAX32,
    MIN16,
    MIN32,
    L_abs,
    L_add,
    L_deposit_h,
    L_deposit_l,
    L_mac,
    L_msu,
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
    msu_r,
    mult,
    mult_r,
    negate,
    round_,
    sat16,
    sat32,
    shl,
    shr,
    sub,
    tfr16CosPIx,
    tfr16SinPIx,
    to_float16,
    to_float32,
    word16,
    word32,
)
from stewart_drake.fixedpoint.tp17 import (
    ERROR_STAGES,
    TP17_GEOMETRY_MM,
    Tp17Trace,
    check_dsp_poses,
    dsp_poses_from_si,
    dsp_poses_to_si,
    tp17_error_stages,
    tp17_leg_lengths,
    tp17_trace,
)

__all__ = [
    "FRAC16",
    "FRAC32",
    "MAX16",
    "MAX32",
    "MIN16",
    "MIN32",
    "L_abs",
    "L_add",
    "L_deposit_h",
    "L_deposit_l",
    "L_mac",
    "L_msu",
    "L_mult",
    "L_negate",
    "L_shl",
    "L_shr",
    "L_sub",
    "SaturationCounter",
    "abs_s",
    "add",
    "div_s",
    "extract_h",
    "extract_l",
    "mac_r",
    "mfr32Sqrt",
    "msu_r",
    "mult",
    "mult_r",
    "negate",
    "round_",
    "sat16",
    "sat32",
    "shl",
    "shr",
    "sub",
    "tfr16CosPIx",
    "tfr16SinPIx",
    "to_float16",
    "to_float32",
    "word16",
    "word32",
    "TP17_GEOMETRY_MM",
    "Tp17Trace",
    "check_dsp_poses",
    "dsp_poses_from_si",
    "dsp_poses_to_si",
    "tp17_leg_lengths",
    "tp17_trace",
    "ERROR_STAGES",
    "tp17_error_stages",
    "QFormat",
    "fixed_point_leg_lengths",
    "fixed_point_rotation",
    "CLOCK_HZ",
    "CYCLE_TABLE",
    "CycleEstimate",
    "estimate_cycles",
    "ik_latency_s",
    "tp17_cycles",
]
