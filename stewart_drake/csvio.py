"""Reading numeric CSV files (poses, trajectories) with errors that name the file and the line."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np


def read_numeric_csv(path, kind: str, widths: tuple[int, ...], columns: str) -> tuple[np.ndarray, np.ndarray]:
    """``(rows (n, w) float array, line numbers (n,))`` from a CSV of numbers, every row of one width
    in ``widths``. A non-numeric first row is a header; blank lines are skipped. ``kind`` names the
    file in errors ("poses", "trajectory"), ``columns`` describes the expected columns."""
    f = Path(path)
    if not f.is_file():
        raise FileNotFoundError(f"{kind} file {str(path)!r} does not exist")
    rows, lines, width = [], [], None
    with f.open(newline="") as fh:
        for lineno, row in enumerate(csv.reader(fh), start=1):
            if not row or all(not c.strip() for c in row):
                continue
            try:
                values = [float(c) for c in row]
            except ValueError:
                if lineno == 1:
                    continue  # header
                raise ValueError(f"{path}:{lineno}: not a number in {row!r}") from None
            if len(values) not in widths or (width is not None and len(values) != width):
                expected = width or " or ".join(map(str, widths))
                raise ValueError(f"{path}:{lineno}: expected {expected} values ({columns}), got {len(values)}")
            if not np.all(np.isfinite(values)):
                raise ValueError(f"{path}:{lineno}: values must be finite, got {row!r}")
            width = len(values)
            rows.append(values)
            lines.append(lineno)
    if not rows:
        raise ValueError(f"{path}: no {kind} rows")
    return np.array(rows), np.array(lines)
