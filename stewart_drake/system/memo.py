"""A small per-process memo keyed by a digest of its inputs: the speed-ups that remember a computed object
(a feed-forward table, a built Diagram) for the next run of the same process. Same inputs, same function:
the same object. Only the last ``size`` are kept, the least recently used dropped first."""

from __future__ import annotations

import hashlib
from collections import OrderedDict
from collections.abc import Callable
from typing import Any


def digest(*parts: bytes) -> bytes:
    """A 32-byte BLAKE2b digest of ``parts`` in order (the key of a memo entry)."""
    h = hashlib.blake2b(digest_size=32)
    for p in parts:
        h.update(p)
    return h.digest()


class Memo:
    """The last ``size`` values of this process, by key (``digest`` of the inputs)."""

    def __init__(self, size: int):
        self.size = size
        self._values: OrderedDict[bytes, Any] = OrderedDict()

    def get(self, key: bytes, make: Callable[[], Any]) -> Any:
        """The value remembered under ``key``, or ``make()`` remembered under it."""
        value = self._values.get(key)
        if value is None:
            value = make()
            self._values[key] = value
            if len(self._values) > self.size:
                self._values.popitem(last=False)
        else:
            self._values.move_to_end(key)
        return value

    def clear(self) -> None:
        self._values.clear()
