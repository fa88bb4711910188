"""Reading numeric CSV files (poses, trajectories) with errors that name the file and the line."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np


def _read_plain(f: Path, widths) -> tuple[np.ndarray, np.ndarray] | None:
    """The fast path for a plain file (ASCII numbers, one optional header line, no blank lines or
    quotes): numpy's C parser, ~1 µs a row. None whenever the file is anything else, so that the
    line-by-line reader handles it (and names the line of any error)."""
    try:
        raw = f.read_bytes()
    except OSError:
        return None
    if not raw or b'"' in raw or not raw.isascii():
        return None
    text = raw.decode("ascii")
    first, _, rest = text.partition("\n")
    try:
        [float(c) for c in first.split(",")]
        skip = 0
    except ValueError:
        skip = 1  # a header
    body = rest if skip else text
    if not body.strip() or "\n\n" in body.replace("\r", "") or body.lstrip("\r\n") != body:
        return None
    try:
        a = np.loadtxt(body.splitlines(), delimiter=",", ndmin=2, dtype=float)
    except ValueError:
        return None
    if a.shape[1] not in widths:
        return None
    return a, np.arange(1 + skip, 1 + skip + len(a))


def read_numeric_csv(path, kind: str, widths: tuple[int, ...], columns: str) -> tuple[np.ndarray, np.ndarray]:
    """``(rows (n, w) float array, line numbers (n,))`` from a CSV of numbers, every row of one width
    in ``widths``. A non-numeric first row is a header; blank lines are skipped. ``kind`` names the
    file in errors ("poses", "trajectory"), ``columns`` describes the expected columns."""
    f = Path(path)
    if not f.is_file():
        raise FileNotFoundError(f"{kind} file {str(path)!r} does not exist")
    fast = _read_plain(f, widths)
    if fast is not None:
        a, lines = fast
        bad = ~np.isfinite(a).all(axis=1)
        if not np.any(bad):
            return a, lines  # anything else: the reader below, which names the line
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
            width = len(values)
            rows.append(values)
            lines.append(lineno)
    if not rows:
        raise ValueError(f"{path}: no {kind} rows")
    a, lines = np.array(rows), np.array(lines)
    bad = ~np.isfinite(a).all(axis=1)  # checked once for the whole file: linear time, one numpy pass
    if np.any(bad):
        k = int(np.argmax(bad))
        raise ValueError(f"{path}:{lines[k]}: values must be finite, got {[repr(v) for v in rows[k]]!r}")
    return a, lines
