"""One meaning of "saturation" in the firmware, its emulation, the certificate and the ABI: an overflow of the
arithmetic. The exact trig table stores cos 0 = sin(pi/2) = 1.0 as 2^f - 1 (1.0 is not a Q(f) word); that clamp
is the table's rounding (error 2^-f, within its certified error), so neither ``sd_ik`` nor the emulation counts
it, and a geometric pose returns 0 as docs/firmware-abi.md says."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

from stewart_drake.control import ControllerConfig
from stewart_drake.core.geometry import load_preset
from stewart_drake.firmware.generate import TRACE_AT, generate
from stewart_drake.firmware.module import compile_generated
from stewart_drake.fixedpoint import QFormat, SaturationCounter
from stewart_drake.fixedpoint.generic import leg_length_words, pose_words
from tests.firmware.firmware_cache import firmware_cache  # noqa: F401

needs_cc = pytest.mark.skipif(shutil.which("cc") is None and shutil.which("gcc") is None, reason="no C compiler")


@pytest.mark.parametrize("fmt", [QFormat(16, 1e-3, "exact"), QFormat(16, 1e-4, "exact"), QFormat(12, 1e-2, "exact")])
@needs_cc
def test_home_pose_counts_no_saturation(fmt):
    p = load_preset("utn-kinematic")
    cfg = ControllerConfig.for_platform(p, ik_format=fmt)
    home = np.array([[0.0, 0.0, 0.1, 0.0, 0.0, 0.0]])  # the ABI doc's home pose (m, rad): every cosine is cos 0
    w = pose_words(home, fmt)
    with SaturationCounter() as sat:
        want = leg_length_words(p, w, fmt, cfg.convention)
    got, nsat = compile_generated(generate(p, cfg)).ik(w)
    assert np.array_equal(got, want)
    assert sat.total == 0 and int(nsat[0]) == 0


@needs_cc
def test_the_clamp_still_clamps_and_an_overflow_still_counts():
    """The clamped entry is 2^f - 1 (the word's top), and a pose beyond the word's lengths still counts."""
    fmt = QFormat(16, 1e-3, "exact")
    p = load_preset("utn-kinematic")
    cfg = ControllerConfig.for_platform(p, ik_format=fmt)
    f = fmt.frac_bits
    m = compile_generated(generate(p, cfg))
    w = np.array([[0, 0, 100, 0, 0, 0], [(1 << f) - 1] * 3 + [0, 0, 0]])  # home; then 32.767 m off in x, y, z
    tr = m.ik_trace(w[0])
    # the trace's cosine words (after the three sines) are the clamped table entry for cos 0
    assert list(tr[TRACE_AT["cos"] : TRACE_AT["cos"] + 3]) == [(1 << f) - 1] * 3
    with SaturationCounter() as sat:
        want = leg_length_words(p, w, fmt, cfg.convention)
    got, nsat = m.ik(w)
    assert np.array_equal(got, want)
    assert int(nsat[0]) == 0 and int(nsat[1]) > 0 and int(nsat.sum()) == sat.total
