"""Append-only JSON-lines journals whose every line is verified when read back (a resume's input).

A journal is a header line, the JSON object ``{"key": IDENTITY, ...}`` naming the study or search that owns it,
then one line per row::

    {"mac": "<64 hex digits>", "row": <the row as JSON>}

with ``mac`` = HMAC-SHA256(key, previous mac ‖ row text), the key the SHA-256 of the identity and the first row's
previous mac the HMAC of the header line: a chain. Reading verifies each line in order, so a row edited by hand,
a line deleted, repeated or moved, or a journal of another identity fails at the first line that differs, and
the reader refuses the journal with ``JournalError`` naming the file and the line (counted from 1, the header
being line 1). The one exception is the last line when it does not end with a newline: a write cut short by an
interruption, left out (its row is computed again) and cut off before the next append.

What the chain guarantees: the rows are the ones this toolkit wrote for this identity, in order, unchanged. Its
key is derived from the identity, not a secret, so it detects edits and damage, not a forger who runs this code;
a caller that can recompute a row's inputs (a drawn value, a design's variables) checks them as well.
"""

from __future__ import annotations

import hashlib
import hmac
import json
import os
from pathlib import Path

from stewart_drake.errors import JournalError

_PREFIX = '{"mac": "'
_MIDDLE = '", "row": '
_ROW_AT = len(_PREFIX) + 64 + len(_MIDDLE)


def _key(identity: str) -> bytes:
    return hashlib.sha256(identity.encode()).digest()


def _mac(key: bytes, previous: str, text: str) -> str:
    return hmac.new(key, (previous + text).encode(), hashlib.sha256).hexdigest()


def header_line(identity: str, **extra) -> str:
    """The header line (no newline) of a journal owned by ``identity``, with ``extra`` JSON fields."""
    return json.dumps({"key": identity, **extra})


def read_header(path: Path) -> dict:
    """The header (first line) of the journal at ``path`` as a dict; ``JournalError`` naming the file's line 1 if
    it is not a JSON object."""
    with open(path, "rb") as fh:
        first = fh.readline()
    try:
        head = json.loads(first.decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError):
        head = None
    if not isinstance(head, dict):
        raise JournalError(JournalError.HEADER.format(path=str(path), text=_shown(first)))
    return head


def read_rows(path: Path, identity: str) -> list[tuple[int, dict]]:
    """``[(line number, row), ...]`` of the journal at ``path`` owned by ``identity``, every line verified (see
    the module docstring): ``JournalError`` naming the file and the first line that does not verify. A last line
    without its newline (an interrupted write) is left out."""
    rows, _, _ = _scan(Path(path), identity)
    return rows


def _scan(path: Path, identity: str) -> tuple[list[tuple[int, dict]], str, int]:
    """The verified rows, the last mac of the chain and the byte length of the verified lines."""
    data = path.read_bytes()
    key = _key(identity)
    end = data.rfind(b"\n") + 1  # bytes after the last newline: a line cut short by an interruption
    lines = data[:end].split(b"\n")[:-1]
    if not lines:
        raise JournalError(JournalError.HEADER.format(path=str(path), text=_shown(data)))
    head = read_header(path)
    if head.get("key") != identity:
        raise JournalError(JournalError.OTHER.format(path=str(path), old=head.get("key"), new=identity))
    mac = _mac(key, "", lines[0].decode("utf-8"))
    rows = []
    for n, raw in enumerate(lines[1:], start=2):
        try:
            text = raw.decode("utf-8")
        except UnicodeDecodeError:
            text = None
        ok = (
            text is not None
            and text.startswith(_PREFIX)
            and text[len(_PREFIX) + 64 :].startswith(_MIDDLE)
            and text.endswith("}")
        )
        row_text = text[_ROW_AT:-1] if ok else ""
        stored = raw[len(_PREFIX) : len(_PREFIX) + 64]  # bytes: compare_digest refuses non-ASCII text
        if not ok or not hmac.compare_digest(stored, _mac(key, mac, row_text).encode()):
            raise JournalError(JournalError.LINE.format(path=str(path), line=n, text=_shown(raw)))
        mac = stored.decode()
        rows.append((n, json.loads(row_text)))
    return rows, mac, end


def _shown(raw: bytes) -> str:
    text = raw.decode("utf-8", errors="replace").strip()
    return repr(text[:60] + ("…" if len(text) > 60 else ""))


class JournalWriter:
    """Appends rows to the journal at ``path`` owned by ``identity``, one flush per call. The file must exist
    with its header (``header_line``; the caller writes it, atomically where it matters); its lines are verified
    first (``JournalError`` as ``read_rows``) and a last line cut short is cut off, so the chain goes on from the
    last whole line."""

    def __init__(self, path: Path, identity: str):
        self.path, self.key = Path(path), _key(identity)
        _, self.mac, end = _scan(self.path, identity)
        self.fh = open(self.path, "r+b")  # noqa: SIM115 - held for the journal's life, closed by close()
        self.fh.truncate(end)
        self.fh.seek(0, os.SEEK_END)

    def append_texts(self, texts: list[str]) -> None:
        """Append rows already encoded as JSON text (``json.dumps(row)``), in order, with one flush."""
        out = []
        for text in texts:
            self.mac = _mac(self.key, self.mac, text)
            out.append(f"{_PREFIX}{self.mac}{_MIDDLE}{text}}}\n")
        self.fh.write("".join(out).encode("utf-8"))
        self.fh.flush()

    def append(self, row: dict) -> None:
        """Append one row (a JSON-able dict)."""
        self.append_texts([json.dumps(row)])

    def close(self) -> None:
        self.fh.close()
