"""Compiling C for the host: find a compiler, build a shared library, cache it by content hash, load it
with cffi.

Why cffi's ABI mode (``ffi.dlopen`` of a plain shared library) rather than its API mode (a CPython
extension): every compiler we fall back to — the system ``cc``/``gcc``/``clang`` and the ``ziglang``
wheel's ``zig cc`` — builds a shared library with one command and no Python headers or setuptools, the
library does not depend on the Python version (one cache entry serves every interpreter), and it is
the very object a user's firmware file compiles to in ``firmware check``. The cost, a libffi call of
~1 µs, does not matter: the hot loops run inside C batch functions, and the controller in the loop
makes one call per 1 ms tick.

Compiler order: ``$STEWART_DRAKE_CC`` (a command line, e.g. ``clang`` or ``gcc -m64``), then ``cc``,
``gcc``, ``clang`` on PATH, then ``python -m ziglang cc`` when the ``ziglang`` wheel is installed.
Cache: ``$STEWART_DRAKE_CACHE``, else ``$XDG_CACHE_HOME/stewart-drake``, else ``~/.cache/stewart-drake``
(never the source tree); an entry's name is the SHA-256 of the compiler's identity, the flags and every
source's bytes, written atomically (compiled in a temporary folder, then renamed) beside the SHA-256 of the
library's own bytes (``<entry>.sha256``); an entry is used only while its bytes match that record (a truncated
or altered library would crash the process when loaded), else it is built again. The package's own kernels'
cffi declarations are cached the same way (``ffi-<SHA-256 of the declarations>.py``, see ``_ffi``).

A compiler runs in its own process group with its address space limited to ``COMPILE_MEMORY_LIMIT_BYTES``
(``ulimit -v``): a source that makes it allocate without end (``#include "/dev/zero"``) is a ``CompileError``.
"""

from __future__ import annotations

import hashlib
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from functools import cache
from pathlib import Path

from stewart_drake.errors import StewartError

C_DIR = Path(__file__).resolve().parent.parent / "fixedpoint" / "c"
CACHE_ENV = "STEWART_DRAKE_CACHE"
CC_ENV = "STEWART_DRAKE_CC"
BASE_FLAGS = ("-std=c99", "-O2", "-fPIC", "-shared")
STRICT_FLAGS = ("-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic")


COMPILE_TIMEOUT_S = 300.0  # one source file; the generated firmware takes ~1 s
COMPILE_MEMORY_LIMIT_BYTES = 4 << 30  # address space of one compiler process; cc1 needs ~0.1 GB for these sources
_OUT_OF_MEMORY = re.compile(r"out of memory|memory exhausted|cannot allocate memory|bad_alloc", re.IGNORECASE)


class CompilerUnavailable(StewartError):
    """No C compiler could be found (nor the ziglang wheel)."""


class CacheUnavailable(StewartError):
    """The folder compiled modules are cached in cannot be created or written."""


# why compiled code cannot be built here (a fallback may run instead); a CompileError is a bug, never hidden
UNAVAILABLE = (CompilerUnavailable, CacheUnavailable)


class CompileError(StewartError):
    """The compiler rejected a source; the message is the compiler's own (file:line: error ...)."""

    MEMORY = "{what}: the C compiler ran out of its memory limit ({limit}); stopped"


@dataclass(frozen=True)
class Compiler:
    """A C compiler command: ``name`` (gcc, clang, zig cc, ...), ``argv`` the command prefix, ``version``
    its first ``--version`` line (part of the cache key)."""

    name: str
    argv: tuple[str, ...]
    version: str


def cache_dir() -> Path:
    """The folder compiled modules are cached in (created on first use)."""
    d = os.environ.get(CACHE_ENV)
    if not d:
        base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
        d = os.path.join(base, "stewart-drake")
    p = Path(d)
    try:
        p.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise CacheUnavailable(_cache_message(p, e)) from None
    return p


def _cache_message(folder: Path, e: OSError) -> str:
    reason = "it is a file, not a folder" if isinstance(e, FileExistsError) and not folder.is_dir() else e.strerror
    return f"the compiled-module cache {folder} cannot be used ({reason}); set ${CACHE_ENV} to a writable folder"


def _probe(name: str, argv: tuple[str, ...]) -> Compiler | None:
    try:
        r = subprocess.run([*argv, "--version"], capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired):
        return None
    if r.returncode != 0:
        return None
    first = (r.stdout or r.stderr).strip().splitlines()
    return Compiler(name, argv, first[0] if first else name)


