"""Reading numeric CSV files (poses, trajectories) with errors that name the file and the line."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from .errors import CsvError

MAX_FIELD_CHARS = 131_072  # the csv module's own limit: a longer field is not a number


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
                    raise CsvError(CsvError.FIELD_TOO_LONG.format(path=path, line=reader.line_num, limit=MAX_FIELD_CHARS,
                                                                  kind=kind)) from None
                raise CsvError(f"{path}:{reader.line_num}: {e}") from None
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
                    raise CsvError(CsvError.NOT_NUMBER.format(path=path, line=lineno, column=col, value=_short(c))) from None
            if values is None:
                continue  # header
            if len(values) not in widths or (width is not None and len(values) != width):
                expected = width or " or ".join(map(str, widths))
                raise CsvError(CsvError.WIDTH.format(path=path, line=lineno, expected=expected, columns=columns, got=len(values)))
            bad = next((i for i, v in enumerate(values) if not math.isfinite(v)), None)
            if bad is not None:
                raise CsvError(CsvError.NOT_FINITE.format(path=path, line=lineno, column=bad + 1, value=_short(row[bad])))
            width = len(values)
            rows.append(values)
            lines.append(lineno)
    if not rows:
        raise CsvError(CsvError.EMPTY.format(path=path, kind=kind))
    return np.array(rows), np.array(lines)


def _short(text: str) -> str:
    return text if len(text) <= 40 else text[:37] + "..."
