"""Output safety: results appear complete or not at all, and no file the tool did not write is ever
overwritten or deleted.

Policy (README "Output folders"):

- The manifest ``.stewart-drake-manifest.json`` of an output folder records, per file, the command that
  wrote it and the SHA-256 of its content. A file is *this command's* only when the manifest lists it
  under this command and its content still has that hash; a file another command wrote belongs to that
  command, and a file that is not listed, was changed since, is a symbolic link or is not a regular
  file belongs to the user.
- An output folder (``--out DIR``) must be new, empty, or hold only this command's files (and those of
  its ``companions``: ``montecarlo --replay K`` beside its study). Anything else is refused with exit 2
  *before* any work is done, naming a file; so are ``.``, an ancestor of the working directory, the home
  folder, ``/``, a symbolic link, and a folder whose manifest is damaged (a damaged manifest is not an
  empty folder).
- ``--force`` writes beside other files: this command's earlier files are replaced or removed, the
  others are never overwritten nor deleted (a name clash is refused, naming the file).
- Nothing is followed through a symbolic link inside the folder, and nothing is deleted unless its
  content hash shows that this command wrote it.
- The folder is built in a temporary sibling ``.DIR.sd-tmp-PID-XXXXXXXX`` holding a marker file
  (``.sd-tmp``, with the PID and the token of its name) and swapped in with one rename, so a reader
  sees the old result or the new one, never a mix. A temporary folder is removed on success, error and
  Ctrl-C; one left by a killed run is removed by the next run writing beside it only if its marker
  says so and its process is gone (a user's entry that merely looks like one is never touched).
- A single output file (``model --write``, ``leg sdf --write``, ``compile -o``) is written in such a
  temporary folder and renamed into place; an existing file is replaced only if it is this command's.
- An error while writing (disk full, ...) is one line naming the option and the file; nothing is left.

Folders are created with the usual permissions (``0o777`` less the umask, 0o755 typically).
"""

from __future__ import annotations

import ctypes
import errno
import fcntl
import json
import os
import re
import stat
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

from stewart_drake import __version__
from stewart_drake.errors import OutputError

MANIFEST = ".stewart-drake-manifest.json"
MARKER = ".sd-tmp"
MANIFEST_FORMAT = 2
_TMP_RE = re.compile(r"^\.(?P<name>.+)\.sd-tmp-(?P<pid>\d+)-(?P<token>[0-9a-f]{8})$")
_RENAME_EXCHANGE = 2
_CHUNK = 1 << 20

# The command that writes (``stewart-drake workspace``: "workspace"); set by the CLI for each run.
_command = "stewart-drake"


def set_command(name: str) -> None:
    """Name the command whose outputs the following writes are (recorded in manifests)."""
    global _command
    _command = str(name)


def current_command() -> str:
    """The command named by ``set_command`` ("stewart-drake" for library use)."""
    return _command


# ----------------------------------------------------------------------------------------------
# Manifests.


class DamagedManifest(Exception):
    """A manifest file that is present but not one this tool writes (internal; becomes OutputError)."""


def load_manifest(folder) -> dict[str, dict] | None:
    """``{relative path: {"command", "sha256"[, "prefix"]}}`` recorded in ``folder``'s manifest; None when
    there is none; ``DamagedManifest`` when one is there but not valid (never read as "empty")."""
    p = Path(folder) / MANIFEST
    try:
        st = os.lstat(p)
    except FileNotFoundError:
        return None
    except OSError as e:
        raise DamagedManifest(e.strerror or str(e)) from None
    if not stat.S_ISREG(st.st_mode):
        raise DamagedManifest("not a regular file")
    if st.st_size > 64 << 20:
        raise DamagedManifest("larger than 64 MiB")
    try:
        data = json.loads(_read_nofollow(p).decode("utf-8"))
    except (OSError, ValueError) as e:
        raise DamagedManifest(f"not JSON ({str(e).splitlines()[0][:80]})") from None
    if not isinstance(data, dict) or data.get("tool") != "stewart-drake":
        raise DamagedManifest("not a stewart-drake manifest")
    files = data.get("files")
    if isinstance(files, list) and all(isinstance(f, str) for f in files):
        # format 1 (no hashes): nothing in it can be verified, so nothing is this tool's to replace
        return {}
    if not isinstance(files, dict):
        raise DamagedManifest("no 'files' table")
    out = {}
    for rel, entry in files.items():
        ok = (
            isinstance(entry, dict)
            and isinstance(entry.get("command"), str)
            and isinstance(entry.get("sha256"), str)
            and re.fullmatch(r"[0-9a-f]{64}", entry["sha256"])
            and (entry.get("prefix") is None or (type(entry["prefix"]) is int and entry["prefix"] >= 0))
        )
        if not ok or not _is_relative_inside(rel):
            raise DamagedManifest(f"entry {str(rel)[:60]!r} is malformed")
        out[rel] = entry
    return out