@cache
def _compilers(cc_env: str | None) -> tuple[Compiler, ...]:
    found = []
    if cc_env:
        try:
            argv = tuple(shlex.split(cc_env))
        except ValueError:  # unbalanced quotes: not a command line
            argv = ()
        c = _probe(argv[0], argv) if argv else None
        if c is None:
            raise CompilerUnavailable(f"{CC_ENV}={cc_env!r} does not run as a C compiler")
        return (c,)
    seen = set()
    for exe in ("cc", "gcc", "clang"):
        path = shutil.which(exe)
        if path and os.path.realpath(path) not in seen:
            seen.add(os.path.realpath(path))
            c = _probe(exe, (path,))
            if c is not None:
                found.append(c)
    zig = zig_compiler()
    if zig is not None:
        found.append(zig)
    return tuple(found)


@cache
def zig_compiler() -> Compiler | None:
    """``python -m ziglang cc`` when the ``ziglang`` wheel is installed, else None."""
    import importlib.util

    if importlib.util.find_spec("ziglang") is None:
        return None
    return _probe("zig cc", (sys.executable, "-m", "ziglang", "cc"))


def compilers() -> tuple[Compiler, ...]:
    """Every usable compiler, in the order of preference (see the module docstring)."""
    return _compilers(os.environ.get(CC_ENV))


def default_compiler() -> Compiler:
    """The preferred compiler; raises CompilerUnavailable if there is none."""
    cs = compilers()
    if not cs:
        raise CompilerUnavailable(
            "no C compiler found (looked for $STEWART_DRAKE_CC, cc, gcc, clang and the ziglang "
            "wheel's zig cc; `pip install ziglang` gives one)"
        )
    return cs[0]


def compiler_by_name(name: str) -> Compiler:
    """A compiler named ``gcc``, ``clang``, ``cc`` or ``zig`` (raises CompilerUnavailable if absent)."""
    if name.startswith("zig"):
        c = zig_compiler()
    else:
        path = shutil.which(name)
        c = _probe(name, (path,)) if path else None
    if c is None:
        raise CompilerUnavailable(f"compiler {name!r} is not available")
    return c


@dataclass(frozen=True)
class Source:
    """A C source for ``build``: a file on disk (``path``; compiled where it is, so that the compiler's
    messages name it) or generated text (``name`` + ``text``, written into the build folder)."""

    name: str
    text: str | None = None
    path: Path | None = None

    def data(self) -> bytes:
        return self.path.read_bytes() if self.path is not None else self.text.encode()


def library_sources(*names: str) -> list[Source]:
    """The package's own C files (``fixedpoint/c``) as build sources."""
    return [Source(n, path=C_DIR / n) for n in names]


def build(
    sources: list[Source],
    *,
    headers: list[Source] = (),
    defines: tuple[str, ...] = (),
    flags: tuple[str, ...] = (),
    compiler: Compiler | None = None,
    strict: bool = False,
    opt: str = "-O2",
) -> Path:
    """Compile ``sources`` (with ``headers`` beside them and the package's ``fixedpoint/c`` on the include
    path) into a shared library in the cache and return its path; a cached build with the same compiler,
    flags and bytes is reused. ``strict``: add ``-Wall -Wextra -Werror -pedantic``. Raises CompileError
    with the compiler's message, CompilerUnavailable without a compiler, CacheUnavailable if the cache
    cannot be written."""
    compiler = compiler or default_compiler()
    cflags = (
        tuple(f for f in BASE_FLAGS if f != "-O2")
        + (opt,)
        + (STRICT_FLAGS[1:] if strict else ())
        + tuple(f"-D{d}" for d in defines)
        + tuple(flags)
    )
    h = hashlib.sha256()
    h.update("\0".join((compiler.version, *compiler.argv, *cflags)).encode())
    for s in [*sources, *headers, *library_sources("dsp56800e.h")]:
        h.update(s.name.encode() + b"\0" + s.data() + b"\0")
    root = cache_dir()
    out = root / f"sd-{h.hexdigest()[:32]}.so"
    if intact(out):
        return out
    try:
        workdir = tempfile.TemporaryDirectory(prefix="build-", dir=root)
    except OSError as e:
        raise CacheUnavailable(_cache_message(root, e)) from None
    with workdir as tmp:
        tmp = Path(tmp)
        files = []
        for s in [*sources, *headers]:
            if s.path is None:
                (tmp / s.name).write_text(s.text)
        for s in sources:
            files.append(str(s.path if s.path is not None else tmp / s.name))
        target = tmp / "lib.so"
        cmd = [*compiler.argv, *cflags, f"-I{tmp}", f"-I{C_DIR}", "-o", str(target), *files]
        r = run_compiler(cmd, sources[0].name)
        if r.returncode != 0:
            msg = (r.stderr or r.stdout).replace(str(tmp) + os.sep, "")
            raise CompileError(_first_error(msg, compiler))
        if not target.is_file():  # e.g. $STEWART_DRAKE_CC=true: it answers --version and exits 0
            raise CompilerUnavailable(
                f"{' '.join(compiler.argv)} exited 0 but wrote no library: not a working C compiler (set ${CC_ENV} to one)"
            )
        store(target, out)
    return out


