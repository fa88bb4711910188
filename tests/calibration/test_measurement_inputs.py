"""A measurement file whose positions are in another unit than its readings is refused with the unit named,
and a bad header is refused before the body is parsed."""

from __future__ import annotations

import csv

import numpy as np
import pytest

from stewart_drake.calibration import measurements
from stewart_drake.calibration.measurements import measurements_csv, read_measurements
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.sampling import random_poses
from stewart_drake.errors import CalibrationError

from .conftest import clean_data


@pytest.fixture(scope="module")
def platform():
    return load_preset("utn-kinematic")


def _pose_file(tmp_path, platform, position_factor=1.0):
    m = clean_data(platform, random_poses(platform, 12, seed=3), "pose")
    rows = list(csv.reader(measurements_csv(m).splitlines()))
    header, body = rows[0], np.array(rows[1:], dtype=float)
    cols = [header.index(c) for c in ("px", "py", "pz")]
    body[:, cols] *= position_factor
    f = tmp_path / "m.csv"
    f.write_text(",".join(header) + "\n" + "".join(",".join(repr(float(v)) for v in r) + "\n" for r in body))
    return f


def test_positions_in_mm_with_readings_in_m_name_the_unit(tmp_path, platform):
    """The readings in m and the positions in mm: the plate 1000x too far; read in mm every pose fits, which
    the message says."""
    assert read_measurements(_pose_file(tmp_path, platform), platform).kind == "pose"  # the same file in m: read
    with pytest.raises(CalibrationError, match=r"m.csv: the measured poses .* read in mm every pose would be inside"):
        read_measurements(_pose_file(tmp_path, platform, 1e3), platform)


def test_a_bad_header_is_refused_before_the_body_is_parsed(tmp_path, platform, monkeypatch):
    """Rows parsed (counted through the csv reader) before the refusal of a header naming 'gg': the header
    alone, not the 5000 rows below it."""
    f = tmp_path / "big.csv"
    f.write_text("l1,l2,l3,l4,l5,l6,px,py,pz,a,b,gg\n" + "0.5,0.5,0.5,0.5,0.5,0.5,0,0,0.1,0,0,0\n" * 5000)
    parsed = []

    class Counting:
        @staticmethod
        def reader(lines, *args, **kwargs):
            for row in csv.reader(lines, *args, **kwargs):
                parsed.append(row)
                yield row

    monkeypatch.setattr(measurements, "csv", Counting)
    with pytest.raises(CalibrationError, match="big.csv:1: unknown column 'gg'"):
        read_measurements(f, platform)
    assert len(parsed) == 1
