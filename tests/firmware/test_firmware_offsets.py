"""The firmware follows the calibration: ``legs.length_offset`` becomes a table of sensor counts added to the
readings in ``sd_tick``, bit-identical with ``control.FixedPointLaw``; a platform without offsets generates
the code it always did."""

from __future__ import annotations

import numpy as np

from stewart_drake.control import FixedPointLaw
from stewart_drake.control.gains import ControllerConfig
from stewart_drake.core.geometry import load_preset
from stewart_drake.firmware.generate import generate, offset_counts
from stewart_drake.firmware.module import TickRunner, compile_generated
from stewart_drake.fixedpoint.generic import pose_words
from tests.firmware.firmware_cache import firmware_cache  # noqa: F401

OFFSETS = [4.2e-4, -1.3e-4, 0.0, 3.05e-4, -4.96e-4, 1e-5]  # m, as a calibration identifies them


def _with_offsets(name="utn-dynamic"):
    p = load_preset(name)
    legs = type(p.legs)(**{**vars(p.legs), "length_offset": OFFSETS})
    return p.replace(legs=legs)


def test_no_offsets_no_table():
    p = load_preset("utn-dynamic")
    text = generate(p, ControllerConfig.for_platform(p)).files["sd_firmware.c"]
    assert "SD_LENGTH_OFFSET" not in text and "int64_t m = measured[i];" in text


def test_offset_table_is_the_offsets_in_counts():
    p = _with_offsets()
    cfg = ControllerConfig.for_platform(p)
    text = generate(p, cfg).files["sd_firmware.c"]
    assert offset_counts(p, cfg).tolist() == [42, -13, 0, 30, -50, 1]  # rounded to the 10 µm count (30.5 -> 30)
    assert "static const int32_t SD_LENGTH_OFFSET[6] = {42, -13, 0, 30, -50, 1};" in text
    assert "int64_t m = (int64_t)measured[i] + SD_LENGTH_OFFSET[i];" in text


def test_tick_with_offsets_equals_the_python_law():
    """sd_tick of the calibrated platform against FixedPointLaw.step on random states and readings: same
    commands and states bit for bit; the offsets really enter (a law without them differs)."""
    p = _with_offsets()
    cfg = ControllerConfig.for_platform(p)
    ctrl = FixedPointLaw(p, cfg)
    plain = FixedPointLaw(load_preset("utn-dynamic"), cfg)
    r = TickRunner(compile_generated(generate(p, cfg)))
    rng = np.random.default_rng(7)
    home = p.home_pose()
    L0 = ctrl.ik_words(home) * 1e-3
    differs = 0
    for _ in range(200):
        ref = home + rng.normal(0, [0.01, 0.01, 0.01, 0.03, 0.03, 0.03])
        reading = L0 - p.length_offset + rng.normal(0, 0.002, 6)
        state = np.r_[
            rng.integers(-(2**28), 2**28, 6),
            np.round(L0 / 1e-5) + rng.integers(-300, 300, 6),
            rng.integers(-3000, 3000, 6),
            ctrl.ik_words(home) + rng.integers(-5, 6, 6),
            rng.integers(-3000, 3000, 6),
        ]
        command, _, new_state, _ = ctrl.step(state.astype(float), ref, reading, None)
        r.set_state(state)
        cmd = r.tick(pose_words(ref, cfg.ik_format), ctrl.quantise(reading), None)
        assert np.array_equal(cmd / 32768.0 * cfg.timing.command_range, command)
        assert np.array_equal(r.state(), new_state.astype(np.int64))
        differs += not np.array_equal(plain.step(state.astype(float), ref, reading, None)[0], command)
    assert differs > 100


def test_sensor_gains_are_refused_by_the_controller_path():
    """legs.length_gain ≠ 1 (calibrate --gains): the generator and both laws refuse it in one line."""
    import pytest

    from stewart_drake.control import FloatLaw
    from stewart_drake.errors import FirmwareError

    p = _with_offsets()
    p = p.replace(legs=type(p.legs)(**{**vars(p.legs), "length_gain": [1.0, 1.0, 1.0005, 1.0, 1.0, 1.0]}))
    cfg = ControllerConfig.for_platform(p)
    for make in (lambda: generate(p, cfg), lambda: FixedPointLaw(p, cfg), lambda: FloatLaw(p, cfg)):
        with pytest.raises(FirmwareError, match=r"legs.length_gain \[1.0, 1.0, 1.0005, 1.0, 1.0, 1.0\] is not 1"):
            make()