def read_manifest(folder) -> list[str] | None:
    """The relative file paths the manifest in ``folder`` lists, or None when there is no valid one."""
    try:
        m = load_manifest(folder)
    except DamagedManifest:
        return None
    return None if m is None else sorted(m)


def _write_manifest(folder: Path, entries: dict[str, dict]) -> None:
    data = {
        "tool": "stewart-drake",
        "version": __version__,
        "format": MANIFEST_FORMAT,
        "files": dict(sorted(entries.items())),
    }
    _write_file_atomic(folder / MANIFEST, (json.dumps(data, indent=2) + "\n").encode("utf-8"))


@contextmanager
def commit_lock(folder: Path) -> Iterator[None]:
    """Writers of one folder change its content and manifest one at a time: an exclusive ``flock`` on the
    folder's parent directory (held for the commit only; no lock file is left behind). Without it two
    concurrent commits could interleave their checks and renames, and the manifest name the wrong writer."""
    fd = os.open(Path(folder).parent, os.O_RDONLY | os.O_DIRECTORY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)  # closing the descriptor releases the lock


_held: dict[str, list[int]] = {}  # folder -> [descriptor, depth] of the run locks this process holds


@contextmanager
def run_lock(folder, *, option: str = "--out", typed: str | None = None) -> Iterator[None]:
    """Hold ``folder`` for a run's lifetime: an exclusive, non-blocking ``flock`` on the folder itself (made here if
    absent, and removed again at the end if still empty). A second run into the folder while this one holds it is
    refused with ``OutputError.BUSY`` naming ``option`` and ``typed`` (the path as the user wrote it). Re-entrant
    within a process (a command holding the folder calls an API that holds it too). The folder swapped in at the
    end (``OutputFolder.writing``) is a new directory: a run started after that commit holds that one."""
    folder = Path(os.path.abspath(folder))
    key = str(folder)
    if key in _held:
        _held[key][1] += 1
        try:
            yield
        finally:
            _held[key][1] -= 1
        return
    made = not folder.exists()
    folder.mkdir(parents=True, exist_ok=True)
    fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        os.close(fd)
        raise OutputError(OutputError.BUSY.format(option=option, typed=typed or str(folder))) from None
    _held[key] = [fd, 1]
    try:
        yield
    finally:
        del _held[key]
        os.close(fd)  # closing the descriptor releases the lock
        if made:
            try:
                os.rmdir(folder)  # only if nothing was written there
            except OSError:
                pass


def claim_in_manifest(folder, names, *, prefix: bool = False, command: str | None = None) -> None:
    """Record ``names`` (relative paths the caller has just written in ``folder``) as this command's.
    ``prefix``: the file is an append-only journal, verified by the hash of the bytes written so far
    (a resumable work file that grows after the claim)."""
    folder = Path(folder)
    with commit_lock(folder):
        entries = load_manifest(folder) or {}
        for rel in names:
            digest, size = _hash_file(folder / rel)
            entries[rel] = {"command": command or _command, "sha256": digest} | ({"prefix": size} if prefix else {})
        _write_manifest(folder, entries)


def _is_relative_inside(rel) -> bool:
    if not isinstance(rel, str) or not rel or "\0" in rel:
        return False
    p = Path(rel)
    return not p.is_absolute() and ".." not in p.parts and rel != MANIFEST


def _read_nofollow(path: Path) -> bytes:
    fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise OSError(errno.EINVAL, "not a regular file")
        chunks = []
        while chunk := os.read(fd, _CHUNK):
            chunks.append(chunk)
        return b"".join(chunks)
    finally:
        os.close(fd)


