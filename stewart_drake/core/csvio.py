"""Reading numeric CSV files (poses, trajectories) with errors that name the file and the line.

A header row is optional; when there is one, its names say which column is which: a poses file's are
``px, py, pz, a, b, g`` and a trajectory's ``t`` and those (then ``px_dot``... and ``px_ddot``... in a
19-column file), in any order and case, each once, with the aliases of ``ALIASES`` (``x``, ``alpha``,
``a_x``, ``time``...). The columns are returned in that order; a header naming anything else is refused at
its line, as soon as the line has been read.
"""

from __future__ import annotations

import csv
import io
import math

import numpy as np

from stewart_drake.core.sanity import check_work, memory_budget
from stewart_drake.errors import CsvError
from stewart_drake.system.input_stream import read_input

MAX_FIELD_CHARS = 131_072  # the csv module's own limit: a longer field is not a number


MAX_LINE_BYTES = 1 << 20  # a row of at most 19 numbers: a longer line is no row of this file

POSE_NAMES = ("px", "py", "pz", "a", "b", "g")
# the columns of each width a file may have, in the order they are returned
COLUMN_NAMES = {
    6: POSE_NAMES,
    7: ("t", *POSE_NAMES),
    19: ("t", *POSE_NAMES, *(n + "_dot" for n in POSE_NAMES), *(n + "_ddot" for n in POSE_NAMES)),
}
_POSE_ALIASES = {
    "px": ("x", "pos_x"),
    "py": ("y", "pos_y"),
    "pz": ("z", "pos_z"),
    "a": ("ax", "a_x", "alpha"),
    "b": ("ay", "a_y", "beta"),
    "g": ("az", "a_z", "gamma", "gama", "c"),  # gama: the seed's spelling, in run's trajectory.csv
}


def _aliases() -> dict[str, str]:
    out = {"t": "t", "time": "t"}
    for name, others in _POSE_ALIASES.items():
        for alias in (name, *others):
            out[alias] = name
            out[alias + "_dot"] = out["d" + alias] = name + "_dot"
            out[alias + "_ddot"] = out["dd" + alias] = name + "_ddot"
    return out


ALIASES = _aliases()  # every accepted header name (lower case) -> its column's name


def is_number(text: str) -> bool:
    """Whether the text of a CSV cell reads as a number (a header cell does not)."""
    try:
        float(text)
    except ValueError:
        return False
    return True


def header_order(path, line: int, header: list[str], kind: str, widths, column_names=None) -> np.ndarray | None:
    """The column order that puts a file's columns as ``column_names`` (width -> names; default
    ``COLUMN_NAMES``, whose names also have the ``ALIASES``) lists them, from its ``header`` (the cells of its
    line ``line``); None when the header is in that order already or its width has no names. ``CsvError``
    naming the file, the line and the name for an unknown, repeated or missing column."""
    table = COLUMN_NAMES if column_names is None else column_names
    names = table.get(len(header)) if len(header) in widths else None
    if names is None:
        return None
    aliases = ALIASES if column_names is None else {"time": "t"} | {n: n for n in names}
    got = []
    for cell in header:
        name = aliases.get(cell.strip().lower())
        if name is None or name not in names:
            raise CsvError(
                CsvError.HEADER_UNKNOWN.format(
                    path=path, line=line, name=_short(cell.strip()), kind=kind, columns=",".join(names)
                )
            )
        got.append(name)
    if len(set(got)) != len(got):
        twice = next(n for n in got if got.count(n) > 1)
        raise CsvError(
            CsvError.HEADER_REPEATED.format(
                path=path, line=line, name=twice, header=_short(",".join(header)), kind=kind, columns=",".join(names)
            )
        )
    order = np.array([got.index(n) for n in names])
    return None if np.array_equal(order, np.arange(len(names))) else order


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

    def __init__(
        self, path, kind: str, option: str | None, bytes_per_row: float, first_line=None, max_rows=None, too_many=None
    ):
        self.path, self.kind, self.option, self.bytes_per_row = path, kind, option, bytes_per_row
        self.lines, self.current = 0, 0
        self.max_rows, self.too_many, self.blank, self.chunks = max_rows, too_many, 0, 0
        self.memory_rows = memory_budget() / bytes_per_row if bytes_per_row else math.inf
        self.first_line, self.head = first_line, b""

    def __call__(self, chunk: bytes, total: int) -> None:
        if self.first_line is not None:
            self.head += chunk[: chunk.find(b"\n") + 1 or len(chunk)]
            if self.head.endswith(b"\n") or len(self.head) > MAX_LINE_BYTES:
                self.finish()
        n = chunk.count(b"\n")
        self.current = len(chunk) - 1 - chunk.rfind(b"\n") if n else self.current + len(chunk)
        self.lines += n
        if self.max_rows is not None:
            # rows at least: lines less the blank ones, a header, and one per chunk (a blank line split between two)
            self.blank += chunk.count(b"\n\n") + chunk.count(b"\n\r\n")
            self.chunks += 1
            if self.lines - self.blank - 1 - self.chunks > self.max_rows:
                raise self.too_many
        if self.current > MAX_LINE_BYTES:
            raise CsvError(
                CsvError.LINE_TOO_LONG.format(path=self.path, line=self.lines + 1, limit=MAX_LINE_BYTES, kind=self.kind)
            )
        if self.lines + 1 > self.memory_rows:
            check_work(
                self.option or self.kind,
                repr(str(self.path)),
                self.lines + 1,
                "rows at least",
                self.bytes_per_row,
                hint="; split the file",
            )

    def finish(self) -> None:
        """Check the file's first line (once), when it is complete or the file has ended."""
        if self.first_line is not None and len(self.head) <= MAX_LINE_BYTES:
            check, self.first_line = self.first_line, None
            check(self.head)


