"""A vehicle's motion as a rider feels it (a "drive"), and its CSV/Parquet files.

A drive is sampled at a uniform step: the specific force ``f = a − g`` (m/s²) and the angular velocity (rad/s) at
the rider's head, both in the head frame (x forward, y left, z up; at rest ``f = (0, 0, +g)``), and optionally the
vehicle's attitude (roll, pitch, yaw, rad; ``zyx``: R = Rz(yaw) Ry(pitch) Rx(roll), Drake's ``RollPitchYaw``).
The file's columns are ``t,fx,fy,fz,wx,wy,wz`` and optionally ``roll,pitch,yaw``, in SI; a CSV's header may give
them in any order (or be left out, in that order).
"""

from __future__ import annotations

import io
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from stewart_drake.core.csvio import read_numeric_csv
from stewart_drake.errors import DriveError, short_number
from stewart_drake.system.output_folder import write_output_file

GRAVITY = 9.80665  # m/s², standard gravity: the specific force at rest
REQUIRED = ("t", "fx", "fy", "fz", "wx", "wy", "wz")
OPTIONAL = ("roll", "pitch", "yaw")
MIN_SAMPLES = 3
MAX_SAMPLES = 10_000_000  # 28 h at 100 Hz: ten float columns of this many rows are 0.8 GB
STEP_TOLERANCE = 1e-6  # relative: a Drive's steps differ by rounding only
FILE_STEP_TOLERANCE = 1e-3  # relative to a file's first step: its times written to 4 significant digits of the step


@dataclass(frozen=True, eq=False)
class Drive:
    """A vehicle's motion at the rider's head.

    Attributes:
        name: shown in outputs.
        t: ``(N,)`` s, increasing in one step.
        specific_force: ``(N, 3)`` m/s², head frame (x forward, y left, z up); ``(0, 0, g)`` at rest.
        angular_velocity: ``(N, 3)`` rad/s, head frame.
        attitude: ``(N, 3)`` rad (roll, pitch, yaw of the vehicle, ``zyx``), or None.
    """

    name: str
    t: np.ndarray
    specific_force: np.ndarray
    angular_velocity: np.ndarray
    attitude: np.ndarray | None = None

    def __post_init__(self):
        t = np.array(self.t, dtype=float)
        if t.ndim != 1 or len(t) < MIN_SAMPLES:
            raise DriveError(
                DriveError.SHAPE.format(name=self.name, field="t", shape=f"(N >= {MIN_SAMPLES},)", got=t.shape)
            )
        n = len(t)
        _check(self.name, "t", t, (n,))
        step = np.diff(t)
        bad = np.flatnonzero(np.abs(step - step[0]) > STEP_TOLERANCE * abs(step[0]))
        if step[0] <= 0 or bad.size:
            j = int(bad[0]) if bad.size else 0  # the step from sample j to j + 1 (counted from 0)
            raise DriveError(DriveError.TIMES.format(name=self.name, index=j + 2, step=step[j], expected=step[0]))
        object.__setattr__(self, "t", _frozen(t))
        for field in ("specific_force", "angular_velocity", "attitude"):
            value = getattr(self, field)
            if value is not None:
                object.__setattr__(self, field, _frozen(_check(self.name, field, np.array(value, dtype=float), (n, 3))))

    @property
    def dt(self) -> float:
        """The sampling step, s."""
        return float(self.t[1] - self.t[0])

    def __len__(self) -> int:
        return len(self.t)


def _check(name: str, field: str, value: np.ndarray, shape: tuple) -> np.ndarray:
    if value.shape != shape:
        raise DriveError(DriveError.SHAPE.format(name=name, field=field, shape=shape, got=value.shape))
    bad = np.argwhere(~np.isfinite(value))
    if bad.size:
        k = int(bad[0][0])
        raise DriveError(DriveError.NOT_FINITE.format(name=name, field=field, index=k + 1, value=value[k]))
    return value


def _frozen(a: np.ndarray) -> np.ndarray:
    a.flags.writeable = False
    return a


