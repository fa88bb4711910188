"""Reading a motion program's text from a file: bounded in size, UTF-8, no NUL bytes; errors name the file."""

from __future__ import annotations

from stewart_drake.errors import InputError
from stewart_drake.system.input_stream import read_input

MAX_PROGRAM_BYTES = 1_000_000


def read_program(path: str) -> str:
    """The text of a program file (UTF-8, at most ``MAX_PROGRAM_BYTES``); ``InputError`` naming the file
    (and the line of a NUL byte) otherwise."""
    data = read_input(  # once, as a stream: a FIFO or <(...) works, /dev/zero stops at the limit
        path,
        kind="program",
        limit=MAX_PROGRAM_BYTES,
        missing=InputError.PROGRAM_MISSING.format(path=path),
        folder=InputError.PROGRAM_NOT_FILE.format(path=path, what="a folder"),
        too_large=InputError.PROGRAM_TOO_LARGE.format(path=path, limit=MAX_PROGRAM_BYTES),
    )
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as e:
        raise InputError(InputError.PROGRAM_NOT_TEXT.format(path=path, offset=e.start)) from None
    if "\0" in text:
        raise InputError(InputError.PROGRAM_NUL.format(path=path, line=text[: text.index("\0")].count("\n") + 1))
    return text