def _remove_tree(path: Path, ignore_errors: bool = False) -> None:
    """``shutil.rmtree``: fd-based, removes the links inside a folder and never follows them."""
    # deferred: every command imports this module at start, and only a command that writes files removes any
    import shutil

    shutil.rmtree(path, ignore_errors=ignore_errors)


def _hash_file(path: Path, limit: int | None = None) -> tuple[str, int]:
    """``(sha256 hex, bytes hashed)`` of a regular file (never through a symbolic link); ``limit``: only
    its first ``limit`` bytes (``OSError`` if it is shorter)."""
    fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise OSError(errno.EINVAL, "not a regular file", str(path))
        # deferred: every command imports this module at start (the command line records its name here), and
        # only a command that writes files hashes them
        import hashlib

        h, n = hashlib.sha256(), 0
        while limit is None or n < limit:
            chunk = os.read(fd, _CHUNK if limit is None else min(_CHUNK, limit - n))
            if not chunk:
                break
            h.update(chunk)
            n += len(chunk)
        if limit is not None and n < limit:
            raise OSError(errno.EINVAL, "shorter than recorded", str(path))
        return h.hexdigest(), n
    finally:
        os.close(fd)


def _no_link_between(root: Path, rel: str) -> bool:
    """True when no component of ``root/rel`` below ``root`` is a symbolic link and every folder on the
    way is a real folder (or does not exist yet: then nothing lies beyond it)."""
    p = root
    for part in Path(rel).parts[:-1]:
        p = p / part
        try:
            if not stat.S_ISDIR(os.lstat(p).st_mode):
                return False
        except FileNotFoundError:
            return True
        except OSError:
            return False
    return True


def _verified(root: Path, rel: str, entry: dict) -> bool:
    """The file ``root/rel`` is a regular file, reached through no link, whose content matches ``entry``."""
    if not _no_link_between(root, rel):
        return False
    try:
        digest, _ = _hash_file(root / rel, entry.get("prefix"))
    except OSError:
        return False
    return digest == entry["sha256"]


def _entries_under(folder: Path) -> list[str]:
    """Relative POSIX paths of every non-folder entry (symbolic links included, never followed), and of
    every empty folder (ending in "/"), under ``folder`` (the manifest excluded)."""
    out = []
    for root, dirs, files in os.walk(folder):  # followlinks=False: a linked folder is an entry, not entered
        if not dirs and not files and root != str(folder):
            out.append(Path(root).relative_to(folder).as_posix() + "/")
        for f in files + [d for d in dirs if os.path.islink(os.path.join(root, d))]:
            rel = Path(os.path.join(root, f)).relative_to(folder).as_posix()
            if rel != MANIFEST:
                out.append(rel)
    return sorted(out)


@dataclass
class Survey:
    """Who owns each entry of an output folder (``survey``)."""

    manifest: dict[str, dict] | None
    own: list[str] = field(default_factory=list)  # this command's, verified
    kept: list[str] = field(default_factory=list)  # a companion command's, verified: kept beside
    other: dict[str, str] = field(default_factory=dict)  # another command's, verified: {path: command}
    user: list[str] = field(default_factory=list)  # not listed, changed since, a link, or not a file


def survey(folder: Path, command: str, companions: tuple[str, ...] = ()) -> Survey:
    """Classify every entry of ``folder`` (see the module docstring); ``DamagedManifest`` passes through."""
    manifest = load_manifest(folder)
    s = Survey(manifest)
    for rel in _entries_under(folder):
        entry = (manifest or {}).get(rel)
        if entry is None or not _verified(folder, rel, entry):
            s.user.append(rel)
        elif entry["command"] == command:
            s.own.append(rel)
        elif any(entry["command"] == c or entry["command"].startswith(c + " ") for c in companions):
            s.kept.append(rel)
        else:
            s.other[rel] = entry["command"]
    return s


# ----------------------------------------------------------------------------------------------
# Checking a destination before the work.


