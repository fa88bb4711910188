"""The feed-forward tables remembered by their inputs (``control.feedforward.TABLE_CACHE``): a speed-up only.
A table served from the cache equals, bit for bit, the inverse dynamics computed afresh and one time at a
time; a changed input (the platform's plate mass, the lead) is a different table; the tables are
read-only, so a caller cannot change what the next one reads."""

import dataclasses

import numpy as np
import pytest

from stewart_drake.control.feedforward import TABLE_CACHE, feedforward_forces
from stewart_drake.core.dynamics import leg_forces_with_legs
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.trajectory import SEED

PLATFORM = load_preset("utn-dynamic")
TICKS = np.arange(50) * 1e-3


def test_a_remembered_table_is_the_one_computed_afresh():
    TABLE_CACHE.clear()
    first = feedforward_forces(PLATFORM, SEED, TICKS, 3.5e-3, 1e-3)
    again = feedforward_forces(PLATFORM, SEED, TICKS, 3.5e-3, 1e-3)
    assert again is first  # served from the cache
    alone = np.array([feedforward_forces(PLATFORM, SEED, [t], 3.5e-3, 1e-3)[0] for t in TICKS])  # never cached
    np.testing.assert_array_equal(first, alone)
    t = TICKS + 3.5e-3
    qm, q0, qp = SEED.pose(t - 1e-3), SEED.pose(t), SEED.pose(t + 1e-3)
    direct = leg_forces_with_legs(PLATFORM, q0, (qp - qm) / 2e-3, (qp - 2 * q0 + qm) / 1e-6)
    np.testing.assert_array_equal(first, direct)
    with pytest.raises(ValueError, match="read-only"):
        first[0, 0] = 0.0


def test_a_changed_input_is_a_different_table():
    TABLE_CACHE.clear()
    nominal = feedforward_forces(PLATFORM, SEED, TICKS, 3.5e-3, 1e-3)
    heavier = dataclasses.replace(PLATFORM, mass=PLATFORM.mass * 1.2)
    assert np.all(feedforward_forces(heavier, SEED, TICKS, 3.5e-3, 1e-3) != nominal)
    assert not np.array_equal(feedforward_forces(PLATFORM, SEED, TICKS, 2.5e-3, 1e-3), nominal)


def test_a_table_with_repeated_rows_computes_each_once(monkeypatch):
    """A held reference repeats rows (ticks at the same time, a pause): the table computes each distinct row
    once and equals, bit for bit, the inverse dynamics of every row computed afresh."""
    import stewart_drake.control.feedforward as ff

    TABLE_CACHE.clear()
    computed = []

    def counting(platform, q, qd, qdd):
        computed.append(len(q))
        return leg_forces_with_legs(platform, q, qd, qdd)

    monkeypatch.setattr(ff, "leg_forces_with_legs", counting)
    times = np.concatenate([TICKS, TICKS[::-1], np.full(20, 0.01)])  # 50 distinct times in 120 rows
    table = feedforward_forces(PLATFORM, SEED, times, 3.5e-3, 1e-3)
    assert computed == [50]
    monkeypatch.undo()
    t = times + 3.5e-3
    qm, q0, qp = SEED.pose(t - 1e-3), SEED.pose(t), SEED.pose(t + 1e-3)
    direct = leg_forces_with_legs(PLATFORM, q0, (qp - qm) / 2e-3, (qp - 2 * q0 + qm) / 1e-6)
    np.testing.assert_array_equal(table, direct)
