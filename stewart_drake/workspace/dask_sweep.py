"""The workspace sweeps on Dask (``dask[distributed]``, a dependency of the package).

Nothing is rescheduled here: Dask's client exposes a ``concurrent.futures.Executor``
(``Client.get_executor``), and the sweeps in ``workspace`` accept any executor, so the same slab and
chunk functions run on a laptop's processes or on a cluster. Use:

    from stewart_drake.workspace.dask_sweep import local_client, workspace_on_dask
    with local_client(n_workers=2) as client:
        ws = workspace_on_dask(platform, resolution=0.0025, client=client)

For a geometry optimisation over many candidate platforms, ``map_platforms`` sends one evaluation
per platform to the cluster (each evaluation runs single-threaded on its worker).

How the cluster is set up for these sweeps (``benchmarks/bench_workspace_dask.py`` measures each choice):

- workers start without Dask's ``MALLOC_TRIM_THRESHOLD_`` (it turns off glibc's adaptive mmap threshold, so every
  large numpy temporary of a slab would be a fresh, zeroed mapping), and the variable is held out of the
  spawning process's own environment while they start (``WORKER_CONFIG``);
- the workers' statistical profiler is off: it takes the GIL from numpy code every 10 ms (``WORKER_CONFIG``);
- every worker imports numpy, scipy and the package before its first task (``warm_up``);
- the Dask entry points size the tasks to at least ``TASKS_PER_WORKER`` per worker thread, so the last wave is
  not a fraction of the others;
- the extents' refinement after the sweep checks each plane's candidate nodes in one vectorised batch
  (``workspace.extents``).

What is shipped per task is small (a slab's ``GridSpec``, a 6-D chunk's arguments, a slab's result), so
nothing is scattered.
"""

from __future__ import annotations

import logging
import math
import os

import dask
import distributed
import numpy as np

from stewart_drake.system.processes import ONE_BLAS_THREAD, quiet_resource_tracker
from stewart_drake.workspace.executors import default_workers
from stewart_drake.workspace.grid import constant_orientation_workspace, default_bounds, grid_axes
from stewart_drake.workspace.maps import count_reachable

# Dask settings for the workers of ``local_client`` (see the module docstring): no statistical profiler,
# and Dask's default worker environment without MALLOC_TRIM_THRESHOLD_ (numpy temporaries reuse the heap).
WORKER_CONFIG = {
    "distributed.worker.profile.enabled": False,
    "distributed.nanny.pre-spawn-environ": ONE_BLAS_THREAD,
    # each worker dies with this process (even by SIGKILL) and leaves Ctrl-C to it (system.processes)
    "distributed.worker.preload": ["stewart_drake.system.processes"],
}
# At least this many tasks per worker thread (load balance: the last wave of tasks is a small share).
TASKS_PER_WORKER = 8


def local_client(n_workers: int | None = None, threads_per_worker: int = 1, processes: bool = True, **kwargs):
    """A ``distributed.Client`` on a ``LocalCluster`` of ``n_workers`` (default: the usable CPUs) worker
    processes, one thread each (the numpy kernels are single-threaded per slab). Use as a context
    manager; closing the client closes the cluster."""
    cluster = local_cluster(n_workers or default_workers(), threads_per_worker, processes, **kwargs)
    client = distributed.Client(cluster)
    client._stewart_owned_cluster = cluster  # closed with the client (see close_client)
    warm_up(client)
    return client


def local_cluster(n_workers: int, threads_per_worker: int = 1, processes: bool = True, **kwargs):
    """A ``LocalCluster`` whose workers run with ``WORKER_CONFIG``: no statistical profiler, glibc's
    adaptive malloc (no ``MALLOC_TRIM_THRESHOLD_``, also when an earlier cluster left it in this
    process's environment). The scheduler's and nannies' INFO messages are not printed, warnings are:
    ``LocalCluster(silence_logs=WARN)`` quiets only Dask's own handler, and in a process where another
    library configured the root logger before Dask was imported (pydrake does, on its first message) they
    reach the root's handler instead."""
    distributed_logger = logging.getLogger("distributed")
    distributed_logger.setLevel(max(distributed_logger.getEffectiveLevel(), logging.WARNING))
    quiet_resource_tracker()
    held = os.environ.pop("MALLOC_TRIM_THRESHOLD_", None)
    try:
        with dask.config.set(WORKER_CONFIG):
            return distributed.LocalCluster(
                n_workers=n_workers,
                threads_per_worker=threads_per_worker,
                processes=processes,
                dashboard_address="127.0.0.1:0",  # a free port: no "Port 8787 is already in use" warning
                **kwargs,
            )
    finally:
        if held is not None:
            os.environ["MALLOC_TRIM_THRESHOLD_"] = held