def _refused_location(path: Path, typed: str, option: str) -> None:
    try:
        cwd = Path.cwd().resolve()
    except OSError:  # the working directory was removed: nothing to protect there
        cwd = Path(path.anchor)
    home = Path.home().resolve()
    if path == Path(path.anchor) or path == home or path == cwd or path in cwd.parents:
        what = (
            "the root folder"
            if path == Path(path.anchor)
            else (
                "your home folder"
                if path == home
                else "the working directory"
                if path == cwd
                else "a parent of the working directory"
            )
        )
        raise OutputError(OutputError.REFUSED_PLACE.format(option=option, typed=typed, what=what))


def _probe_writable(path: Path, typed: str, option: str) -> None:
    """Raise ``OutputError`` unless a folder can be created beside (or at) ``path``: tried for real in
    the nearest existing ancestor (mkdir + rmdir), so /proc, read-only mounts and permissions count."""
    parent, shown = path.parent, Path(typed).parent
    while not parent.exists() and not parent.is_symlink():
        parent, shown = parent.parent, shown.parent
    if not parent.is_dir():
        part = str(shown) if str(shown) not in ("", ".") else str(parent)
        raise OutputError(OutputError.NOT_A_FOLDER.format(option=option, typed=typed, part=part))
    probe = parent / f".{path.name or 'out'}.sd-tmp-{os.getpid()}-{os.urandom(4).hex()}"
    try:
        os.mkdir(probe)
        os.rmdir(probe)
    except OSError as e:
        raise OutputError(
            OutputError.UNWRITABLE.format(option=option, typed=typed, reason=e.strerror or str(e))
        ) from None


def clean_stale_temps(path: Path) -> list[Path]:
    """Remove temporary siblings ``.NAME.sd-tmp-PID-XXXXXXXX`` of ``path`` left by runs that were killed:
    real folders (not links) holding this tool's marker, whose PID and token match the name and whose
    process no longer exists. Return what was removed."""
    removed = []
    try:
        entries = list(Path(path).parent.iterdir())
    except OSError:
        return removed
    for e in entries:
        m = _TMP_RE.match(e.name)
        if not m or m["name"] != Path(path).name or _pid_alive(int(m["pid"])):
            continue
        try:
            if not stat.S_ISDIR(os.lstat(e).st_mode):
                continue
            mark = json.loads(_read_nofollow(e / MARKER).decode("utf-8"))
        except (OSError, ValueError):
            continue
        if not isinstance(mark, dict) or mark.get("pid") != int(m["pid"]) or mark.get("token") != m["token"]:
            continue
        _remove_tree(e, ignore_errors=True)  # fd-based: removes links inside, never follows them
        removed.append(e)
    return removed


def _pid_alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    except OverflowError:
        return False
    return True


def _damaged(option: str, typed: str, problem: DamagedManifest) -> OutputError:
    return OutputError(
        OutputError.MANIFEST_DAMAGED.format(option=option, typed=typed, manifest=MANIFEST, reason=problem)
    )


