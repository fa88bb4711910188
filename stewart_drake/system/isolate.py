"""Running code the user wrote (their C firmware) in a child process with a time limit.

A user's ``sd_ik`` that never returns, calls ``exit(0)``, dereferences NULL or ``printf``s to standard
output would otherwise hang the command, end it with status 0 and no output (a false pass), kill it with
a bare "Segmentation fault", or corrupt its ``--json``. ``run_isolated(fn, ...)`` runs ``fn`` in a forked
child (no re-import: the loaded modules are shared copy-on-write) whose standard output is
``/dev/null`` and which dies with its parent; ``fn`` calls ``beat()`` whenever it makes progress, and the
child is stopped (its whole process group, compilers included) when ``limit`` seconds pass without
one. The child runs in its own process group, which is ended when it answers or dies (a process the
user's code forks does not outlive the command), and its address space may grow by at most
``FIRMWARE_MEMORY_LIMIT_BYTES`` (``RLIMIT_AS``; an endless ``malloc`` fails there instead of taking the
machine's memory). Every way the child can fail becomes one ``IsolationError`` line naming the file; the
command exits 2.
"""

from __future__ import annotations

import faulthandler
import multiprocessing
import os
import resource
import signal
import time
from collections.abc import Callable

from stewart_drake.errors import IsolationError, OptionError
from stewart_drake.system.processes import child_setup

FIRMWARE_TIME_LIMIT_S = 120.0  # firmware check: compile, 100000 poses, 0.5 s closed loop (~10 s here)
FIRMWARE_IDLE_LIMIT_S = 60.0  # simulate --firmware: seconds the simulated time may stand still (a tick takes µs)
# the address space the child may add to its size at the fork: pydrake's import (~0.2 GB), a firmware check of
# the largest --poses and a closed loop fit many times over; a runaway allocation stops here
FIRMWARE_MEMORY_LIMIT_BYTES = 4 << 30
# the share of that allowance the child's resident peak must have grown by for a crash or a hang to be called
# running out of memory: touched pages count in both, and an allocation the limit refused leaves the child near it
_MEMORY_HIT_SHARE = 0.5


def check_time_limit(value: float, option: str = "--time-limit") -> float:
    """``value`` (a time limit, s) if it is a positive number of seconds, at most a day (``OptionError``)."""
    if not 0 < value <= 86400:
        raise OptionError(OptionError.BETWEEN.format(option=option, lo="0 (excluded)", hi=86400, value=value))
    return float(value)


def _address_space() -> int:
    """This process's address space (bytes; ``VmSize``), 0 where ``/proc`` does not say."""
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmSize:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return 0


def _cap_memory(allowance: int) -> None:
    """Limit this process's address space to its present size plus ``allowance`` bytes (where it can be read)."""
    size = _address_space()
    if size <= 0:
        return
    _, hard = resource.getrlimit(resource.RLIMIT_AS)
    cap = size + allowance
    if hard != resource.RLIM_INFINITY:
        cap = min(cap, hard)
    resource.setrlimit(resource.RLIMIT_AS, (cap, hard))


def _child(conn, fn, args, allowance: int) -> None:
    child_setup()
    faulthandler.disable()  # a crash in the user's code is the parent's one line, not a Python stack dump
    signal.signal(signal.SIGTERM, signal.SIG_DFL)  # the CLI's handler (processes.Terminated) is the parent's
    os.setpgid(0, 0)  # its own group: a compiler it starts is stopped with it
    devnull = os.open(os.devnull, os.O_RDWR)
    os.dup2(devnull, 1)  # a printf in the user's code must not reach our standard output
    os.dup2(devnull, 0)  # nor a read take the terminal's input
    os.close(devnull)

    def beat() -> None:
        conn.send(("beat", None))

    conn.send(("rss", _max_rss()))
    _cap_memory(allowance)
    try:
        result = fn(beat, *args)
    except MemoryError:
        conn.send(("memory", None))
    except BaseException as e:  # noqa: BLE001 - handed to the parent, which raises it there
        try:
            conn.send(("error", e))
        except Exception:  # noqa: BLE001 - an exception that does not pickle: its text
            conn.send(("error", IsolationError(f"{type(e).__name__}: {e}")))
    else:
        conn.send(("ok", result))
    conn.close()


