"""Running code the user wrote (their C firmware) in a child process with a time limit.

A user's ``sd_ik`` that never returns, calls ``exit(0)``, dereferences NULL or ``printf``s to standard
output would otherwise hang the command, end it with status 0 and no output (a false pass), kill it with
a bare "Segmentation fault", or corrupt its ``--json``. ``run_isolated(fn, ...)`` runs ``fn`` in a forked
child (no re-import: the loaded modules are shared copy-on-write) whose standard output is
``/dev/null`` and which dies with its parent; ``fn`` calls ``beat()`` whenever it makes progress, and the
child is stopped (its whole process group, compilers included) when ``limit`` seconds pass without
one. Every way the child can fail becomes one ``IsolationError`` line naming the file; the command exits 2.
"""

from __future__ import annotations

import faulthandler
import multiprocessing
import os
import signal
import time
from collections.abc import Callable

from stewart_drake.core.processes import child_setup
from stewart_drake.errors import IsolationError, OptionError

FIRMWARE_TIME_LIMIT_S = 120.0  # firmware check: compile, 100000 poses, 0.5 s closed loop (~10 s here)
FIRMWARE_IDLE_LIMIT_S = 60.0  # simulate --firmware: seconds the simulated time may stand still (a tick takes µs)


def check_time_limit(value: float, option: str = "--time-limit") -> float:
    """``value`` (a time limit, s) if it is a positive number of seconds, at most a day (``OptionError``)."""
    if not 0 < value <= 86400:
        raise OptionError(OptionError.BETWEEN.format(option=option, lo="0 (excluded)", hi=86400, value=value))
    return float(value)


def _child(conn, fn, args) -> None:
    child_setup()
    faulthandler.disable()  # a crash in the user's code is the parent's one line, not a Python stack dump
    signal.signal(signal.SIGTERM, signal.SIG_DFL)  # the CLI's handler (processes.Terminated) is the parent's
    os.setpgid(0, 0)  # its own group: a compiler it starts is stopped with it
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)  # a printf in the user's code must not reach our standard output
    os.close(devnull)

    def beat() -> None:
        conn.send(("beat", None))

    try:
        result = fn(beat, *args)
    except BaseException as e:  # noqa: BLE001 - handed to the parent, which raises it there
        try:
            conn.send(("error", e))
        except Exception:  # noqa: BLE001 - an exception that does not pickle: its text
            conn.send(("error", IsolationError(f"{type(e).__name__}: {e}")))
    else:
        conn.send(("ok", result))
    conn.close()


def run_isolated(fn: Callable, *args, path: str, limit: float):
    """``fn(beat, *args)`` computed in a child process (see the module docstring); its result, or its
    exception raised here. ``path`` is the user's file as they wrote it (named in every failure), ``limit``
    the seconds allowed between two ``beat()`` calls (the first counted from the start)."""
    ctx = multiprocessing.get_context("fork")
    recv, send = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_child, args=(send, fn, args), daemon=True)
    proc.start()
    send.close()
    try:
        deadline = time.monotonic() + limit
        while True:
            wait = deadline - time.monotonic()
            if wait <= 0:
                _stop(proc)
                raise IsolationError(IsolationError.HUNG.format(path=path, limit=limit))
            if recv.poll(min(wait, 0.5)):
                try:
                    kind, value = recv.recv()
                except (EOFError, OSError):  # the child ended without an answer
                    break
                if kind == "beat":
                    deadline = time.monotonic() + limit
                    continue
                proc.join(10)
                if kind == "error":
                    raise value
                return value
            if not proc.is_alive() and not recv.poll(0):
                break
    except BaseException:
        _stop(proc)
        raise
    finally:
        recv.close()
    proc.join(10)
    code = proc.exitcode
    if code is not None and code < 0:
        try:
            name = signal.Signals(-code).name
        except ValueError:
            name = f"signal {-code}"
        raise IsolationError(IsolationError.CRASHED.format(path=path, signal=name))
    raise IsolationError(IsolationError.EXITED.format(path=path, code=code))


def _stop(proc) -> None:
    if proc.is_alive():
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except OSError:
            proc.kill()
    proc.join(10)
