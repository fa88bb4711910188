"""The files a report section reads besides the package and the libraries: recorded while it is built, so that the
result cache (``report.cache``) gives a section back only while they are unchanged — a user's analysis that reads
its own platform file is computed again when that file is edited.

Recorded: every file opened for reading through Python (audit event ``open``: ``open``, ``io.open``,
``os.open``, module imports) inside ``recording()``, in the process that builds the section and in those that run
its parts (``report.parts``). Not recorded: what the cache keys on already (the package's files, the libraries
under the interpreter's prefixes and its user site, the cache folder), the kernel's pseudo-files, files gone by the
end of the build (temporary), and files a C library opens by itself.
"""

from __future__ import annotations

import hashlib
import os
import site
import sys
from contextlib import contextmanager
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1]
_RECORDINGS: list[set] = []  # the paths opened during each open recording of this process
_HOOKED = [False]  # an audit hook cannot be removed: it is added once and idle outside a recording


def _on_audit(event: str, args: tuple) -> None:
    """Add a path opened for reading to every open recording."""
    if event != "open" or not _RECORDINGS:
        return
    path, mode, flags = args
    if path is None or isinstance(path, int):  # a file descriptor: opened earlier
        return
    writing = any(c in mode for c in "wax+") if isinstance(mode, str) else bool(flags & (os.O_WRONLY | os.O_RDWR))
    if not writing:
        name = os.path.abspath(os.fsdecode(path))
        for paths in _RECORDINGS:
            paths.add(name)


@contextmanager
def recording():
    """The set of the absolute paths opened for reading inside the block (filled as they are opened)."""
    if not _HOOKED[0]:
        sys.addaudithook(_on_audit)
        _HOOKED[0] = True
    paths: set[str] = set()
    _RECORDINGS.append(paths)
    try:
        yield paths
    finally:
        _RECORDINGS.remove(paths)


def _keyed_elsewhere() -> list[Path]:
    """Folders whose files the cache keys on otherwise (or never depend on a run's inputs)."""
    from stewart_drake.core.c_build import CacheUnavailable, cache_dir

    folders = {sys.prefix, sys.base_prefix, sys.exec_prefix, site.getuserbase(), "/proc", "/sys", "/dev"}
    try:
        folders.add(str(cache_dir()))
    except CacheUnavailable:
        pass
    return [PACKAGE, *(Path(f).resolve() for f in folders)]


def digests(paths) -> dict[str, str]:
    """``{path: SHA-256 hex}`` of the recorded ``paths`` that are files now and lie outside ``_keyed_elsewhere``."""
    skip = _keyed_elsewhere()
    out = {}
    for name in sorted(paths):
        p = Path(name).resolve()
        if p.is_file() and not any(p == f or f in p.parents for f in skip):
            out[str(p)] = hashlib.sha256(p.read_bytes()).hexdigest()
    return out


def unchanged(inputs: dict[str, str]) -> bool:
    """Whether every file of ``inputs`` (``digests``) still has those bytes."""
    for name, digest in inputs.items():
        try:
            if hashlib.sha256(Path(name).read_bytes()).hexdigest() != digest:
                return False
        except OSError:
            return False
    return True