class OutputFolder:
    """A checked ``--out`` destination. Create it (which checks the policy) before any work; fill it
    with ``with out.writing() as tmp:`` when the results are ready.

    ``typed`` is the path as the user wrote it (used in messages), ``option`` the option's name,
    ``command`` the writing command (default: the CLI's, ``set_command``), ``companions`` the commands
    whose files this one keeps beside its own without ``--force``; ``force_option`` how the caller asks
    for ``force`` (``"--force"``, ``"force=True"``), None when it cannot: a refusal suggests only what the
    caller offers. ``names``: the files the command will write (paths relative to the folder), when known:
    one that another command or the user holds there is refused here, before any work, even with ``force``
    (files are written beside others, never over them).
    """

    def __init__(
        self,
        typed,
        *,
        force: bool = False,
        option: str = "--out",
        command: str | None = None,
        companions: tuple[str, ...] = (),
        force_option: str | None = None,
        names: tuple[str, ...] = (),
    ):
        self.typed, self.force, self.option, self.force_option = str(typed), force, option, force_option
        self.command, self.companions, self.names = command or _command, tuple(companions), tuple(names)
        if not self.typed or "\0" in self.typed:
            raise OutputError(OutputError.BAD_PATH.format(option=option, typed=self.typed))
        self.path = Path(os.path.abspath(os.path.expanduser(self.typed)))
        self.check()

    def check(self) -> Survey | None:
        """Apply the policy to the destination as it is now (raises ``OutputError``); its ``Survey``."""
        path, typed, option = self.path, self.typed, self.option
        try:
            resolved = path.resolve()
        except (OSError, RuntimeError):
            raise OutputError(OutputError.BAD_PATH.format(option=option, typed=typed)) from None
        _refused_location(resolved, typed, option)
        found = None
        if path.exists() or path.is_symlink():
            if path.is_symlink():
                if not path.is_dir():
                    raise OutputError(OutputError.NOT_A_FOLDER.format(option=option, typed=typed, part=typed))
                raise OutputError(OutputError.SYMLINK.format(option=option, typed=typed))
            if not path.is_dir():
                raise OutputError(OutputError.NOT_A_FOLDER.format(option=option, typed=typed, part=typed))
            try:
                found = survey(path, self.command, self.companions)
            except DamagedManifest as e:
                raise _damaged(option, typed, e) from None
            except OSError as e:
                raise OutputError(
                    OutputError.UNWRITABLE.format(option=option, typed=typed, reason=e.strerror or str(e))
                ) from None
            if not self.force:
                if found.other:
                    rel, cmd = next(iter(sorted(found.other.items())))
                    raise OutputError(
                        OutputError.OTHER_COMMAND.format(
                            option=option,
                            typed=typed,
                            name=rel,
                            other=cmd,
                            command=self.command,
                            count=len(found.other),
                            remedy=self.remedy(),
                        )
                    )
                if found.user:
                    listed = found.manifest is not None and found.user[0] in found.manifest
                    why = (
                        "was not written by stewart-drake (no manifest)"
                        if found.manifest is None
                        else "holds a file changed since stewart-drake wrote it"
                        if listed
                        else "holds files stewart-drake did not write"
                    )
                    raise OutputError(
                        OutputError.NOT_OURS.format(
                            option=option,
                            typed=typed,
                            why=why,
                            example=found.user[0],
                            count=len(found.user),
                            remedy=self.remedy(),
                        )
                    )
            for rel in self.names:  # with force or companions: a name of ours held by another's file
                if rel in found.other or rel in found.kept or rel in found.user:
                    other = found.other.get(rel) or (found.manifest or {}).get(rel, {}).get("command")
                    other = other if rel not in found.user else None  # changed since: the user's now
                    raise OutputError(
                        OutputError.CLASH_OTHER.format(option=option, typed=typed, name=rel, other=other)
                        if other
                        else OutputError.CLASH.format(option=option, typed=typed, name=rel)
                    )
            if not os.access(path, os.W_OK | os.X_OK):
                raise OutputError(OutputError.UNWRITABLE.format(option=option, typed=typed, reason="permission denied"))
        _probe_writable(path, typed, option)
        return found

    def remedy(self) -> str:
        """What a refusal suggests: the caller's ``force_option``, else a folder this command wrote."""
        if self.force_option:
            return OutputError.REMEDY_FORCE.format(force=self.force_option)
        return OutputError.REMEDY_OWN.format(command=self.command)

    @contextmanager
    def writing(self) -> Iterator[Path]:
        """Yield an empty temporary folder beside the destination; when the block completes, its files
        become the destination's content (see the module docstring); on any error or interrupt the
        destination is unchanged and the temporary folder is gone. An ``OSError`` while writing (disk
        full, ...) becomes one ``OutputError`` naming the option and the file."""
        clean_stale_temps(self.path)
        self.check()  # the destination may have changed while the work ran
        tmp, committed = None, False
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            tmp = make_temp_dir(self.path)
            yield tmp
            with commit_lock(self.path):
                self._commit(tmp)
            committed = True  # what may be left at tmp now is the previous result, kept on purpose
        except OSError as e:
            raise self._write_error(e, tmp) from None
        finally:
            if tmp is not None and not committed and os.path.lexists(tmp):
                _remove_tree(tmp, ignore_errors=True)

    def _write_error(self, e: OSError, tmp: Path | None) -> OutputError:
        name = e.filename
        if name is not None and tmp is not None:
            try:
                name = str(self.path / Path(os.fsdecode(name)).relative_to(tmp))
            except ValueError:
                name = os.fsdecode(name)
        where = f"{name}: " if name else ""
        reason = f"{where}{e.strerror or e}"
        return OutputError(OutputError.UNWRITABLE.format(option=self.option, typed=self.typed, reason=reason))

    def _commit(self, tmp: Path) -> None:
        os.unlink(tmp / MARKER)
        new = {}
        for rel in _entries_under(tmp):
            if rel.endswith("/") or not _no_link_between(tmp, rel) or not stat.S_ISREG(os.lstat(tmp / rel).st_mode):
                continue  # only regular files are results
            new[rel] = {"command": self.command, "sha256": _hash_file(tmp / rel)[0]}
        out = self.path
        found = self.check()
        if found is None:  # a new folder
            _write_manifest(tmp, new)
            os.rename(tmp, out)
            return
        if not (found.kept or found.other or found.user):
            # Only this command's files there: swap the whole folder (one rename makes the new content visible).
            _write_manifest(tmp, new)
            if not _exchange(tmp, out):
                if not any(out.iterdir()):
                    os.rename(tmp, out)  # onto an empty folder
                    return
                old = tmp.with_name(tmp.name + "-old")
                os.rename(out, old)
                os.rename(tmp, out)
                os.rename(old, tmp)
            _remove_verified(tmp, found.manifest or {}, found.own)
            return
        # Others' files there (a companion's, or --force): ours go beside them, file by file.
        others = set(found.kept) | set(found.other) | set(found.user)
        for rel in new:
            parts = Path(rel).parts
            ancestors = {"/".join(parts[:i]) for i in range(1, len(parts))}
            blocked = rel in others or any(
                g in ancestors or g.rstrip("/") in ancestors or g.startswith(rel + "/") for g in others
            )
            if blocked or not _no_link_between(out, rel):
                raise OutputError(OutputError.CLASH.format(option=self.option, typed=self.typed, name=rel))
        manifest = found.manifest or {}
        _remove_verified(out, manifest, [r for r in found.own if r not in new], keep_root=True)
        for rel in new:
            dst = out / rel
            dst.parent.mkdir(parents=True, exist_ok=True)
            os.replace(tmp / rel, dst)
        kept = {r: e for r, e in manifest.items() if e["command"] != self.command}
        _write_manifest(out, kept | new)
        _remove_tree(tmp, ignore_errors=True)  # only the empty folders of the moved files are left