def _max_rss() -> int:
    """This process's resident peak (KiB, as ``getrusage`` gives it on Linux)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss


def run_isolated(fn: Callable, *args, path: str, limit: float, memory: int | None = None):
    """``fn(beat, *args)`` computed in a child process (see the module docstring); its result, or its
    exception raised here. ``path`` is the user's file as they wrote it (named in every failure), ``limit``
    the seconds allowed between two ``beat()`` calls (the first counted from the start), ``memory`` the bytes
    of address space the child may add (default ``FIRMWARE_MEMORY_LIMIT_BYTES``)."""
    allowance = FIRMWARE_MEMORY_LIMIT_BYTES if memory is None else int(memory)
    recv, send = multiprocessing.Pipe(duplex=False)
    pid = os.fork()
    if pid == 0:  # the child: never returns into the caller's frames
        code = 1
        try:
            recv.close()
            _child(send, fn, args, allowance)
            code = 0
        finally:
            os._exit(code)
    send.close()
    try:
        os.setpgid(pid, pid)  # as the child does: its group exists before the parent may have to end it
    except OSError:
        pass
    start_rss = None
    answer = None
    ended = None
    try:
        deadline = time.monotonic() + limit
        while True:
            wait = deadline - time.monotonic()
            if wait <= 0:
                ended = _end(pid)
                raise _failure(path, ended, start_rss, allowance, IsolationError.HUNG.format(path=path, limit=limit))
            if recv.poll(min(wait, 0.5)):
                try:
                    kind, value = recv.recv()
                except (EOFError, OSError):  # the child ended without an answer
                    break
                if kind == "beat":
                    deadline = time.monotonic() + limit
                    continue
                if kind == "rss":
                    start_rss = value
                    continue
                answer = (kind, value)
                break
            if _has_ended(pid) and not recv.poll(0):
                break
    except BaseException:
        if ended is None:
            _end(pid)
        raise
    finally:
        recv.close()
    status, usage = _end(pid)  # also ends whatever the user's code started in the child's group
    if answer is not None:
        kind, value = answer
        if kind == "memory":
            raise IsolationError(IsolationError.MEMORY.format(path=path, limit=_mib(allowance)))
        if kind == "error":
            raise value
        return value
    code = os.waitstatus_to_exitcode(status)
    if code < 0:
        try:
            name = signal.Signals(-code).name
        except ValueError:
            name = f"signal {-code}"
        message = IsolationError.CRASHED.format(path=path, signal=name)
    else:
        message = IsolationError.EXITED.format(path=path, code=code)
    raise _failure(path, (status, usage), start_rss, allowance, message)


def _mib(n: int) -> str:
    return f"{n / (1 << 20):g} MiB"


def _failure(path: str, ended, start_rss, allowance: int, message: str) -> IsolationError:
    """The child's failure: running out of its memory when its resident peak grew by a large share of the
    allowance, else ``message``."""
    _, usage = ended
    if start_rss is not None and (usage.ru_maxrss - start_rss) * 1024 >= _MEMORY_HIT_SHARE * allowance:
        return IsolationError(IsolationError.MEMORY.format(path=path, limit=_mib(allowance)))
    return IsolationError(message)


_REAPED: dict[int, tuple] = {}  # children reaped by _has_ended where waitid cannot look without reaping


def _has_ended(pid: int) -> bool:
    """Whether the child has ended (left unreaped where the system allows: its group cannot be taken by another)."""
    if hasattr(os, "waitid"):
        try:
            return os.waitid(os.P_PID, pid, os.WEXITED | os.WNOHANG | os.WNOWAIT) is not None
        except ChildProcessError:
            return True
    got, status, usage = os.wait4(pid, os.WNOHANG)
    if got == 0:
        return False
    _REAPED[pid] = (status, usage)
    return True


def _end(pid: int) -> tuple:
    """Kill the child's process group (the child, and what its code forked) and reap the child:
    ``(wait status, its resource usage)``."""
    try:
        os.killpg(pid, signal.SIGKILL)
    except OSError:
        try:
            os.kill(pid, signal.SIGKILL)
        except OSError:
            pass
    if pid in _REAPED:
        return _REAPED.pop(pid)
    _, status, usage = os.wait4(pid, 0)
    return status, usage
