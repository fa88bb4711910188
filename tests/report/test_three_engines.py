"""The "Three engines" section's float-law loop against Drake's: a row per preset and its two checks."""

import pytest

from stewart_drake.analyses import three_engines
from stewart_drake.engines.cross_check import engine_status
from stewart_drake.report import Section

STATUS = engine_status()


@pytest.mark.skipif(STATUS["pinocchio"] is not None, reason=str(STATUS["pinocchio"]))
def test_section_shows_the_float_loop_beside_drakes_with_its_checks():
    section = Section("Three engines", quick=True)
    three_engines.drake_loop(section, ["utn-dynamic"])
    checks = {c.what: c for c in section.checks}
    ratio = checks["utn-dynamic: float-law loop, Pinocchio − Drake plate with a 1 nm sensor, |ratio at h/2 − ½|"]
    size = checks["utn-dynamic: float-law loop, Pinocchio − Drake plate with a 1 nm sensor (≤ ½ h T max|a|)"]
    # first order: halving the step halves the difference (the second-order share below a half of the first)
    assert ratio.tolerance == 0.25 and ratio.worst <= ratio.tolerance
    assert 0 < size.worst <= size.tolerance and size.unit == "m"
    assert any("Pinocchio against Drake" in b for b in section.blocks)
