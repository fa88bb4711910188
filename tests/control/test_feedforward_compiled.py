"""The fixed-point loop's feed-forward tables by the compiled inverse dynamics (``FeedforwardTable``, engine ``c``):
computed ``CHUNK_ROWS`` ticks at a time, each row the number of that row alone (the C loop is elementwise), within
``leg_forces_kernel.RELATIVE_TOLERANCE`` of numpy's table (the reference, which the analyses keep); without the
compiled loop, numpy's table bit for bit, and the engine says so."""

import numpy as np
import pytest

from stewart_drake.control import feedforward as ff
from stewart_drake.core import leg_forces_kernel
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.trajectory import ROTATING

H = 1e-3  # a 1 kHz controller
LEAD = 3.5e-3  # s, a table's lead (output delay + half a sample + the actuator lag)
PLATFORM = load_preset("utn-kinematic")


def _relative(F, ref) -> np.ndarray:
    return np.abs(F - ref).max(-1) / np.abs(ref).max(-1)


@pytest.mark.skipif(leg_forces_kernel.library() is None, reason="no C compiler")
def test_a_table_across_chunk_boundaries_is_its_rows_alone(monkeypatch):
    """3 chunks of 64 ticks and 17 more: every row equals the row computed alone (same engine), so a chunk boundary
    changes nothing, and the table is within the stated tolerance of numpy's."""
    monkeypatch.setattr(ff, "CHUNK_ROWS", 64)
    ff.TABLE_CACHE.clear()
    times = np.arange(3 * 64 + 17) * H
    assert ff.feedforward_engine("float") == "numpy"  # the float law's log would carry every last bit
    table = ff.FeedforwardTable(PLATFORM, ROTATING, LEAD, H, ff.feedforward_engine("fixed"))
    assert table.engine == "c"
    rows = table.prime(times)
    alone = np.array([ff.feedforward_forces(PLATFORM, ROTATING, [t], LEAD, H, "c")[0] for t in times])
    np.testing.assert_array_equal(rows, alone)
    reference = ff.feedforward_forces(PLATFORM, ROTATING, times, LEAD, H, "numpy")
    assert _relative(rows, reference).max() <= leg_forces_kernel.RELATIVE_TOLERANCE
    assert table.force(times[5] + 0.25 * H).shape == (6,)  # a time off the table: computed on its own


def test_without_the_compiled_loop_the_tables_are_numpys(monkeypatch):
    monkeypatch.setattr(leg_forces_kernel, "_LIB", [None])
    ff.TABLE_CACHE.clear()
    times = np.arange(300) * H
    table = ff.FeedforwardTable(PLATFORM, ROTATING, LEAD, H, ff.feedforward_engine("fixed"))
    assert table.engine == "numpy"
    reference = ff.feedforward_forces(PLATFORM, ROTATING, times, LEAD, H)
    np.testing.assert_array_equal(table.prime(times), reference)
    ff.TABLE_CACHE.clear()  # computed again: asking for the compiled loop where there is none gives numpy's numbers
    np.testing.assert_array_equal(ff.feedforward_forces(PLATFORM, ROTATING, times, LEAD, H, "c"), reference)
