"""The calibrated platform file: every architecture (6-6, 3-6, 6-3 with leg_base) written and read back
equal, with its offsets and its calibration block."""

from __future__ import annotations

import numpy as np
import pytest

from stewart_drake.calibration.simulate import draw_machine
from stewart_drake.core.geometry import CalibrationRecord, load_platform, load_preset
from stewart_drake.core.platform_file import platform_yaml
from tests.calibration.conftest import ERRORS
from tests.calibration.test_model import _six_three


@pytest.mark.parametrize(
    "make", [lambda: load_preset("gonzalez-dutra-2009"), lambda: load_preset("utn-dynamic"), _six_three]
)
def test_written_platform_reads_back_equal(tmp_path, make):
    nominal = make()
    truth, _ = draw_machine(nominal, ERRORS, np.random.default_rng(3))
    if nominal.name == "gonzalez-dutra-2009":  # sensor gains too (calibrate --gains)
        truth = truth.replace(
            legs=type(truth.legs)(**{**vars(truth.legs), "length_gain": [1.0002, 1, 1, 0.9995, 1, 1]})
        )
    rec = CalibrationRecord(source="m.csv", sha256="ab" * 32, poses=30, parameters=["leg 1 offset"], sigma=[1.5e-6])
    f = tmp_path / "c.yaml"
    f.write_text(platform_yaml(truth, rec, "a header\nof two lines"))
    back = load_platform(f)
    for name in (
        "base_anchors",
        "top_anchors",
        "leg_top",
        "stroke",
        "com",
        "inertia",
        "rotation_centre",
        "length_offset",
    ):
        assert np.array_equal(getattr(back, name), getattr(truth, name)), name
    assert back.mass == truth.mass and back.home_height == truth.home_height and back.name == truth.name
    assert np.any(back.length_offset)
    assert ("leg_base:" in f.read_text()) == (nominal.name == "six-three")
    assert ("length_gain:" in f.read_text()) == (nominal.name == "gonzalez-dutra-2009")
    assert "sigma: [1.5e-06]" in f.read_text() and f.read_text().startswith("# a header\n# of two lines\n")