def instance(path: Path, tag: str) -> Path:
    """A copy of the cached library ``path`` of its own, ``<name>-<tag>.so`` in the cache (stored like a build).
    A process maps a library file once, with one set of its globals: a library whose globals its loader sets
    (``firmware.module``'s gains table) is loaded from one copy per setting, named by ``tag``."""
    copy = path.with_name(f"{path.stem}-{tag}{path.suffix}")
    if not intact(copy):
        _store_copy(path, copy)
    return copy


def _store_copy(library: Path, path: Path) -> None:
    """Store a copy of ``library`` as the cache entry ``path`` (``store``)."""
    fd, tmp = tempfile.mkstemp(suffix=path.suffix, dir=path.parent)
    os.close(fd)
    shutil.copyfile(library, tmp)
    store(Path(tmp), path)


def _digest_path(path: Path) -> Path:
    return path.with_name(path.name + ".sha256")


def _file_digest(path: Path) -> str:
    with open(path, "rb") as f:
        return hashlib.file_digest(f, "sha256").hexdigest()


def intact(path: Path) -> bool:
    """Whether the cached library at ``path`` exists and its bytes are those recorded when it was stored."""
    try:
        return _digest_path(path).read_text().strip() == _file_digest(path)
    except OSError:
        return False


def store(built: Path, path: Path) -> None:
    """Move the library ``built`` to the cache entry ``path`` with the record of its bytes (each file replaced
    atomically; the record first, so that an interrupted store leaves an entry that does not match it)."""
    digest = _digest_path(path)
    fd, tmp = tempfile.mkstemp(suffix=".sha256", dir=path.parent)
    with os.fdopen(fd, "w") as f:
        f.write(_file_digest(built) + "\n")
    os.replace(tmp, digest)
    os.replace(built, path)


