"""Reading a motion program's text from a file: bounded in size, UTF-8, no NUL bytes; errors name the file."""

from __future__ import annotations

from pathlib import Path

from stewart_drake.errors import InputError

MAX_PROGRAM_BYTES = 1_000_000


def read_program(path: str) -> str:
    """The text of a program file (UTF-8, at most ``MAX_PROGRAM_BYTES``); ``InputError`` naming the file
    (and the line of a NUL byte) otherwise."""
    f = Path(path)
    if not f.exists():
        raise InputError(InputError.PROGRAM_MISSING.format(path=path))
    if not f.is_file():
        what = "a folder" if f.is_dir() else "not a regular file"
        raise InputError(InputError.PROGRAM_NOT_FILE.format(path=path, what=what))
    with f.open("rb") as fh:
        data = fh.read(MAX_PROGRAM_BYTES + 1)
    if len(data) > MAX_PROGRAM_BYTES:
        raise InputError(InputError.PROGRAM_TOO_LARGE.format(path=path, limit=MAX_PROGRAM_BYTES))
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as e:
        raise InputError(InputError.PROGRAM_NOT_TEXT.format(path=path, offset=e.start)) from None
    if "\0" in text:
        raise InputError(InputError.PROGRAM_NUL.format(path=path, line=text[: text.index("\0")].count("\n") + 1))
    return text
