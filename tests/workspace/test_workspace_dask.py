"""The Dask entry points size their tasks to the cluster and still give the serial results."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stewart_drake import workspace as ws
from stewart_drake.core.geometry import load_preset

pytest.importorskip("distributed", reason='the Dask back end needs dask.distributed (pip install "dask[distributed]")')

from stewart_drake.workspace import dask_sweep as wd  # noqa: E402


def test_slab_size_gives_enough_tasks_per_worker():
    p = load_preset("gonzalez-dutra-2009")
    for threads in (1, 2, 16):
        nodes = wd.slab_nodes(p, threads, resolution=0.005)
        w = ws.constant_orientation_workspace(p, resolution=0.005, refine=False, chunk_nodes=nodes)
        nx, ny, nz = (len(a) for a in w.axes)
        slabs = math.ceil(nx / max(2, nodes // (ny * nz)))
        # at least TASKS_PER_WORKER per thread, unless two-plane slabs already cover the grid
        assert slabs >= min(wd.TASKS_PER_WORKER * threads, math.ceil(nx / 2))
        assert nodes <= 1 << 21


def test_auto_sized_dask_sweeps_equal_serial():
    """Slabs and chunks sized by the cluster split the same sweep: identical volume, views, extents,
    count and marginals; the workers run without their statistical profiler."""
    p = load_preset("gonzalez-dutra-2009")
    grids = (
        [np.linspace(-0.1, 0.1, 4)] * 2 + [p.home_height + np.linspace(-0.1, 0.1, 4)] + [np.linspace(-0.3, 0.3, 4)] * 3
    )
    serial_w = ws.constant_orientation_workspace(p, resolution=0.01)
    serial_c = ws.count_reachable(p, grids)
    client = wd.local_client(n_workers=1)
    try:
        assert client.run(lambda: __import__("dask").config.get("distributed.worker.profile.enabled")) == {
            a: False for a in client.nthreads()
        }
        w = wd.workspace_on_dask(p, client=client, resolution=0.01)
        c = wd.count_reachable_on_dask(p, grids, client=client)
    finally:
        wd.close_client(client)
    assert w.inside_nodes == serial_w.inside_nodes and w.volume == serial_w.volume
    assert np.array_equal(w.top, serial_w.top) and np.array_equal(w.extents, serial_w.extents)
    assert c["count"] == serial_c["count"]
    for a, b in zip(c["marginals"], serial_c["marginals"]):
        assert np.array_equal(a, b)


def test_local_client_workers_keep_the_adaptive_malloc(monkeypatch):
    """Workers start without Dask's MALLOC_TRIM_THRESHOLD_ (it made every numpy temporary a fresh mmap:
    1.9× the CPU time of the 2.5 mm sweep), and with single-threaded BLAS as Dask sets it — also after a
    plain LocalCluster has left the variable in this process's environment."""
    import os

    from distributed import LocalCluster

    monkeypatch.delenv("MALLOC_TRIM_THRESHOLD_", raising=False)  # this process's environment restored afterwards
    with LocalCluster(n_workers=1, threads_per_worker=1, dashboard_address=None):
        pass
    assert os.environ.get("MALLOC_TRIM_THRESHOLD_") == "65536"  # Dask's, in this process now
    client = wd.local_client(n_workers=1)
    try:
        env = client.run(
            lambda: {k: __import__("os").environ.get(k) for k in ("MALLOC_TRIM_THRESHOLD_", "OMP_NUM_THREADS")}
        )
    finally:
        wd.close_client(client)
    assert list(env.values()) == [{"MALLOC_TRIM_THRESHOLD_": None, "OMP_NUM_THREADS": "1"}]
