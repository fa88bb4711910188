"""The workspace sweeps on Dask (optional: ``pip install "dask[distributed]"``).

Nothing is rescheduled here: Dask's client exposes a ``concurrent.futures.Executor``
(``Client.get_executor``), and the sweeps in ``workspace`` accept any executor, so the same slab and
chunk functions run on a laptop's processes or on a cluster. Use:

    from stewart_drake.workspace_dask import local_client, workspace_on_dask
    with local_client(n_workers=2) as client:
        ws = workspace_on_dask(platform, resolution=0.0025, client=client)

For a geometry optimisation over many candidate platforms, ``map_platforms`` sends one evaluation
per platform to the cluster (each evaluation runs single-threaded on its worker).
"""

from __future__ import annotations

from . import workspace as _ws


def _require_distributed():
    try:
        import distributed
    except ImportError:  # pragma: no cover - exercised only without dask
        raise ImportError('the Dask back end needs dask.distributed: pip install "dask[distributed]"') from None
    return distributed


def local_client(n_workers: int | None = None, threads_per_worker: int = 1, processes: bool = True, **kwargs):
    """A ``distributed.Client`` on a ``LocalCluster`` of ``n_workers`` (default: the usable CPUs) worker
    processes, one thread each (the numpy kernels are single-threaded per slab). Use as a context
    manager; closing the client closes the cluster."""
    distributed = _require_distributed()
    n = n_workers or _ws.default_workers()
    cluster = distributed.LocalCluster(
        n_workers=n, threads_per_worker=threads_per_worker, processes=processes, dashboard_address=None, **kwargs
    )
    client = distributed.Client(cluster)
    client._stewart_owned_cluster = cluster  # closed with the client (see close_client)
    return client


def close_client(client) -> None:
    """Close a client from ``local_client`` and its cluster."""
    cluster = getattr(client, "_stewart_owned_cluster", None)
    client.close()
    if cluster is not None:
        cluster.close()


def dask_executor(client):
    """The ``concurrent.futures.Executor`` view of a Dask client (tasks are not cached: pure=False)."""
    _require_distributed()
    return client.get_executor(pure=False)


def _with_client(client, fn, *args, **kwargs):
    own = client is None
    client = local_client() if own else client
    try:
        return fn(*args, executor=dask_executor(client), **kwargs)
    finally:
        if own:
            close_client(client)


def workspace_on_dask(platform, client=None, **kwargs):
    """``workspace.constant_orientation_workspace`` with its slabs on Dask (a temporary local cluster
    when ``client`` is None). Keyword arguments as in the core function; the result is identical."""
    return _with_client(client, _ws.constant_orientation_workspace, platform, **kwargs)


def count_reachable_on_dask(platform, grids, client=None, **kwargs):
    """``workspace.count_reachable`` (a chunked 6-D grid sweep) with its chunks on Dask."""
    return _with_client(client, _ws.count_reachable, platform, grids, **kwargs)


def map_platforms(function, platforms, client, **kwargs) -> list:
    """``[function(p, **kwargs) for p in platforms]`` evaluated on the cluster, in order. ``function``
    must be importable by the workers (a module-level function, e.g. ``workspace.stroke_volume_columns``)."""
    _require_distributed()
    futures = client.map(function, list(platforms), pure=False, **kwargs)
    return client.gather(futures)
