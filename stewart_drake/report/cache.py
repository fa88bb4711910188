"""The report's result cache: a section is recomputed only when its inputs or its code changed.

A section's key is the SHA-256 of: its code version (``code_version``: the package sources its analysis reaches
by imports, ``code_deps.closure``, and every data file of the installed ``stewart_drake`` package, by relative
path and content, plus the versions of Python and of the libraries that draw or compute, ``DEPENDENCIES``), the
analysis' name, the content of its script when it lies outside the package, the ``quick`` flag, and the
compiler the C builds would use (``$STEWART_DRAKE_CC``, ``$CC``: the compiled firmware is an input of the
sections that run it). The analyses read only the built-in presets (package files, so part of the code version)
and their own fixed seeds. So an edit of a module recomputes the sections whose analyses import it, directly or
not, and no other. A script of the user's may read files of its own: each entry carries the files its section
read outside the package (``report.reads``), and is given back only while they are unchanged.

The entry is the pickled ``Section`` (its text, tables, figures' PNG bytes, checks, warnings, original run
time), so a hit gives back the section exactly as it was computed. Entries live in
``c_build.cache_dir() / "report"`` (``$STEWART_DRAKE_CACHE``), written atomically; a section whose analysis
raised is not stored (the failure may be transient); an unreadable entry counts as a miss. Where the cache
folder cannot be used the report runs without it.
"""

from __future__ import annotations

import hashlib
import os
import pickle
import sys
import tempfile
from functools import cache
from pathlib import Path

from stewart_drake.report import reads

PACKAGE = Path(__file__).resolve().parents[1]
FORMAT = 2  # bump when the entry's layout changes (2: a section carries the files it read, ``report.reads``)
# the libraries whose versions can change a section's numbers or figures (part of the code version)
DEPENDENCIES = ("drake", "numpy", "scipy", "matplotlib", "pymoo", "python-flint", "cffi")


def _digest(p: Path) -> bytes:
    """SHA-256 of file ``p``'s bytes."""
    return hashlib.sha256(p.read_bytes()).digest()


_package_digest = cache(_digest)  # a package file's: read once per process (the package does not change under it)


@cache
def data_version(root: Path = PACKAGE) -> str:
    """SHA-256 (hex) of every package file under ``root`` but the Python sources and the bytecode caches
    (relative path and bytes, in sorted order: C files, presets, grammars, tables), of the Python version and
    of the ``DEPENDENCIES``' versions: an edit of any data, or an upgrade, changes every section's key."""
    import numpy as np

    h = hashlib.sha256()
    for p in sorted(
        q for q in root.rglob("*") if q.is_file() and "__pycache__" not in q.parts and q.suffix not in (".py", ".pyc")
    ):
        h.update(str(p.relative_to(root)).encode() + b"\0" + _package_digest(p))
    from importlib.metadata import PackageNotFoundError, version

    for dist in DEPENDENCIES:
        try:
            h.update(f"|{dist}={version(dist)}".encode())
        except PackageNotFoundError:
            h.update(f"|{dist}=absent".encode())
    h.update(f"{sys.version}|{np.__version__}|{FORMAT}".encode())
    return h.hexdigest()


@cache
def code_version(path: Path | None, root: Path = PACKAGE) -> str:
    """SHA-256 (hex) of the code a section of the analysis script at ``path`` runs: ``data_version`` and the
    package sources its imports reach (``code_deps.closure``; every package source when ``path`` is None)."""
    from stewart_drake.report.code_deps import all_sources, closure

    sources = closure(path, root) if path is not None else all_sources(root)
    h = hashlib.sha256(data_version(root).encode())
    for p in sources:
        h.update(str(p.relative_to(root)).encode() + b"\0" + _package_digest(p))
    return h.hexdigest()


def section_key(analysis, quick: bool) -> str:
    """The cache key (hex) of ``analysis``' section (see the module docstring)."""
    path = Path(analysis.path).resolve() if analysis.path is not None else None
    h = hashlib.sha256(code_version(path).encode())
    h.update(f"|{analysis.name}|{bool(quick)}".encode())
    if path is not None and PACKAGE not in path.parents:
        h.update(b"|script|" + _digest(path))
    for var in ("STEWART_DRAKE_CC", "CC"):
        h.update(f"|{var}={os.environ.get(var, '')}".encode())
    return h.hexdigest()


def folder() -> Path | None:
    """The cache folder (created), or None where it cannot be used."""
    from stewart_drake.core.c_build import CacheUnavailable, cache_dir

    try:
        d = cache_dir() / "report"
        d.mkdir(parents=True, exist_ok=True)
        return d
    except (CacheUnavailable, OSError):
        return None


def load(key: str):
    """The cached ``Section`` of ``key``, or None (absent, unreadable, a file it read changed, or the cache
    unusable)."""
    d = folder()
    if d is None:
        return None
    try:
        with open(d / f"{key}.pickle", "rb") as f:
            section = pickle.load(f)
    except FileNotFoundError:
        return None
    except Exception:  # noqa: BLE001 - a truncated or foreign entry is a miss, recomputed and rewritten
        return None
    return section if reads.unchanged(section.inputs) else None  # a file it read was edited or removed


def store(key: str, section) -> None:
    """Write ``section`` under ``key`` (atomically: a reader never sees half an entry)."""
    d = folder()
    if d is None:
        return
    fd, tmp = tempfile.mkstemp(dir=d, suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            pickle.dump(section, f, protocol=pickle.HIGHEST_PROTOCOL)
        os.replace(tmp, d / f"{key}.pickle")
    except OSError:
        Path(tmp).unlink(missing_ok=True)
