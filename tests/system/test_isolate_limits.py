"""The user's code runs under limits it cannot escape: its child's address space is capped (an endless
``malloc`` is one line naming the file, not the machine's memory), a process it forks ends with it, and a
compiler's address space is capped too. The caps are small here; the defaults are the modules' constants."""

from __future__ import annotations

import ctypes
import os
import shutil
import time
from pathlib import Path

import numpy as np
import pytest

from stewart_drake.errors import IsolationError
from stewart_drake.system import c_build
from stewart_drake.system.isolate import run_isolated

needs_cc = pytest.mark.skipif(shutil.which("cc") is None and shutil.which("gcc") is None, reason="no C compiler")
CAP = 256 << 20  # a cap far above what the child needs to start and far below the machine's memory


def _malloc_until_refused(beat):
    """Touch 16 MiB blocks from C's malloc until it refuses one, then use the refused (NULL) block as C would."""
    libc = ctypes.CDLL(None)
    libc.malloc.restype = ctypes.c_void_p
    libc.malloc.argtypes = [ctypes.c_size_t]
    block = 16 << 20
    while True:
        p = libc.malloc(block)
        ctypes.memset(p or 0, 1, block)  # NULL: a SIGSEGV, as the firmware's own memset would be


def _numpy_until_refused(beat):
    keep = []
    while True:
        keep.append(np.ones(1 << 21))  # 16 MiB, touched


def test_c_allocation_without_end_is_the_memory_line():
    t0 = time.perf_counter()
    with pytest.raises(IsolationError) as e:
        run_isolated(_malloc_until_refused, path="mem.c", limit=60, memory=CAP)
    assert str(e.value) == IsolationError.MEMORY.format(path="mem.c", limit="256 MiB")
    assert time.perf_counter() - t0 < 30


def test_python_allocation_without_end_is_the_memory_line():
    with pytest.raises(IsolationError) as e:
        run_isolated(_numpy_until_refused, path="mem.c", limit=60, memory=CAP)
    assert str(e.value) == IsolationError.MEMORY.format(path="mem.c", limit="256 MiB")


def test_a_small_crash_is_not_called_memory():
    def crash(beat):
        ctypes.memset(0, 1, 16)

    with pytest.raises(IsolationError) as e:
        run_isolated(crash, path="segv.c", limit=60, memory=CAP)
    assert str(e.value).startswith("segv.c: the firmware crashed (SIGSEGV"), e.value


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def test_a_forked_process_ends_with_the_answer(tmp_path):
    """The child forks a sleeper and answers: the answer comes back and the sleeper is gone."""
    pid_file = tmp_path / "orphan.pid"

    def fork_and_answer(beat):
        pid = os.fork()
        if pid == 0:
            time.sleep(60)  # bounded: were it left behind, it holds the test's output pipes this long
            os._exit(0)
        pid_file.write_text(str(pid))
        return 42

    assert run_isolated(fork_and_answer, path="fork.c", limit=60) == 42
    orphan = int(pid_file.read_text())
    deadline = time.monotonic() + 5
    while _alive(orphan) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not _alive(orphan)


@pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc's cc1 is the compiler that reads /dev/zero without end")
def test_compiler_memory_cap(tmp_path, monkeypatch):
    """``#include "/dev/zero"`` makes cc1 read without end; under a 256 MiB cap it stops with one line."""
    monkeypatch.setattr(c_build, "COMPILE_MEMORY_LIMIT_BYTES", CAP)
    monkeypatch.setattr(c_build, "cache_dir", lambda: tmp_path)
    t0 = time.perf_counter()
    with pytest.raises(c_build.CompileError) as e:
        c_build.build(
            [c_build.Source("zero.c", text='#include "/dev/zero"\n')], compiler=c_build.compiler_by_name("gcc")
        )
    assert str(e.value) == c_build.CompileError.MEMORY.format(what="zero.c", limit="256 MiB of address space")
    assert time.perf_counter() - t0 < 60


@needs_cc
def test_truncated_cache_entry_is_rebuilt(tmp_path, monkeypatch):
    """A cached library whose bytes differ from the record made when it was stored is built again, never
    loaded (a truncated one is a SIGBUS at dlopen)."""
    monkeypatch.setattr(c_build, "cache_dir", lambda: tmp_path)
    src = [c_build.Source("one.c", text="int one(void) { return 1; }\n")]
    path = c_build.build(src)
    whole = path.read_bytes()
    path.write_bytes(whole[: len(whole) // 2])
    assert not c_build.intact(path)
    again = c_build.build(src)
    assert again == path and again.read_bytes() == whole and c_build.intact(again)
    ffi, lib = c_build.load(again, "int one(void);")
    assert lib.one() == 1


@needs_cc
def test_truncated_kernel_in_the_cache_is_rebuilt(tmp_path, monkeypatch):
    """The package's kernels (``RealtimeFK(engine="c")``, the IK kernel, ...) are cached by their source alone
    (``source_keyed_library``): a truncated copy there is built again before it is loaded."""
    monkeypatch.setattr(c_build, "cache_dir", lambda: tmp_path)
    src = tmp_path / "two.c"
    src.write_text("int two(void) { return 2; }\n")
    path = c_build.source_keyed_library(src, "int two(void);", "sd-test-two")
    whole = path.read_bytes()
    path.write_bytes(whole[:100])
    again = c_build.source_keyed_library(src, "int two(void);", "sd-test-two")
    assert again == path and c_build.intact(again) and again.read_bytes() == whole
    _, lib = c_build.load(again, "int two(void);")
    assert lib.two() == 2


@pytest.mark.parametrize("waitid", [True, False])
def test_a_crash_after_a_fork_is_seen_and_the_fork_ended(monkeypatch, tmp_path, waitid):
    """The child forks a sleeper (which holds the answer pipe open) and crashes: the crash is found by the child's
    status, not the pipe's end, and the sleeper is ended. Where ``os.waitid`` is missing (macOS) the child is
    reaped as it is found ended and its status kept."""
    if not waitid:
        monkeypatch.delattr(os, "waitid", raising=False)
    pid_file = tmp_path / "sleeper.pid"

    def fork_and_crash(beat):
        pid = os.fork()
        if pid == 0:
            time.sleep(60)  # bounded: were it left behind, it holds the test's output pipes this long
            os._exit(0)
        pid_file.write_text(str(pid))
        ctypes.memset(0, 1, 16)

    with pytest.raises(IsolationError) as e:
        run_isolated(fork_and_crash, path="segv.c", limit=30, memory=CAP)
    assert str(e.value).startswith("segv.c: the firmware crashed (SIGSEGV"), e.value
    sleeper = int(pid_file.read_text())
    deadline = time.monotonic() + 5
    while _alive(sleeper) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not _alive(sleeper)