def load_drive(path) -> Drive:
    """The drive in the CSV or Parquet file ``path`` (named after the file's stem). ``DriveError`` naming the
    file, line (row) and column of the first bad value, a missing column or an uneven time step."""
    path = str(path)
    if path.lower().endswith(".parquet"):
        rows, lines = _read_parquet(path)
    else:
        rows, lines = read_numeric_csv(
            path,
            "drive",
            (7, 10),
            ",".join(REQUIRED) + "[," + ",".join(OPTIONAL) + "]",
            bytes_per_row=10 * 8 * 3,
            max_rows=MAX_SAMPLES,
            too_many=DriveError(
                DriveError.TOO_MANY.format(path=path, got=f"more than {MAX_SAMPLES}", limit=MAX_SAMPLES)
            ),
            column_names={7: REQUIRED, 10: REQUIRED + OPTIONAL},
        )
    if len(rows) < MIN_SAMPLES:
        raise DriveError(DriveError.TOO_FEW.format(path=path, need=MIN_SAMPLES, got=len(rows)))
    t = rows[:, 0]
    step = np.diff(t)
    expected = step[0]
    bad = np.flatnonzero(~(np.abs(step - expected) <= FILE_STEP_TOLERANCE * abs(expected)) | (step <= 0))
    if bad.size:
        k = int(bad[0]) + 1
        raise DriveError(
            DriveError.STEP.format(
                path=path,
                line=int(lines[k]),
                t=short_number(t[k], 6),
                t_prev=short_number(t[k - 1], 6),
                step=short_number(step[k - 1], 6),
                expected=short_number(expected, 6),
            )
        )
    # the times as an exact grid: the file's rounding of t would otherwise fail the uniform-step check of Drive
    grid = t[0] + (t[-1] - t[0]) / (len(t) - 1) * np.arange(len(t))
    return Drive(Path(path).stem, grid, rows[:, 1:4], rows[:, 4:7], rows[:, 7:10] if rows.shape[1] == 10 else None)


def _read_parquet(path: str) -> tuple[np.ndarray, np.ndarray]:
    try:
        meta = pq.ParquetFile(path)
        n = meta.metadata.num_rows
        names = meta.schema_arrow.names
    except FileNotFoundError:
        raise DriveError(DriveError.INPUT_MISSING.format(kind="drive", path=path)) from None
    except (OSError, pa.ArrowException) as e:
        raise DriveError(DriveError.PARQUET.format(path=path, reason=e)) from None
    if n > MAX_SAMPLES:
        raise DriveError(DriveError.TOO_MANY.format(path=path, got=n, limit=MAX_SAMPLES))
    for column in REQUIRED:
        if column not in names:
            raise DriveError(DriveError.PARQUET_COLUMN.format(path=path, column=column, columns=",".join(REQUIRED)))
    columns = list(REQUIRED) + ([*OPTIONAL] if all(c in names for c in OPTIONAL) else [])
    table = meta.read(columns=columns)
    rows = np.empty((n, len(columns)))
    for j, column in enumerate(columns):
        values = table.column(column).to_numpy(zero_copy_only=False)
        try:
            rows[:, j] = np.asarray(values, dtype=float)
        except (TypeError, ValueError):
            rows[:, j] = np.nan
        bad = np.flatnonzero(~np.isfinite(rows[:, j]))
        if bad.size:
            k = int(bad[0])
            raise DriveError(
                DriveError.PARQUET_VALUE.format(path=path, row=k + 1, column=column, value=str(_shown(values[k])))
            )
    return rows, np.arange(1, n + 1)


def _shown(value):
    """A Parquet cell for a message: numpy scalars as plain Python values."""
    return value.item() if isinstance(value, np.generic) else value


def drive_columns(drive: Drive) -> dict[str, np.ndarray]:
    """The drive's columns by their file names (``t``, ``fx`` ... and ``roll`` ... when it has an attitude)."""
    parts = [drive.t[:, None], drive.specific_force, drive.angular_velocity]
    if drive.attitude is not None:
        parts.append(drive.attitude)
    names = REQUIRED + (OPTIONAL if drive.attitude is not None else ())
    return dict(zip(names, np.hstack(parts).T))


def save_drive(drive: Drive, path) -> Path:
    """Write ``drive`` to ``path`` (``.csv``: a header and full-precision rows; ``.parquet``: one float64 column
    each). A file that exists is replaced only when this program wrote it (the output policy's
    ``write_output_file``); returns the path."""
    shown = str(path)
    columns = drive_columns(drive)
    if shown.lower().endswith(".parquet"):
        sink = io.BytesIO()
        pq.write_table(pa.table(columns), sink)
        data = sink.getvalue()
    elif shown.lower().endswith(".csv"):
        body = np.column_stack(list(columns.values()))
        text = io.StringIO()
        text.write(",".join(columns) + "\n")
        np.savetxt(text, body, delimiter=",", fmt="%.17g")
        data = text.getvalue().encode("ascii")
    else:
        raise DriveError(DriveError.FORMAT.format(path=shown))
    return write_output_file(shown, data, option="path")
