"""Strict JSON output: what every command prints or writes with ``--json`` / ``summary.json``."""

from __future__ import annotations

import json
import math

import numpy as np


def dumps_strict(obj) -> str:
    """Strict JSON (RFC 8259: no NaN/Infinity). numpy values become lists/numbers; a non-finite number
    becomes ``null`` and the path to it is listed under ``"non_finite"`` (added to a top-level dict)
    so that a reader knows why."""
    bad: list[str] = []
    clean = _strict(obj, "", bad)
    if bad and isinstance(clean, dict):
        clean["non_finite"] = {"paths": bad, "reason": "not a finite number (written as null)"}
    return json.dumps(clean, indent=2, allow_nan=False)


def _strict(x, where: str, bad: list):
    if isinstance(x, np.ndarray):
        x = x.tolist()
    elif isinstance(x, np.generic):
        x = x.item()
    if isinstance(x, dict):
        return {str(k): _strict(v, f"{where}.{k}" if where else str(k), bad) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_strict(v, f"{where}[{i}]", bad) for i, v in enumerate(x)]
    if isinstance(x, float) and not math.isfinite(x):
        bad.append(where or "value")
        return None
    if x is None or isinstance(x, (bool, int, float, str)):
        return x
    if hasattr(x, "tolist"):
        return _strict(x.tolist(), where, bad)
    return str(x)
