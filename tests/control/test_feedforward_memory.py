"""The feed-forward table's working memory is bounded: the inverse dynamics runs ``CHUNK_ROWS`` rows at a
time, so a longer run adds only its own rows to the peak, and the chunked table equals the whole one."""

import tracemalloc

import numpy as np

from stewart_drake.control import feedforward as ff
from stewart_drake.core.dynamics import leg_forces_with_legs
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.trajectory import SEED

H = 1e-3  # a 1 kHz controller


def _peak(platform, n: int) -> int:
    ff.TABLE_CACHE.clear()
    tracemalloc.start()
    try:
        ff.feedforward_forces(platform, SEED, np.arange(n) * H, 0.0, H)
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_peak_memory_grows_by_the_tables_own_rows_only():
    """From 10 000 to 40 000 ticks the peak grows by less than 1 kB a tick: the arrays that grow with the run
    are the poses at t − h, t, t + h and their rates (6 × 48 B), the 18-column rows and their distinct-row
    sort (~300 B) and the table (48 B); the inverse dynamics' own temporaries (~7 kB a row) exist for one
    chunk at a time."""
    platform = load_preset("utn-dynamic")
    assert (_peak(platform, 40_000) - _peak(platform, 10_000)) / 30_000 < 1000


def test_chunked_forces_equal_the_whole_batch():
    platform = load_preset("utn-dynamic")
    t = np.arange(3 * ff.CHUNK_ROWS + 17) * H
    qm, q0, qp = SEED.pose(t - H), SEED.pose(t), SEED.pose(t + H)
    qd, qdd = (qp - qm) / (2 * H), (qp - 2 * q0 + qm) / H**2
    assert np.array_equal(ff.chunked_leg_forces(platform, q0, qd, qdd), leg_forces_with_legs(platform, q0, qd, qdd))
