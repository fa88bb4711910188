"""Spec values at the edges the spec fuzz found at 5000 examples (issue 24, item 4): a negative zero
('±-0', '0..-0', '±-0%') is zero, and draws what zero draws; numpy's uniform had refused the range 0.0 to
-0.0 ("high - low < 0"), a ValueError out of ``check_study``."""

from __future__ import annotations

import numpy as np
import pytest

from stewart_drake.core.geometry import load_platform
from stewart_drake.montecarlo.scenario import Study, draw
from stewart_drake.montecarlo.spec import parse_spec


@pytest.mark.parametrize(
    "word, zero",
    [
        ("anchor=±-0", "anchor=±0"),
        ("anchor=+--0mm", "anchor=±0mm"),
        ("actuator_lag=0..-0", "actuator_lag=0..0"),
        ("plate_mass=±-0%", "plate_mass=±0%"),
    ],
)
def test_negative_zero_is_zero(word, zero):
    p = load_platform("utn-dynamic")
    law = next(iter(parse_spec([word]).laws.values()))
    assert not any(np.signbit(v) for v in law.values if isinstance(v, float)), law
    _, d = draw(Study(p, parse_spec([word]), seed=0, runs=1), 0)
    _, z = draw(Study(p, parse_spec([zero]), seed=0, runs=1), 0)
    assert d.columns() == z.columns()
