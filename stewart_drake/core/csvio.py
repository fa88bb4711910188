"""Reading numeric CSV files (poses, trajectories) with errors that name the file and the line."""

from __future__ import annotations

import csv
import io
import math

import numpy as np

from stewart_drake.core.input_stream import read_input
from stewart_drake.core.sanity import check_work, memory_budget
from stewart_drake.errors import CsvError

MAX_FIELD_CHARS = 131_072  # the csv module's own limit: a longer field is not a number


MAX_LINE_BYTES = 1 << 20  # a row of at most 19 numbers: a longer line is no row of this file


def _read_plain(raw: bytes, widths) -> tuple[np.ndarray, np.ndarray] | None:
    """The fast path for a plain file (ASCII numbers, one optional header line, no blank lines or
    quotes): numpy's C parser, ~1 µs a row. None whenever the file is anything else, so that the
    line-by-line reader handles it (and names the line of any error)."""
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


class _RowBudget:
    """``read_input``'s ``on_chunk`` for a CSV: counts lines as they arrive and refuses, while reading,
    a line longer than ``MAX_LINE_BYTES`` (``/dev/zero``) or more rows than memory holds at
    ``bytes_per_row`` each (``sanity.check_work``, naming ``option``)."""

    def __init__(self, path, kind: str, option: str | None, bytes_per_row: float):
        self.path, self.kind, self.option, self.bytes_per_row = path, kind, option, bytes_per_row
        self.lines, self.current = 0, 0
        self.max_rows = memory_budget() / bytes_per_row if bytes_per_row else math.inf

    def __call__(self, chunk: bytes, total: int) -> None:
        n = chunk.count(b"\n")
        self.current = len(chunk) - 1 - chunk.rfind(b"\n") if n else self.current + len(chunk)
        self.lines += n
        if self.current > MAX_LINE_BYTES:
            raise CsvError(
                CsvError.LINE_TOO_LONG.format(path=self.path, line=self.lines + 1, limit=MAX_LINE_BYTES, kind=self.kind)
            )
        if self.lines + 1 > self.max_rows:
            check_work(
                self.option or self.kind,
                repr(str(self.path)),
                self.lines + 1,
                "rows at least",
                self.bytes_per_row,
                hint="; split the file",
            )


def read_numeric_csv(
    path, kind: str, widths: tuple[int, ...], columns: str, *, option: str | None = None, bytes_per_row: float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """``(rows (n, w) float array, line numbers (n,))`` from a CSV of numbers, every row of one width
    in ``widths``. A non-numeric first row is a header; blank lines are skipped; a UTF-8 byte-order
    mark is ignored; a field longer than ``MAX_FIELD_CHARS`` is refused. ``kind`` names the file in errors ("poses", "trajectory"), ``columns`` describes
    the expected columns. The file is read once, as a stream (a FIFO or ``<(...)`` works), and refused
    while it is read when its rows would need more memory than there is (``bytes_per_row`` each, the
    caller's cost of a row; ``option`` names it). Errors (``CsvError``) name the file and the line,
    counted from 1."""
    raw = read_input(
        path,
        kind=kind,
        limit=max(memory_budget(), 1 << 20),
        on_chunk=_RowBudget(path, kind, option, bytes_per_row),
        missing=CsvError.MISSING.format(kind=kind, path=str(path)),
        folder=CsvError.IS_FOLDER.format(kind=kind, path=str(path)),
    )
    fast = _read_plain(raw, widths)
    if fast is not None:
        a, lines = fast
        bad = ~np.isfinite(a).all(axis=1)
        if not np.any(bad):
            return a, lines  # anything else: the reader below, which names the line
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as e:
        raise CsvError(CsvError.NOT_TEXT.format(path=path, line=raw[: e.start].count(b"\n") + 1)) from None
    rows, lines, width = [], [], None
    reader = csv.reader(io.StringIO(text, newline=""))
    lineno = 0
    while True:
        try:
            row = next(reader)
        except StopIteration:
            break
        except csv.Error as e:
            if "field larger than field limit" in str(e):
                raise CsvError(
                    CsvError.FIELD_TOO_LONG.format(path=path, line=reader.line_num, limit=MAX_FIELD_CHARS, kind=kind)
                ) from None
            raise CsvError(CsvError.SYNTAX.format(path=path, line=reader.line_num, problem=e)) from None
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
            raise CsvError(CsvError.NOT_FINITE.format(path=path, line=lineno, column=bad + 1, value=_short(row[bad])))
        width = len(values)
        rows.append(values)
        lines.append(lineno)
    if not rows:
        raise CsvError(CsvError.EMPTY.format(path=path, kind=kind))
    return np.array(rows), np.array(lines)


def _short(text: str) -> str:
    return text if len(text) <= 40 else text[:37] + "..."
