"""Shared fixtures of the calibration tests: the issue's machine errors and noise, and noise-free data."""

from __future__ import annotations

import numpy as np
import pytest

from stewart_drake.calibration.measurements import Measurements
from stewart_drake.calibration.model import Noise, measure
from stewart_drake.montecarlo.spec import parse_spec

# The "done when": ±1 mm joint errors, ±0.5 mm sensor offsets; 10 µm / 20 µrad tracker, 1 µm sensors.
ERRORS = parse_spec("anchor=±1mm leg_offset=±0.5mm").laws
NOISE = Noise(length=1e-6, position=10e-6, angle=20e-6)


def clean_data(platform, poses, kind: str, targets=None) -> Measurements:
    """Noise-free measurements of ``platform`` at ``poses`` (lines 2..n+1)."""
    q = np.asarray(poses, dtype=float)
    m = measure(platform, q, "utn", targets)
    n = len(q)
    return Measurements(
        kind,
        m["readings"],
        q if kind == "pose" else None,
        m.get("targets"),
        m["tilts"] if kind == "inclinometer" else None,
        np.ones(n),
        np.arange(2, n + 2),
    )


@pytest.fixture(scope="module")
def errors():
    return ERRORS
