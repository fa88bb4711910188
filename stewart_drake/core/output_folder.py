"""Output safety: results appear complete or not at all, and no file the tool did not write is ever
overwritten or deleted.

Policy (README "Output folders"):

- An output folder (``--out DIR``) must be new, empty, or a folder this tool wrote before: one holding
  a manifest ``.stewart-drake-manifest.json`` that lists the files the tool wrote there, and nothing
  else. Anything else (a folder with other files, an existing non-folder, ``.``, an ancestor of the
  working directory, the home folder, ``/``) is refused with exit 2 *before* any work is done.
- ``--force`` accepts a folder that also holds other files: the tool's files are written next to them;
  a file not listed in the manifest is never overwritten nor deleted (a name clash is refused).
- The folder is built in a temporary sibling ``.DIR.sd-tmp-PID-XXXX`` and swapped in with one rename
  (new, empty or manifest-only folders), so a reader sees the old result or the new one, never a mix.
  The temporary folder is removed on success, error and Ctrl-C; one left by a killed run (its PID no
  longer alive) is removed by the next run that writes beside it.
- A single output file (``model --write``, ``leg sdf --write``, ``compile -o``) is written through a
  temporary sibling and a rename; an existing file is replaced only if the folder's manifest lists it.

Folders are created with the usual permissions (``0o777`` less the umask, 0o755 typically).
"""

from __future__ import annotations

import ctypes
import errno
import json
import os
import re
import secrets
import shutil
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from stewart_drake import __version__
from stewart_drake.errors import OutputError

MANIFEST = ".stewart-drake-manifest.json"
_TMP_RE = re.compile(r"^\.(?P<name>.+)\.sd-tmp-(?P<pid>\d+)-[0-9a-f]{8}$")
_RENAME_EXCHANGE = 2


# ----------------------------------------------------------------------------------------------
# Manifests.


