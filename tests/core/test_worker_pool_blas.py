"""``system.processes.worker_pool``: its workers run with one BLAS thread, and the parent's environment is put back."""

import os

from stewart_drake.system.processes import ONE_BLAS_THREAD, worker_pool


def _blas_environment(_) -> dict:
    return {k: os.environ.get(k) for k in ONE_BLAS_THREAD}


def test_workers_get_one_blas_thread_and_the_parent_keeps_its_own(monkeypatch):
    monkeypatch.setenv(
        "OPENBLAS_NUM_THREADS", "3"
    )  # a user's own setting: the workers override it, the parent keeps it
    monkeypatch.delenv("MKL_NUM_THREADS", raising=False)
    with worker_pool(2) as pool:
        seen = list(pool.map(_blas_environment, range(4)))
    assert all(s == ONE_BLAS_THREAD for s in seen)
    assert os.environ["OPENBLAS_NUM_THREADS"] == "3"
    assert "MKL_NUM_THREADS" not in os.environ