def run_compiler(cmd: list[str], what: str, timeout: float | None = None) -> subprocess.CompletedProcess:
    """Run a compiler command with a time limit (``COMPILE_TIMEOUT_S``), in its own process group so that
    its own children (cc1, ld) stop with it; its output decoded leniently (a binary "source" makes the
    compiler echo bytes that are not UTF-8). ``CompileError`` naming ``what`` when it does not finish."""
    timeout = COMPILE_TIMEOUT_S if timeout is None else timeout
    kib = max(1, int(COMPILE_MEMORY_LIMIT_BYTES) // 1024)
    # the limit set by the shell the compiler replaces (no preexec_fn: unsafe in a process with threads); where
    # the system refuses it, the compiler runs without it
    limited = (
        ["/bin/sh", "-c", f'ulimit -v {kib} 2>/dev/null; exec "$@"', "sh", *cmd] if os.path.exists("/bin/sh") else cmd
    )
    p = subprocess.Popen(
        limited,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        start_new_session=True,
        encoding="utf-8",
        errors="replace",
    )
    try:
        out, err = p.communicate(timeout=timeout)
    except BaseException as e:  # the time limit, Ctrl-C, SIGTERM: the compiler's whole group goes
        try:
            os.killpg(p.pid, signal.SIGKILL)
        except OSError:
            pass
        p.wait()
        if isinstance(e, subprocess.TimeoutExpired):
            raise CompileError(f"{what}: the C compiler did not finish within {timeout:g} s; stopped") from None
        raise
    if p.returncode != 0 and _OUT_OF_MEMORY.search(err or out or ""):
        limit = f"{COMPILE_MEMORY_LIMIT_BYTES / (1 << 20):g} MiB of address space"
        raise CompileError(CompileError.MEMORY.format(what=what, limit=limit))
    return subprocess.CompletedProcess(cmd, p.returncode, out, err)


def _first_error(msg: str, compiler: Compiler) -> str:
    """The compiler's first error line (file:line:col: error: ...), else the start of its output."""
    lines = msg.strip().splitlines()
    for line in lines:
        if re.search(r":\d+:(\d+:)? (fatal )?error", line):
            return line
    return f"{compiler.name} failed: " + " | ".join(lines[:3])


@cache
def _ffi(cdef: str, cached: bool = False):
    """cffi's ``FFI`` for the declarations ``cdef``. Parsing them takes cffi's C parser (pycparser), whose
    import and parse cost a large share of a short command's start-up; ``cached``: the parsed declarations are
    also kept in the cache as the module cffi generates for them (its out-of-line ABI mode: a few type tables,
    run with ``_cffi_backend`` alone, checked against its recorded SHA-256 like a library) and read from there
    by later processes."""
    entry = _ffi_entry(cdef) if cached else None
    if entry is not None:
        try:
            code = entry.read_bytes()
            if _digest_path(entry).read_text().strip() == hashlib.sha256(code).hexdigest():
                namespace: dict = {}
                exec(compile(code, str(entry), "exec"), namespace)  # the module cffi generated for ``cdef``
                return namespace["ffi"]
        except OSError:  # not stored yet (or unreadable): parse, and store
            pass
    import cffi  # deferred: only a process that parses declarations (not read from the cache) needs the parser

    ffi = cffi.FFI()
    ffi.cdef(cdef)
    if entry is not None:
        _store_ffi(ffi, entry)
    return ffi


def _ffi_entry(cdef: str) -> Path | None:
    """The cache entry of the declarations ``cdef`` for this cffi (its generated modules are read by the
    ``_cffi_backend`` of the version that wrote them); None without a usable cache."""
    import _cffi_backend  # deferred: cffi's C part, loaded only by a process that loads a kernel

    key = hashlib.sha256(f"{_cffi_backend.__version__}\n{cdef}".encode()).hexdigest()[:32]
    try:
        return cache_dir() / f"ffi-{key}.py"
    except CacheUnavailable:
        return None


def _store_ffi(ffi, entry: Path) -> None:
    """Keep ``ffi``'s declarations as the module cffi generates for them at ``entry`` (nothing if the cache
    cannot hold it, nor declarations cffi does not write out of line: the next process parses them again)."""
    import cffi
    from cffi.recompiler import make_py_source

    try:
        fd, tmp = tempfile.mkstemp(suffix=".py", dir=entry.parent)
        os.close(fd)
        try:
            make_py_source(ffi, entry.stem.replace("-", "_"), tmp)
            store(Path(tmp), entry)
        finally:
            if os.path.lexists(tmp):
                os.unlink(tmp)
    except (OSError, cffi.FFIError, cffi.CDefError, cffi.VerificationError):
        pass


_LOADED: dict[tuple[str, str], object] = {}


def source_keyed_library(source: Path, cdef: str, prefix: str, opt: str = "-O2", flags: tuple[str, ...] = ()) -> Path:
    """A one-file kernel's shared library in the cache, keyed on its source, declarations and options alone.
    ``build`` keys its cache on the compiler's identity too, which costs a probe of every compiler (≈ 0.15 s
    per process); a kernel whose result does not depend on which C99 compiler built it is looked up here first
    (``prefix`` names the cached copy)."""
    key = hashlib.sha256(source.read_bytes() + cdef.encode() + " ".join((opt, *flags)).encode()).hexdigest()[:32]
    fast = cache_dir() / f"{prefix}-{key}.so"
    if not intact(fast):
        _store_copy(build([Source(source.name, path=source)], opt=opt, flags=flags), fast)
    return fast


def load(path: Path, cdef: str, cache_declarations: bool = False):
    """``(ffi, lib)`` for the shared library at ``path`` with the declarations ``cdef`` (loaded once).
    ``cache_declarations``: for the package's own kernels, whose libraries define every declared function
    (``_ffi``'s cache: a missing function raises ``ffi.error`` from cached declarations, ``AttributeError``
    from parsed ones, which is how a user's firmware is probed for optional functions)."""
    ffi = _ffi(cdef, cache_declarations)
    key = (str(path), cdef)
    if key not in _LOADED:
        _LOADED[key] = ffi.dlopen(str(path))
    return ffi, _LOADED[key]