def read_manifest(folder: Path) -> list[str] | None:
    """The relative file paths the manifest in ``folder`` lists, or None when there is no (valid) one."""
    try:
        data = json.loads((Path(folder) / MANIFEST).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    files = data.get("files") if isinstance(data, dict) else None
    if data.get("tool") != "stewart-drake" or not isinstance(files, list) or not all(isinstance(f, str) for f in files):
        return None
    return [f for f in files if _is_relative_inside(f)]


def _write_manifest(folder: Path, files) -> None:
    text = json.dumps({"tool": "stewart-drake", "version": __version__, "files": sorted(set(files))}, indent=2) + "\n"
    _write_file_atomic(folder / MANIFEST, text.encode("utf-8"))


def claim_in_manifest(folder, names) -> None:
    """Record ``names`` (relative paths the caller has just written in ``folder``) as the tool's own, so
    that the folder stays a valid destination for a later ``OutputFolder`` (e.g. a resumable work file)."""
    folder = Path(folder)
    _write_manifest(folder, (read_manifest(folder) or []) + list(names))


def _is_relative_inside(rel: str) -> bool:
    p = Path(rel)
    return bool(rel) and not p.is_absolute() and ".." not in p.parts and rel != MANIFEST


def _files_under(folder: Path) -> list[str]:
    """Relative POSIX paths of every non-folder entry, and of every empty folder (ending in "/"), under
    ``folder`` (the manifest excluded)."""
    out = []
    for root, dirs, files in os.walk(folder):
        if not dirs and not files and root != str(folder):
            out.append(Path(root).relative_to(folder).as_posix() + "/")
        for f in files + [d for d in dirs if os.path.islink(os.path.join(root, d))]:
            rel = Path(os.path.join(root, f)).relative_to(folder).as_posix()
            if rel != MANIFEST:
                out.append(rel)
    return sorted(out)


def _foreign_entries(folder: Path, ours: list[str]) -> list[str]:
    """Files under ``folder`` that the manifest ``ours`` does not list."""
    known = set(ours)
    return [f for f in _files_under(folder) if f not in known]


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
    probe = parent / f".{path.name or 'out'}.sd-tmp-{os.getpid()}-{secrets.token_hex(4)}"
    try:
        os.mkdir(probe)
        os.rmdir(probe)
    except OSError as e:
        raise OutputError(
            OutputError.UNWRITABLE.format(option=option, typed=typed, reason=e.strerror or str(e))
        ) from None


def clean_stale_temps(path: Path) -> list[Path]:
    """Remove temporary siblings ``.NAME.sd-tmp-PID-XXXX`` of ``path`` left by runs that were killed
    (their process no longer exists); return what was removed."""
    removed = []
    parent = path.parent
    try:
        entries = list(parent.iterdir())
    except OSError:
        return removed
    for e in entries:
        m = _TMP_RE.match(e.name)
        if not m or m["name"] != path.name or _pid_alive(int(m["pid"])):
            continue
        if e.is_dir() and not e.is_symlink():
            shutil.rmtree(e, ignore_errors=True)
        else:
            try:
                e.unlink()
            except OSError:
                continue
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


class OutputFolder:
    """A checked ``--out`` destination. Create it (which checks the policy) before any work; fill it
    with ``with out.writing() as tmp:`` when the results are ready.

    ``typed`` is the path as the user wrote it (used in messages), ``option`` the option's name.
    """

    def __init__(self, typed, *, force: bool = False, option: str = "--out"):
        self.typed, self.force, self.option = str(typed), force, option
        if not self.typed or "\0" in self.typed:
            raise OutputError(OutputError.BAD_PATH.format(option=option, typed=self.typed))
        self.path = Path(os.path.abspath(os.path.expanduser(self.typed)))
        self.check()

    def check(self) -> None:
        """Apply the policy to the destination as it is now (raises ``OutputError``)."""
        path, typed, option = self.path, self.typed, self.option
        try:
            resolved = path.resolve()
        except (OSError, RuntimeError):
            raise OutputError(OutputError.BAD_PATH.format(option=option, typed=typed)) from None
        _refused_location(resolved, typed, option)
        if path.exists() or path.is_symlink():
            if not path.is_dir():
                raise OutputError(OutputError.NOT_A_FOLDER.format(option=option, typed=typed, part=typed))
            if path.is_symlink():
                raise OutputError(OutputError.SYMLINK.format(option=option, typed=typed))
            ours = read_manifest(path)
            try:
                present = _files_under(path)
            except OSError as e:
                raise OutputError(
                    OutputError.UNWRITABLE.format(option=option, typed=typed, reason=e.strerror or str(e))
                ) from None
            foreign = [f for f in present if f not in set(ours or [])]
            if foreign and not self.force:
                why = (
                    "was not written by stewart-drake (no manifest)"
                    if ours is None
                    else "holds files stewart-drake did not write"
                )
                raise OutputError(
                    OutputError.NOT_OURS.format(
                        option=option, typed=typed, why=why, example=foreign[0], count=len(foreign)
                    )
                )
            if not os.access(path, os.W_OK | os.X_OK):
                raise OutputError(OutputError.UNWRITABLE.format(option=option, typed=typed, reason="permission denied"))
        _probe_writable(path, typed, option)

    @contextmanager
    def writing(self) -> Iterator[Path]:
        """Yield an empty temporary folder beside the destination; when the block completes, its files
        become the destination's content (see the module docstring); on any error or interrupt the
        destination is unchanged and the temporary folder is gone."""
        clean_stale_temps(self.path)
        self.check()  # the destination may have changed while the work ran
        self.path.parent.mkdir(parents=True, exist_ok=True)
        tmp = _make_temp_dir(self.path)
        try:
            yield tmp
            self._commit(tmp)
        finally:
            if tmp.exists():
                shutil.rmtree(tmp, ignore_errors=True)

    def _commit(self, tmp: Path) -> None:
        new = _files_under(tmp)
        out = self.path
        ours = read_manifest(out) if out.is_dir() else None
        foreign = _foreign_entries(out, ours or []) if out.is_dir() else []
        if not foreign:
            # Swap the whole folder: one rename makes the new content visible.
            _write_manifest(tmp, new)
            if not out.exists():
                os.rename(tmp, out)
                return
            if not _exchange(tmp, out):
                if not any(out.iterdir()):
                    os.rename(tmp, out)  # onto an empty folder
                    return
                old = tmp.with_name(tmp.name + "-old")
                os.rename(out, old)
                os.rename(tmp, out)
                tmp = old
            shutil.rmtree(tmp, ignore_errors=True)  # the previous result (only files we wrote)
            return
        # --force into a folder with other files: put ours beside them, file by file.
        clash = [
            f for f in new if f in set(foreign) or any(f.startswith(g + "/") or g.startswith(f + "/") for g in foreign)
        ]
        if clash:
            raise OutputError(OutputError.CLASH.format(option=self.option, typed=self.typed, name=clash[0]))
        for rel in ours or []:
            if rel not in new:
                _remove_quietly(out / rel)
        for rel in new:
            dst = out / rel
            dst.parent.mkdir(parents=True, exist_ok=True)
            if dst.is_dir() and not dst.is_symlink():
                shutil.rmtree(dst)
            os.replace(tmp / rel, dst)
        _write_manifest(out, new)


def _remove_quietly(p: Path) -> None:
    try:
        p.unlink()
    except OSError:
        pass


def _make_temp_dir(path: Path) -> Path:
    """A new empty folder ``.NAME.sd-tmp-PID-XXXX`` beside ``path``, normal permissions (umask)."""
    while True:
        tmp = path.with_name(f".{path.name}.sd-tmp-{os.getpid()}-{secrets.token_hex(4)}")
        try:
            os.mkdir(tmp, 0o777)
            return tmp
        except FileExistsError:
            continue


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
def atomic_folder(out_dir, *, force: bool = False) -> Iterator[Path]:
    """Check ``out_dir`` against the policy and yield a temporary folder that becomes it on success
    (``OutputFolder(out_dir).writing()``). ``out_dir`` may also be an ``OutputFolder`` already checked."""
    out = out_dir if isinstance(out_dir, OutputFolder) else OutputFolder(out_dir, force=force)
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
    tmp = path.with_name(f".{path.name}.sd-tmp-{os.getpid()}-{secrets.token_hex(4)}")
    try:
        with open(tmp, "xb") as fh:
            fh.write(data)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def write_text_atomic(path, text: str) -> Path:
    """Write ``text`` to ``path`` through a temporary sibling and a rename (library use: no policy
    check, e.g. regenerating the repository's ``sdf/``); return the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    _write_file_atomic(path, text.encode("utf-8"))
    return path


def check_output_file(typed, *, option: str) -> Path:
    """Check, before any work, that the file ``typed`` may be written: its folder exists or can be
    created, and the file is new or listed in that folder's manifest. Return its absolute path."""
    typed = str(typed)
    if not typed or "\0" in typed:
        raise OutputError(OutputError.BAD_PATH.format(option=option, typed=typed))
    path = Path(os.path.abspath(os.path.expanduser(typed)))
    if typed.endswith(("/", os.sep)) or path.is_dir():
        raise OutputError(OutputError.FILE_IS_FOLDER.format(option=option, typed=typed))
    if path.exists() or path.is_symlink():
        if path.is_symlink() or not path.is_file():
            raise OutputError(OutputError.FILE_NOT_REGULAR.format(option=option, typed=typed))
        if path.name not in (read_manifest(path.parent) or []):
            raise OutputError(OutputError.FILE_NOT_OURS.format(option=option, typed=typed))
    _probe_writable(path, typed, option)
    return path


def write_output_file(typed, text: str, *, option: str) -> Path:
    """Write ``text`` to the file ``typed`` under the policy (``check_output_file``), atomically, and
    record it in the folder's manifest; return the path."""
    path = check_output_file(typed, option=option)
    clean_stale_temps(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        _write_file_atomic(path, text.encode("utf-8"))
        _write_manifest(path.parent, (read_manifest(path.parent) or []) + [path.name])
    except OSError as e:
        raise OutputError(
            OutputError.UNWRITABLE.format(option=option, typed=typed, reason=e.strerror or str(e))
        ) from None
    return path
