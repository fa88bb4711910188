"""Results kept on disk between runs, under a key that changes whenever the code or an input could change them.

A key starts from the package's version (``package_version``): every file of the installed ``stewart_drake``
package, sources and data alike, by relative path and content, and the versions of Python and of the libraries
that compute or draw (``DEPENDENCIES``). Any edit of the package is therefore a miss everywhere: simple and
sound, where a scan of the imports would miss code reached by a computed name. The caller adds its inputs
(``key``: bytes, e.g. a pickle of the exact objects; two different values never pickle alike, so an input that
changes is always a miss).

Entries are pickles in ``c_build.cache_dir() / KIND`` (``$STEWART_DRAKE_CACHE``), written atomically (a reader
never sees half an entry); an unreadable entry is a miss, recomputed and rewritten; where the cache folder cannot
be used, nothing is kept.
"""

from __future__ import annotations

import hashlib
import os
import pickle
import sys
import tempfile
from functools import cache
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import Any

import numpy as np

from stewart_drake.system.c_build import CacheUnavailable, cache_dir

PACKAGE = Path(__file__).resolve().parents[1]
# the libraries whose versions can change a result's numbers or figures (part of the package version)
DEPENDENCIES = ("drake", "numpy", "scipy", "matplotlib", "pymoo", "python-flint", "cffi")


@cache
def package_version(root: Path = PACKAGE) -> str:
    """SHA-256 (hex) of every file under ``root`` but the bytecode caches (relative path and bytes, in sorted
    order), of the Python version and of the ``DEPENDENCIES``' versions. Read once per process: the installed
    package does not change under a running command."""
    h = hashlib.sha256()
    for p in sorted(q for q in root.rglob("*") if q.is_file() and "__pycache__" not in q.parts and q.suffix != ".pyc"):
        h.update(str(p.relative_to(root)).encode() + b"\0" + hashlib.sha256(p.read_bytes()).digest())
    for dist in DEPENDENCIES:
        try:
            h.update(f"|{dist}={version(dist)}".encode())
        except PackageNotFoundError:
            h.update(f"|{dist}=absent".encode())
    h.update(f"{sys.version}|{np.__version__}".encode())
    return h.hexdigest()


def key(*inputs: bytes) -> str:
    """The key (hex) of a result of ``inputs`` computed by this package version."""
    h = hashlib.sha256(package_version().encode())
    for part in inputs:
        h.update(len(part).to_bytes(8, "little") + part)
    return h.hexdigest()


def folder(kind: str) -> Path | None:
    """The cache folder of ``kind`` (created), or None where it cannot be used."""
    try:
        d = cache_dir() / kind
        d.mkdir(parents=True, exist_ok=True)
        return d
    except (CacheUnavailable, OSError):
        return None


def load(kind: str, key: str | None) -> Any:
    """The result stored under ``key``, or None (no key, absent, unreadable, or the cache unusable)."""
    d = folder(kind) if key is not None else None
    if d is None:
        return None
    try:
        with open(d / f"{key}.pickle", "rb") as f:
            return pickle.load(f)
    except FileNotFoundError:
        return None
    except Exception:  # noqa: BLE001 - a truncated or foreign entry is a miss, recomputed and rewritten
        return None


def store(kind: str, key: str | None, value: Any) -> None:
    """Write ``value`` under ``key`` (atomically); no key, or the cache unusable: nothing."""
    d = folder(kind) if key is not None else None
    if d is None:
        return
    fd, tmp = tempfile.mkstemp(dir=d, suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            pickle.dump(value, f, protocol=pickle.HIGHEST_PROTOCOL)
        os.replace(tmp, d / f"{key}.pickle")
    except OSError:
        Path(tmp).unlink(missing_ok=True)
