"""Drive files: CSV and Parquet round trips, and errors that name the file, line and column."""

import re

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from stewart_drake.control.cueing.drive import GRAVITY, Drive, load_drive, save_drive
from stewart_drake.errors import CsvError, DriveError


def _drive(n=50, attitude=True) -> Drive:
    rng = np.random.default_rng(3)
    t = 0.01 * np.arange(n)
    f = rng.normal(size=(n, 3)) + [0, 0, GRAVITY]
    return Drive("d", t, f, rng.normal(size=(n, 3)), rng.normal(size=(n, 3)) if attitude else None)


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
@pytest.mark.parametrize("attitude", [True, False])
def test_round_trip_is_exact(tmp_path, suffix, attitude):
    # %.17g (CSV) and float64 (Parquet) hold every double exactly; t is read back on its exact grid
    d = _drive(attitude=attitude)
    back = load_drive(save_drive(d, tmp_path / f"d{suffix}"))
    np.testing.assert_array_equal(back.specific_force, d.specific_force)
    np.testing.assert_array_equal(back.angular_velocity, d.angular_velocity)
    np.testing.assert_allclose(back.t, d.t, rtol=0, atol=1e-15)
    assert (back.attitude is None) == (not attitude)


def test_csv_header_in_any_order_and_no_header(tmp_path):
    p = tmp_path / "h.csv"
    p.write_text("wz,wy,wx,fz,fy,fx,t\n" + "".join(f"6,5,4,3,2,1,{k * 0.1}\n" for k in range(4)))
    d = load_drive(p)
    np.testing.assert_array_equal(d.specific_force[0], [1, 2, 3])
    np.testing.assert_array_equal(d.angular_velocity[0], [4, 5, 6])
    q = tmp_path / "n.csv"
    q.write_text("".join(f"{k * 0.1},1,2,3,4,5,6\n" for k in range(4)))
    assert load_drive(q).dt == pytest.approx(0.1)


def test_csv_errors_name_file_line_and_column(tmp_path):
    p = tmp_path / "bad.csv"
    p.write_text("t,fx,fy,fz,wx,wy,wz\n0,0,0,9.8,0,0,0\n0.01,0,x,9.8,0,0,0\n0.02,0,0,9.8,0,0,0\n")
    with pytest.raises(CsvError, match=re.escape(f"{p}:3: column 3: not a number: 'x'")):
        load_drive(p)
    p.write_text("t,fx,fy,fz,wx,wy,speed\n0,0,0,9.8,0,0,0\n")
    with pytest.raises(CsvError, match="'speed' names no column of a drive file"):
        load_drive(p)
    p.write_text("t,fx,fy,fz,wx,wy,wz\n0,0,0,9.8,0,0,0\n0.01,0,0,9.8,0,0,0\n0.03,0,0,9.8,0,0,0\n0.04,0,0,9.8,0,0,0\n")
    with pytest.raises(DriveError, match=re.escape(f"{p}:4: column t: samples must be evenly spaced; t = 0.030000 s")):
        load_drive(p)


def test_parquet_errors_name_column_and_row(tmp_path):
    p = tmp_path / "bad.parquet"
    cols = {c: [0.0, 0.01, 0.02] for c in ("t", "fx", "fy", "fz", "wx", "wy")}
    pq.write_table(pa.table(cols), p)
    with pytest.raises(DriveError, match="column 'wz' is missing"):
        load_drive(p)
    cols["wz"] = [0.0, float("nan"), 0.0]
    pq.write_table(pa.table(cols), p)
    with pytest.raises(DriveError, match=re.escape("row 2, column 'wz': values must be finite numbers, got nan")):
        load_drive(p)


def test_save_never_replaces_a_file_it_did_not_write(tmp_path):
    p = tmp_path / "mine.csv"
    p.write_text("the user's own notes\n")
    with pytest.raises(Exception, match="never overwritten"):
        save_drive(_drive(), p)
    assert p.read_text() == "the user's own notes\n"


def test_drive_checks_its_arrays():
    with pytest.raises(DriveError, match=re.escape("specific_force must have shape (4, 3), got (4, 2)")):
        Drive("x", np.arange(4.0), np.zeros((4, 2)), np.zeros((4, 3)))
    with pytest.raises(DriveError, match="t must increase in equal steps; sample 3 steps 2.0 s"):
        Drive("x", np.array([0.0, 1, 3, 4]), np.zeros((4, 3)), np.zeros((4, 3)))
