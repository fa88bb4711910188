"""The feed-forward table's working memory is bounded: the poses, rates and inverse dynamics run ``CHUNK_ROWS``
ticks at a time, so a longer run adds only its own rows to the peak, and the chunked table equals the whole one."""

import tracemalloc

import numpy as np
import pytest

from stewart_drake.control import feedforward as ff
from stewart_drake.core.dynamics import leg_forces_with_legs
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.trajectory import SEED

H = 1e-3  # a 1 kHz controller


def _peak(platform, n: int, engine: str) -> int:
    ff.TABLE_CACHE.clear()
    tracemalloc.start()
    try:
        ff.feedforward_forces(platform, SEED, np.arange(n) * H, 0.0, H, engine)
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


@pytest.mark.parametrize("engine", ["numpy", "c"])
def test_peak_memory_grows_by_the_tables_own_rows_only(engine):
    """From 10 000 to 40 000 ticks the peak grows by the table and the times (48 + 8 B a tick, the caller's) and
    little else (< 100 B a tick): the poses at t − h, t, t + h, their rates, the distinct-row sort (numpy) and the
    inverse dynamics' temporaries (~7 kB a row for numpy) exist for one chunk at a time."""
    platform = load_preset("utn-dynamic")
    assert (_peak(platform, 40_000, engine) - _peak(platform, 10_000, engine)) / 30_000 < 56 + 100


def test_chunked_forces_equal_the_whole_batch():
    """The numpy path: the table of 3 chunks and 17 ticks is the inverse dynamics of every row in one batch, bit
    for bit (the pose functions and the inverse dynamics are elementwise over rows)."""
    platform = load_preset("utn-dynamic")
    t = np.arange(3 * ff.CHUNK_ROWS + 17) * H
    qm, q0, qp = SEED.pose(t - H), SEED.pose(t), SEED.pose(t + H)
    qd, qdd = (qp - qm) / (2 * H), (qp - 2 * q0 + qm) / H**2
    ff.TABLE_CACHE.clear()
    table = ff.feedforward_forces(platform, SEED, t, 0.0, H, "numpy")
    assert np.array_equal(table, leg_forces_with_legs(platform, q0, qd, qdd))
