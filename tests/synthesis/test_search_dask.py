"""The search's evaluations on Dask actors: a worker lost between generations costs a resend, not a different
result; through a scheduler's address, every thread of a multi-threaded worker holds an evaluator."""

from __future__ import annotations

import os
import signal
from importlib import resources

import numpy as np
import pytest

from stewart_drake.synthesis.requirements import load_requirements
from stewart_drake.synthesis.search import Evaluations
from stewart_drake.workspace.dask_sweep import local_cluster

SEED_001 = resources.files("stewart_drake") / "examples" / "seed_001_requirements.yaml"


@pytest.fixture(scope="module")
def req():
    return load_requirements(SEED_001)


def designs(req, n: int, seed: int) -> np.ndarray:
    return req.lower + np.random.default_rng(seed).random((n, len(req.lower))) * (req.upper - req.lower)


def test_a_lost_worker_costs_a_resend_not_a_different_result(req):
    """A worker killed (SIGKILL) with its actor: the next generation is sent again to new actors on the workers
    left and its rows and journal lines are those computed in this process, bit for bit."""
    X = designs(req, 36, 11)
    ref = Evaluations(req, 0)(X)
    engine = Evaluations(req, 2)
    try:
        assert engine(X) == ref
        os.kill(next(iter(engine.client.run(os.getpid).values())), signal.SIGKILL)
        assert engine(X) == ref
        assert 1 <= len(engine.actors) <= 2  # the nanny's restarted worker may or may not be back yet
    finally:
        engine.close()


def test_scheduler_address_and_a_two_thread_worker(req):
    """``--scheduler``: the client reaches the actors through the scheduler (Dask's default), one actor per worker
    thread (2 on one 2-thread worker), and 5 chunks (60 designs, 3 and 2 per actor) come back in order, equal to
    this process's rows."""
    X = designs(req, 60, 12)
    ref = Evaluations(req, 0)(X)
    cluster = local_cluster(1, threads_per_worker=2)
    try:
        engine = Evaluations(req, scheduler=cluster.scheduler_address)
        try:
            assert len(engine.actors) == 2 and not engine.client.direct_to_workers
            assert engine(X) == ref
            assert all(a.cpu_seconds > 0 for a in engine.actors)  # both threads evaluated (the benchmark reads it)
            assert engine(X[:12]) == Evaluations(req, 0)(X[:12])  # fewer chunks than actors
        finally:
            engine.close()
    finally:
        cluster.close()
