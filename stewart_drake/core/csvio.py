"""Reading numeric CSV files (poses, trajectories) with errors that name the file and the line."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from stewart_drake.errors import CsvError

MAX_FIELD_CHARS = 131_072  # the csv module's own limit: a longer field is not a number


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
    in ``widths``. A non-numeric first row is a header; blank lines are skipped; a UTF-8 byte-order
    mark is ignored; a field longer than ``MAX_FIELD_CHARS`` is refused. ``kind`` names the file in errors ("poses", "trajectory"), ``columns`` describes
    the expected columns. Errors (``CsvError``) name the file and the line, counted from 1."""
    f = Path(path)
    if not f.exists():
        raise CsvError(CsvError.MISSING.format(kind=kind, path=str(path)))
    if f.is_dir():
        raise CsvError(CsvError.IS_FOLDER.format(kind=kind, path=str(path)))
    fast = _read_plain(f, widths)
    if fast is not None:
        a, lines = fast
        bad = ~np.isfinite(a).all(axis=1)
        if not np.any(bad):
            return a, lines  # anything else: the reader below, which names the line
    rows, lines, width = [], [], None
    with f.open(newline="", encoding="utf-8-sig") as fh:
        reader = csv.reader(fh)
        lineno = 0
        while True:
            try:
                row = next(reader)
            except StopIteration:
                break
            except csv.Error as e:
                if "field larger than field limit" in str(e):
                    raise CsvError(
                        CsvError.FIELD_TOO_LONG.format(
                            path=path, line=reader.line_num, limit=MAX_FIELD_CHARS, kind=kind
                        )
                    ) from None
                raise CsvError(CsvError.SYNTAX.format(path=path, line=reader.line_num, problem=e)) from None
            except UnicodeDecodeError:
                raise CsvError(CsvError.NOT_TEXT.format(path=path, line=reader.line_num + 1)) from None
            lineno = reader.line_num
            if not row or all(not c.strip() for c in row):
                continue
            values = []
            for col, c in enumerate(row, 1):
                try:
                    values.append(float(c))
                except ValueError:
                    if lineno == 1:
                        values = None
                        break
                    raise CsvError(
                        CsvError.NOT_NUMBER.format(path=path, line=lineno, column=col, value=_short(c))
                    ) from None
            if values is None:
                continue  # header
            if len(values) not in widths or (width is not None and len(values) != width):
                expected = width or " or ".join(map(str, widths))
                raise CsvError(
                    CsvError.WIDTH.format(path=path, line=lineno, expected=expected, columns=columns, got=len(values))
                )
            bad = next((i for i, v in enumerate(values) if not math.isfinite(v)), None)
            if bad is not None:
                raise CsvError(
                    CsvError.NOT_FINITE.format(path=path, line=lineno, column=bad + 1, value=_short(row[bad]))
                )
            width = len(values)
            rows.append(values)
            lines.append(lineno)
    if not rows:
        raise CsvError(CsvError.EMPTY.format(path=path, kind=kind))
    return np.array(rows), np.array(lines)


def _short(text: str) -> str:
    return text if len(text) <= 40 else text[:37] + "..."