def _remove_verified(root: Path, manifest: dict[str, dict], rels: list[str], keep_root: bool = False) -> None:
    """Delete the files ``rels`` under ``root`` whose content still matches ``manifest`` (checked again
    now: a file changed meanwhile is the user's and stays), then the folders this leaves empty; without
    ``keep_root`` also the manifest and ``root`` itself if nothing else is left (else a note names it)."""
    for rel in rels:
        if rel in manifest and _verified(root, rel, manifest[rel]):
            try:
                os.unlink(root / rel)
            except OSError:
                continue
            parent = (root / rel).parent
            while parent != root:
                try:
                    os.rmdir(parent)
                except OSError:
                    break
                parent = parent.parent
    if keep_root:
        return
    try:
        if os.path.lexists(root / MANIFEST) and stat.S_ISREG(os.lstat(root / MANIFEST).st_mode):
            os.unlink(root / MANIFEST)
        os.rmdir(root)
    except OSError:
        print(f"stewart-drake: note: kept {root}: it holds files changed while this run wrote", file=sys.stderr)


def make_temp_dir(path: Path) -> Path:
    """A new empty folder ``.NAME.sd-tmp-PID-XXXXXXXX`` beside ``path`` (normal permissions, umask) with
    the marker that lets a later run recognise it as a stale temporary (``clean_stale_temps``)."""
    while True:
        token = os.urandom(4).hex()
        tmp = path.with_name(f".{path.name}.sd-tmp-{os.getpid()}-{token}")
        try:
            os.mkdir(tmp, 0o777)
        except FileExistsError:
            continue
        (tmp / MARKER).write_text(json.dumps({"pid": os.getpid(), "token": token}), encoding="utf-8")
        return tmp