def _import_kernels() -> bool:
    """Run on each worker: unpickling this function there imports this module and with it the sweep's
    modules (``workspace``, scipy.optimize), so that the first timed task does not pay for them."""
    return True


def warm_up(client) -> None:
    """Import the sweep's modules on every worker now, not inside the first timed tasks."""
    client.run(_import_kernels)


def worker_threads(client) -> int:
    """Threads across the cluster's workers (at least 1)."""
    return max(1, sum(client.nthreads().values()))


def close_client(client) -> None:
    """Close a client from ``local_client`` and its cluster."""
    cluster = getattr(client, "_stewart_owned_cluster", None)
    client.close()
    if cluster is not None:
        cluster.close()


def dask_executor(client):
    """The ``concurrent.futures.Executor`` view of a Dask client (tasks are not cached: pure=False)."""
    return client.get_executor(pure=False)


def slab_nodes(
    platform,
    threads: int,
    orientation=(0.0, 0.0, 0.0),
    resolution: float = 0.01,
    convention: str = "utn",
    bounds=None,
    chunk_nodes: int = 1 << 21,
    **_,
) -> int:
    """The ``chunk_nodes`` that gives at least ``TASKS_PER_WORKER`` slabs per thread (never more than
    ``chunk_nodes``; a slab keeps at least two x-planes)."""
    b = default_bounds(platform, orientation, convention) if bounds is None else np.asarray(bounds, dtype=float)
    nx, ny, nz = (len(a) for a in grid_axes(b, float(resolution)))
    planes = max(2, math.ceil(nx / (TASKS_PER_WORKER * threads)))
    return int(min(chunk_nodes, planes * ny * nz))


def workspace_on_dask(platform, client=None, **kwargs):
    """``workspace.constant_orientation_workspace`` with its slabs on Dask (a temporary local cluster
    when ``client`` is None). Keyword arguments as in the core function; the result is identical (the
    slab size only splits the same sweep; at least ``TASKS_PER_WORKER`` slabs per worker thread unless
    ``chunk_nodes`` is given)."""
    own = client is None
    client = local_client() if own else client
    try:
        if "chunk_nodes" not in kwargs:
            kwargs["chunk_nodes"] = slab_nodes(platform, worker_threads(client), **kwargs)
        return constant_orientation_workspace(platform, executor=dask_executor(client), **kwargs)
    finally:
        if own:
            close_client(client)


def count_reachable_on_dask(platform, grids, client=None, **kwargs):
    """``workspace.count_reachable`` (a chunked 6-D grid sweep) with its chunks on Dask: at least
    ``TASKS_PER_WORKER`` chunks per worker thread unless ``chunk`` is given (never more than 2^18 poses)."""
    own = client is None
    client = local_client() if own else client
    try:
        if "chunk" not in kwargs:
            total = math.prod(len(np.ravel(g)) for g in grids)
            kwargs["chunk"] = int(max(1, min(1 << 18, math.ceil(total / (TASKS_PER_WORKER * worker_threads(client))))))
        return count_reachable(platform, grids, executor=dask_executor(client), **kwargs)
    finally:
        if own:
            close_client(client)


def map_platforms(function, platforms, client, **kwargs) -> list:
    """``[function(p, **kwargs) for p in platforms]`` evaluated on the cluster, in order. ``function``
    must be importable by the workers (a module-level function, e.g. ``workspace.stroke_volume_columns``)."""
    futures = client.map(function, list(platforms), pure=False, **kwargs)
    return client.gather(futures)
