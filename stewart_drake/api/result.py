"""The base of every result object: ``to_dict()`` as plain Python (lists, floats, bools, None, str)."""

from __future__ import annotations

import numpy as np


def plain(x):
    """``x`` with numpy arrays and scalars (at any depth in dicts, lists and tuples) turned into Python lists
    and numbers: what ``json.dumps`` writes."""
    if isinstance(x, dict):
        return {k: plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [plain(v) for v in x]
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, np.generic):
        return x.item()
    return x


class Result:
    """A result of the public API. ``to_dict()`` gives its numbers as plain Python in SI units: the
    command's ``--json`` output is this dict with lengths and angles converted to the command's units."""

    def to_dict(self) -> dict:
        """The result as a JSON-ready dict (SI units)."""
        return plain(self._fields())

    def _fields(self) -> dict:
        raise NotImplementedError  # each result class defines its fields (a programming error otherwise)

    def __repr__(self) -> str:
        keys = ", ".join(k for k in self._fields())
        return f"{type(self).__name__}({keys})"