def _exchange(a: Path, b: Path) -> bool:
    """Atomically swap two paths (Linux ``renameat2(RENAME_EXCHANGE)``); False where unsupported."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        fn = libc.renameat2
    except (OSError, AttributeError):
        return False
    AT_FDCWD = -100
    rc = fn(AT_FDCWD, os.fsencode(a), AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE)
    if rc == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.EINVAL, errno.ENOSYS, errno.EXDEV, errno.EPERM, errno.ENOTSUP):
        return False
    raise OSError(err, os.strerror(err), str(b))


@contextmanager
def atomic_folder(
    out_dir, *, force: bool = False, command: str | None = None, force_option: str | None = None
) -> Iterator[Path]:
    """Check ``out_dir`` against the policy and yield a temporary folder that becomes it on success
    (``OutputFolder(out_dir).writing()``). ``out_dir`` may also be an ``OutputFolder`` already checked."""
    out = (
        out_dir
        if isinstance(out_dir, OutputFolder)
        else OutputFolder(out_dir, force=force, command=command, force_option=force_option)
    )
    with out.writing() as tmp:
        yield tmp


# ----------------------------------------------------------------------------------------------
# Single files.

_UNSAFE = re.compile(r"[^A-Za-z0-9._+-]+")


def safe_file_stem(name: str, default: str = "platform", max_len: int = 100) -> str:
    """A file name stem derived from a name read from an input file: letters, digits, ``._+-`` only
    (other runs become "_"), no leading dot, at most ``max_len`` characters; ``default`` if nothing is
    left. The result never names a folder, so it stays inside the folder it is joined to."""
    stem = _UNSAFE.sub("_", str(name)).strip("._")[:max_len].strip("._") or default
    return stem if stem not in (".", "..") else default


def _write_file_atomic(path: Path, data: bytes) -> None:
    """Write ``path`` through a marked temporary folder beside it and a rename (no partial file, ever)."""
    tmp = make_temp_dir(path)
    try:
        with open(tmp / path.name, "xb") as fh:
            fh.write(data)
        os.replace(tmp / path.name, path)
    finally:
        _remove_tree(tmp, ignore_errors=True)


def write_text_atomic(path, text: str) -> Path:
    """Write ``text`` to ``path`` through a temporary sibling and a rename (library use: no policy
    check, e.g. regenerating the repository's ``sdf/``); return the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    _write_file_atomic(path, text.encode("utf-8"))
    return path


def check_output_file(typed, *, option: str, command: str | None = None) -> Path:
    """Check, before any work, that the file ``typed`` may be written: its folder exists or can be
    created, and the file is new or this command's (listed in that folder's manifest under this command,
    content unchanged). Return its absolute path."""
    typed = str(typed)
    if not typed or "\0" in typed:
        raise OutputError(OutputError.BAD_PATH.format(option=option, typed=typed))
    path = Path(os.path.abspath(os.path.expanduser(typed)))
    if typed.endswith(("/", os.sep)) or path.is_dir():
        raise OutputError(OutputError.FILE_IS_FOLDER.format(option=option, typed=typed))
    if path.exists() or path.is_symlink():
        if path.is_symlink() or not path.is_file():
            raise OutputError(OutputError.FILE_NOT_REGULAR.format(option=option, typed=typed))
        try:
            entry = (load_manifest(path.parent) or {}).get(path.name)
        except DamagedManifest as e:
            raise _damaged(option, typed, e) from None
        if entry is None or entry["command"] != (command or _command) or not _verified(path.parent, path.name, entry):
            raise OutputError(OutputError.FILE_NOT_OURS.format(option=option, typed=typed))
    _probe_writable(path, typed, option)
    return path


def write_output_file(typed, text: str | bytes, *, option: str, command: str | None = None) -> Path:
    """Write ``text`` (UTF-8, or ``bytes`` as they are) to the file ``typed`` under the policy
    (``check_output_file``), atomically, and record it in the folder's manifest; return the path."""
    path = check_output_file(typed, option=option, command=command)
    clean_stale_temps(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        _write_file_atomic(path, text if isinstance(text, bytes) else text.encode("utf-8"))
        claim_in_manifest(path.parent, [path.name], command=command)
    except DamagedManifest as e:
        raise _damaged(option, typed, e) from None
    except OSError as e:
        raise OutputError(
            OutputError.UNWRITABLE.format(option=option, typed=typed, reason=e.strerror or str(e))
        ) from None
    return path
