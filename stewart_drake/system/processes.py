"""Child processes: how many a command may start, and that they die with their parent, quietly.

- ``check_workers``: the one rule for ``--workers``/``--jobs`` (each worker is a Python process with
  numpy, ~150 MB; more than 4 per CPU only adds overhead).
- ``child_setup``: run first in every ``multiprocessing`` pool worker and in the isolated firmware child:
  the kernel kills it when its parent dies, even by SIGKILL (``PR_SET_PDEATHSIG``), and it ignores SIGINT:
  Ctrl-C reaches the whole process group, and the parent alone stops the work and says so in one line (no
  traceback per worker). Dask's worker processes ignore SIGINT from their first import of this package
  (``mark_cli``; ``dask_sweep.WORKER_CONFIG`` preloads this module) and end within a second of their
  parent's SIGKILL by themselves (their nanny's pipe closes; measured on a 2-worker study).
- ``mark_cli``: the command line's PID in the environment (``STEWART_DRAKE_CLI_PID``): a worker process it
  starts (its child) ignores SIGINT from the moment it imports this package (``system.interrupts``), so that
  a Ctrl-C while the worker starts is not a traceback either; ``mark_cli`` returns what restores the
  environment (a command run in-process must not mark the caller's later children).
- ``worker_pool``: a spawn ``ProcessPoolExecutor`` whose workers run ``child_setup`` and are terminated,
  not waited for, when the parent is interrupted; its workers' BLAS is single-threaded (``ONE_BLAS_THREAD``).
- ``Terminated`` / ``handle_sigterm``: SIGTERM raises in the main thread like Ctrl-C, so that the
  ``finally`` blocks run (temporary folders removed, clusters closed) before the process exits 143.
"""

from __future__ import annotations

import os
import signal
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING

from stewart_drake.core.sanity import check_work
from stewart_drake.errors import OptionError
from stewart_drake.system.interrupts import CLI_PID_ENV

if TYPE_CHECKING:
    from concurrent.futures import ProcessPoolExecutor

BYTES_PER_WORKER = 150e6
WORKERS_PER_CPU = 4
_PR_SET_PDEATHSIG = 1
# The environment of every worker process this package starts (``worker_pool``, Dask's nannies): one BLAS thread.
# The workers already fill the CPUs, and OpenBLAS's own threads on top of them spin for the small (6 × 6 … 6000 × 42)
# matrices of these analyses. One thread also makes the results independent of the machine's core count (a
# threaded product may sum in another order).
ONE_BLAS_THREAD = {"OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}


def max_workers() -> int:
    """The most worker processes one command may start on this machine."""
    return WORKERS_PER_CPU * (os.cpu_count() or 1)


def check_workers(option: str, value: int, minimum: int = 1) -> int:
    """``value`` if it is a number of worker processes this machine can hold (``minimum`` ..
    ``max_workers()``, and their memory within the budget); else ``OptionError``/``WorkTooLargeError``
    naming ``option`` and the value."""
    if not minimum <= value <= max_workers():
        raise OptionError(OptionError.BETWEEN.format(option=option, lo=minimum, hi=max_workers(), value=value))
    check_work(option, str(value), value, "worker processes", BYTES_PER_WORKER)
    return value


def die_with_parent(sig: int = signal.SIGKILL) -> None:
    """Ask the kernel to send ``sig`` to this process when its parent dies (Linux; elsewhere nothing)."""
    # deferred: the command line imports this module at start, and only a worker process asks this
    import ctypes

    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(_PR_SET_PDEATHSIG, int(sig), 0, 0, 0)
    except (OSError, AttributeError):
        return
    if os.getppid() == 1:  # the parent died before the request: follow it now
        os._exit(1)


def child_setup() -> None:
    """Run first in a worker process: die with the parent, leave SIGINT to the parent."""
    die_with_parent()
    try:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    except ValueError:  # not the main thread: the parent's cleanup still stops this worker
        return


@contextmanager
def worker_pool(n: int) -> Iterator[ProcessPoolExecutor]:
    """A ``ProcessPoolExecutor`` of ``n`` spawned workers (no fork of a process that may hold Drake's
    threads) running ``child_setup`` with ``ONE_BLAS_THREAD`` in their environment (the workers start at the
    first task, so the parent's environment carries it for the pool's life, then is put back); on an error or
    interrupt the workers are terminated at once."""
    # deferred: multiprocessing and concurrent.futures are a large share of a numpy command's start-up, and only
    # the commands that start workers need them (the command line imports this module at start)
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    quiet_resource_tracker()
    ctx = multiprocessing.get_context("spawn")
    before = set(multiprocessing.active_children())
    held = {k: os.environ.get(k) for k in ONE_BLAS_THREAD}
    os.environ.update(ONE_BLAS_THREAD)
    pool = ProcessPoolExecutor(max_workers=n, mp_context=ctx, initializer=child_setup)
    try:
        yield pool
    except BaseException:
        for p in set(multiprocessing.active_children()) - before:
            p.terminate()
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    finally:
        for k, v in held.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
    pool.shutdown(wait=True)


def quiet_resource_tracker() -> None:
    """The resource tracker (started with the first pool) outlives a parent killed by SIGKILL for a moment
    and then warns of "leaked semaphore objects" on the terminal: it takes this process's warning options
    (``sys.warnoptions``) when it starts, so the warning is filtered there."""
    option = "ignore::UserWarning:multiprocessing.resource_tracker"
    if option not in sys.warnoptions:
        sys.warnoptions.append(option)


def mark_cli() -> Callable[[], None]:
    """Record this process as the command line that owns the worker processes it starts; return the
    function that puts the environment back as it was."""
    before = os.environ.get(CLI_PID_ENV)
    os.environ[CLI_PID_ENV] = str(os.getpid())

    def restore() -> None:
        if before is None:
            os.environ.pop(CLI_PID_ENV, None)
        else:
            os.environ[CLI_PID_ENV] = before

    return restore


def exit_now(code: int) -> None:
    """End this process now with ``code`` after flushing its output, without the exit hooks (an interrupted
    Dask cluster's atexit close prints tracebacks); its workers die with it (``die_with_parent``)."""
    # a process that never imported multiprocessing has started no children through it
    multiprocessing = sys.modules.get("multiprocessing")
    children = multiprocessing.active_children() if multiprocessing is not None else []
    for p in children:  # first, so that none logs the lost connection
        try:
            os.kill(p.pid, signal.SIGKILL)
        except OSError:
            pass
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):
            pass
    os._exit(code)


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised in the main thread so that cleanup runs as for Ctrl-C (exit status 143)."""


def _raise_terminated(signum, frame) -> None:
    signal.signal(signal.SIGTERM, signal.SIG_DFL)  # a second SIGTERM ends the process at once
    raise Terminated()


def handle_sigterm() -> None:
    """Make SIGTERM raise ``Terminated`` in the main thread (nothing when called from another thread)."""
    try:
        signal.signal(signal.SIGTERM, _raise_terminated)
    except ValueError:
        pass
