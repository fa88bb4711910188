"""Reading an input file once, as a stream with a byte budget.

Every input file (platform and ``--vary`` YAML, CSV poses and trajectories, motion programs, firmware C)
is read here: opened once and read in chunks up to a limit, so that a FIFO, a process substitution
(``<(...)``, ``/dev/fd/N``) or a device works like a file, and an endless one (``/dev/zero``) is refused
by the budget instead of filling memory (its ``stat`` size is 0, so a size check cannot see it). A CSV
reader passes ``on_chunk`` to refuse, while reading, more rows than memory holds.
"""

from __future__ import annotations

import errno
import os
from collections.abc import Callable

from stewart_drake.errors import InputError

CHUNK = 1 << 20


def read_input(
    path,
    *,
    kind: str,
    limit: int,
    on_chunk: Callable[[bytes, int], None] | None = None,
    missing: str | None = None,
    folder: str | None = None,
    too_large: str | None = None,
) -> bytes:
    """The bytes of the input ``path`` (as the user wrote it), read once, at most ``limit`` of them.

    ``kind`` names the file in messages ("trajectory"); ``missing``/``folder``/``too_large`` replace the
    default messages for a missing path, a folder and a file beyond ``limit``. ``on_chunk(chunk, bytes so far)`` sees each chunk as it
    arrives and may raise to stop reading. Raises ``InputError`` naming the file."""
    shown = os.fspath(path)
    try:
        fd = os.open(shown, os.O_RDONLY | getattr(os, "O_CLOEXEC", 0))
    except FileNotFoundError:
        raise InputError(missing or InputError.INPUT_MISSING.format(kind=kind, path=shown)) from None
    except IsADirectoryError:
        raise InputError(folder or InputError.INPUT_FOLDER.format(kind=kind, path=shown)) from None
    except (OSError, ValueError) as e:
        reason = getattr(e, "strerror", None) or str(e)
        raise InputError(InputError.INPUT_UNREADABLE.format(kind=kind, path=shown, reason=reason)) from None
    chunks, total = [], 0
    try:
        while True:
            try:
                chunk = os.read(fd, min(CHUNK, limit + 1 - total))
            except IsADirectoryError:
                raise InputError(folder or InputError.INPUT_FOLDER.format(kind=kind, path=shown)) from None
            except OSError as e:
                if e.errno == errno.EINTR:
                    continue
                raise InputError(
                    InputError.INPUT_UNREADABLE.format(kind=kind, path=shown, reason=e.strerror or str(e))
                ) from None
            if not chunk:
                break
            total += len(chunk)
            if total > limit:
                raise InputError(too_large or InputError.INPUT_TOO_LARGE.format(kind=kind, path=shown, limit=limit))
            chunks.append(chunk)
            if on_chunk is not None:
                on_chunk(chunk, total)
    finally:
        os.close(fd)
    return b"".join(chunks)


def decode_text(data: bytes, path, kind: str) -> str:
    """``data`` as UTF-8 text (a byte-order mark dropped); ``InputError`` naming the file and the line
    of the first byte that is not (e.g. a binary file given as C source)."""
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as e:
        line = data[: e.start].count(b"\n") + 1
        raise InputError(
            InputError.INPUT_NOT_TEXT.format(kind=kind, path=os.fspath(path), line=line, offset=e.start)
        ) from None
