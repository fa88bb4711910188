"""The report's result cache: a section is recomputed only when its code or its declared inputs changed.

A section's key is the SHA-256 of:

- the package's version (``system.results.package_version``): every file of the installed ``stewart_drake``
  package, sources and data alike, by relative path and content, and the versions of Python and of the
  libraries that draw or compute. Any edit of the package recomputes every section: simple and sound, where a
  scan of the imports would miss code reached by a computed name; and the entry's ``FORMAT``;
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
``c_build.cache_dir() / "report"`` (``$STEWART_DRAKE_CACHE``; ``system.results``), written atomically; a section
whose analysis raised is not stored (the failure may be transient); an unreadable entry counts as a miss. Where
the cache folder cannot be used the report runs without it.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

from stewart_drake.system import results
from stewart_drake.system.results import PACKAGE, package_version

FORMAT = 4  # bump when the entry's layout or the key's recipe changes (4: the package version in system.results)
KIND = "report"


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
    h.update(f"|format={FORMAT}|{analysis.name}|{bool(quick)}".encode())
    if outside:
        h.update(b"|script|" + path_digest(path))
        for name in declared:
            h.update(f"|input|{name}|".encode() + path_digest(path.parent / name))
    h.update(b"|subject|" + (b"presets" if subject is None else subject.key().encode()))
    for var in ("STEWART_DRAKE_CC", "CC"):
        h.update(f"|{var}={os.environ.get(var, '')}".encode())
    return h.hexdigest()


def load(key: str | None):
    """The cached ``Section`` of ``key``, or None (no key, absent, unreadable, or the cache unusable)."""
    return results.load(KIND, key)


def store(key: str | None, section) -> None:
    """Write ``section`` under ``key`` (atomically: a reader never sees half an entry); no key: nothing."""
    results.store(KIND, key, section)
