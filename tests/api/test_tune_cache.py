"""A run of a ``controller.gains: tune`` machine plans with the gains kept by its first run (the cache itself:
``tests/control/test_tuning_cache.py``)."""

from __future__ import annotations

import pytest

from stewart_drake.api.simulation import plan_run
from tests.control.test_tuning_cache import tunings  # noqa: F401 - the fixture: a fresh cache, a counted tuner

NEWCOMER = "examples/newcomer-210kg.yaml"


def test_the_next_run_of_a_machine_reads_the_gains_it_was_tuned_with(tunings):  # noqa: F811
    first = plan_run(NEWCOMER, **{"controller.gains": "tune"}).scenario.config.gains
    again = plan_run(NEWCOMER, **{"controller.gains": "tune"}).scenario.config.gains
    assert len(tunings) == 1 and again == first and first.kp == pytest.approx(1000.0, rel=1e-3)  # its Q15 word
