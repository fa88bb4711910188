"""The report's result cache: a section is recomputed only when its code or its declared inputs changed.

A section's key is the SHA-256 of:

- the package's version (``package_version``): every file of the installed ``stewart_drake`` package, sources
  and data alike, by relative path and content, and the versions of Python and of the libraries that draw or
  compute (``DEPENDENCIES``). Any edit of the package recomputes every section: simple and sound, where a
  scan of the imports would miss code reached by a computed name;
- the analysis' name, the ``quick`` flag and the compiler the C builds would use (``$STEWART_DRAKE_CC``,
  ``$CC``: the compiled firmware is an input of the sections that run it);
- the subject's declared inputs (``report.subject.Subject.key``: the content of the user's platform or
  machine file, or the preset's name, whose file is package data);
- for an analysis script outside the package: its own text and the content of the files and folders it declares
  in ``INPUTS`` (a literal list of paths relative to the script, read from its source: ``report.metadata``). A
  folder's key is its listing and its files' content. A script that declares no ``INPUTS`` may read anything:
  its section is never cached (``section_key`` gives None).

The package's own analyses read only package files, their subject and their own fixed seeds. Nothing a section
reads is recorded while it runs: what is not declared is not an input, and a section that could read something
undeclared is not cached.

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
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

import numpy as np

from stewart_drake.system.c_build import CacheUnavailable, cache_dir

PACKAGE = Path(__file__).resolve().parents[1]
FORMAT = 3  # bump when the entry's layout or the key's recipe changes (3: declared inputs only)
# the libraries whose versions can change a section's numbers or figures (part of the package version)
DEPENDENCIES = ("drake", "numpy", "scipy", "matplotlib", "pymoo", "python-flint", "cffi")


@cache
def package_version(root: Path = PACKAGE) -> str:
    """SHA-256 (hex) of every file under ``root`` but the bytecode caches (relative path and bytes, in sorted
    order), of the Python version and of the ``DEPENDENCIES``' versions. Read once per process: the installed
    package does not change under a running report."""
    h = hashlib.sha256()
    for p in sorted(q for q in root.rglob("*") if q.is_file() and "__pycache__" not in q.parts and q.suffix != ".pyc"):
        h.update(str(p.relative_to(root)).encode() + b"\0" + hashlib.sha256(p.read_bytes()).digest())
    for dist in DEPENDENCIES:
        try:
            h.update(f"|{dist}={version(dist)}".encode())
        except PackageNotFoundError:
            h.update(f"|{dist}=absent".encode())
    h.update(f"{sys.version}|{np.__version__}|{FORMAT}".encode())
    return h.hexdigest()


def path_digest(path: Path) -> bytes:
    """SHA-256 of what ``path`` holds now, read through symbolic links: a file's bytes; a folder's listing
    (every file and folder below it, relative names, sorted) and its files' bytes; a marker when absent."""
    h = hashlib.sha256()
    if path.is_file():
        h.update(b"file\0" + path.read_bytes())
    elif path.is_dir():
        h.update(b"folder\0")
        seen = {os.path.realpath(path)}
        for root, dirs, files in os.walk(path, followlinks=True):
            dirs[:] = sorted(d for d in dirs if os.path.realpath(Path(root, d)) not in seen)  # no link cycles
            seen.update(os.path.realpath(Path(root, d)) for d in dirs)
            for name in sorted(files):
                p = Path(root, name)
                h.update(str(p.relative_to(path)).encode() + b"\0" + path_digest(p))
            for name in dirs:
                h.update(str(Path(root, name).relative_to(path)).encode() + b"/\0")
    else:
        h.update(b"absent")
    return h.digest()


def section_key(analysis, quick: bool, subject=None) -> str | None:
    """The cache key (hex) of ``analysis``' section of ``subject`` (None: the presets), or None when the section
    must not be cached: a script outside the package that declares no ``INPUTS`` (see the module docstring)."""
    path = Path(analysis.path).resolve() if analysis.path is not None else None
    outside = path is None or PACKAGE not in path.parents
    declared = getattr(analysis, "inputs", None)
    if outside and declared is None:
        return None
    h = hashlib.sha256(package_version().encode())
    h.update(f"|{analysis.name}|{bool(quick)}".encode())
    if outside:
        h.update(b"|script|" + path_digest(path))
        for name in declared:
            h.update(f"|input|{name}|".encode() + path_digest(path.parent / name))
    h.update(b"|subject|" + (b"presets" if subject is None else subject.key().encode()))
    for var in ("STEWART_DRAKE_CC", "CC"):
        h.update(f"|{var}={os.environ.get(var, '')}".encode())
    return h.hexdigest()


def folder() -> Path | None:
    """The cache folder (created), or None where it cannot be used."""
    try:
        d = cache_dir() / "report"
        d.mkdir(parents=True, exist_ok=True)
        return d
    except (CacheUnavailable, OSError):
        return None


def load(key: str | None):
    """The cached ``Section`` of ``key``, or None (no key, absent, unreadable, or the cache unusable)."""
    d = folder() if key is not None else None
    if d is None:
        return None
    try:
        with open(d / f"{key}.pickle", "rb") as f:
            return pickle.load(f)
    except FileNotFoundError:
        return None
    except Exception:  # noqa: BLE001 - a truncated or foreign entry is a miss, recomputed and rewritten
        return None


def store(key: str | None, section) -> None:
    """Write ``section`` under ``key`` (atomically: a reader never sees half an entry); no key: nothing."""
    d = folder() if key is not None else None
    if d is None:
        return
    fd, tmp = tempfile.mkstemp(dir=d, suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            pickle.dump(section, f, protocol=pickle.HIGHEST_PROTOCOL)
        os.replace(tmp, d / f"{key}.pickle")
    except OSError:
        Path(tmp).unlink(missing_ok=True)