def read_numeric_csv(
    path,
    kind: str,
    widths: tuple[int, ...],
    columns: str,
    *,
    option: str | None = None,
    bytes_per_row: float = 0.0,
    max_rows: int | None = None,
    too_many: Exception | None = None,
    column_names: dict[int, tuple[str, ...]] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """``(rows (n, w) float array, line numbers (n,))`` from a CSV of numbers, every row of one width
    in ``widths``. A non-numeric first row is a header; blank lines are skipped; a UTF-8 byte-order
    mark is ignored; a field longer than ``MAX_FIELD_CHARS`` is refused. ``kind`` names the file in errors
    ("poses", "trajectory"), ``columns`` describes the expected columns. A header's names put the columns in
    the order of ``COLUMN_NAMES`` (see the module docstring); it is checked as soon as it is read. The file is read once, as a stream (a FIFO or ``<(...)`` works), and refused
    while it is read when its rows would need more memory than there is (``bytes_per_row`` each, the
    caller's cost of a row; ``option`` names it), or when it has more than ``max_rows`` rows (``too_many`` is
    raised, while reading). ``column_names`` (width -> names, lower case) replaces ``COLUMN_NAMES`` for a file of
    other columns. Errors (``CsvError``) name the file and the line, counted from 1."""
    found = {"order": None}

    def first_line(head: bytes) -> None:
        # the header (or first row) is checked as soon as it has arrived: a bad one is refused before the rest
        try:
            text = head.decode("utf-8-sig")
        except UnicodeDecodeError:
            return  # the reader below names the line
        cells = next(csv.reader([text.rstrip("\r\n")]), [])
        if not cells or all(not c.strip() for c in cells):
            return
        if len(cells) not in widths:
            expected = " or ".join(map(str, widths))
            raise CsvError(CsvError.WIDTH.format(path=path, line=1, expected=expected, columns=columns, got=len(cells)))
        if not all(is_number(c) for c in cells):
            found["order"] = header_order(path, 1, cells, kind, widths, column_names)

    budget = _RowBudget(path, kind, option, bytes_per_row, first_line, max_rows, too_many)
    raw = read_input(
        path,
        kind=kind,
        limit=max(memory_budget(), 1 << 20),
        on_chunk=budget,
        missing=CsvError.MISSING.format(kind=kind, path=str(path)),
        folder=CsvError.IS_FOLDER.format(kind=kind, path=str(path)),
    )
    budget.finish()
    a, lines = _parse(path, raw, kind, widths, columns)
    if max_rows is not None and len(a) > max_rows:
        raise too_many
    return (a, lines) if found["order"] is None else (a[:, found["order"]], lines)


def _parse(path, raw: bytes, kind: str, widths, columns: str) -> tuple[np.ndarray, np.ndarray]:
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
