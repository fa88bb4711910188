"""Running independent sweep tasks (workspace slabs, 6-D chunks) in-process, on a process pool or on
any ``concurrent.futures.Executor`` (e.g. Dask's, see ``workspace_dask``), with tqdm progress on stderr.
"""

from __future__ import annotations

import os
import sys
from collections import deque

from stewart_drake.system.processes import worker_pool
from stewart_drake.workspace.limits import WorkspaceError


def run_tasks(fn, tasks, executor, workers, progress, desc):
    """Yield ``fn(*task)`` for every task, in order: in-process, on a process pool of ``workers``, or on a
    given ``concurrent.futures.Executor``. A generator, so that callers merge results as they come
    and memory stays bounded by the slab, not by the number of slabs. Progress with tqdm on stderr."""
    # deferred: tqdm is needed only when a sweep runs, and `stewart-drake workspace --help` imports this module
    from tqdm import tqdm

    bar = tqdm(total=len(tasks), desc=desc, disable=not progress, file=sys.stderr, leave=False)
    try:
        if executor is None and workers > 1 and len(tasks) > 1:
            with worker_pool(workers) as ex:  # spawned, dying with this process, terminated on Ctrl-C/SIGTERM
                yield from _drain(ex, fn, tasks, bar, window=4 * workers)
        elif executor is not None:
            if not hasattr(executor, "submit"):  # a concurrent.futures.Executor, or any object like one
                raise WorkspaceError(WorkspaceError.EXECUTOR.format(kind=type(executor).__name__))
            yield from _drain(executor, fn, tasks, bar, window=None)
        else:
            for t in tasks:
                yield fn(*t)
                bar.update()
    finally:
        bar.close()


def _drain(executor, fn, tasks, bar, window):
    """Submit tasks (at most ``window`` in flight, None: all) and yield results in order."""
    pending, it = deque(), iter(tasks)
    for t in it if window is None else (next(it, None) for _ in range(window)):
        if t is not None:
            pending.append(executor.submit(fn, *t))
    while pending:
        res = pending.popleft().result()
        nxt = next(it, None)
        if nxt is not None:
            pending.append(executor.submit(fn, *nxt))
        bar.update()
        yield res


def default_workers() -> int:
    """Worker processes that pay off here: the CPUs this process may use (at most 8)."""
    try:
        n = len(os.sched_getaffinity(0))
    except AttributeError:
        n = os.cpu_count() or 1
    return max(1, min(n, 8))
