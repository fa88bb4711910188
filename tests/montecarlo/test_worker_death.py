"""A Dask worker killed in the middle of a study: its run is computed again on a live worker, and the
study's rows are those of an undisturbed in-process study, row for row."""

from __future__ import annotations

import os
import signal
import threading
import time

import pytest

from stewart_drake.core.geometry import load_platform
from stewart_drake.montecarlo.scenario import Study
from stewart_drake.montecarlo.spec import parse_spec
from stewart_drake.montecarlo.study import run_study

RUNS = 6


def _rows_without_wall_time(rows):
    return [{k: v for k, v in r.items() if k != "wall_s"} for r in rows]


# One worker: the killed one held everything the study had sent (a scattered study was lost with it for good,
# and every run failed); two: the other worker may take the run over.
@pytest.mark.parametrize("n_workers", [1, 2])
def test_a_killed_worker_s_run_is_rerun_and_the_rows_are_unchanged(tmp_path, n_workers):
    distributed = pytest.importorskip("distributed")
    spec = parse_spec(["anchor=±0.5mm", "plate_mass=±20%"])
    study = Study(load_platform("utn-dynamic"), spec, seed=3, runs=RUNS, duration=0.5)
    expected = _rows_without_wall_time(run_study(study, None, workers=0, progress=False))
    killed = {}
    with distributed.LocalCluster(
        n_workers=n_workers, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster:
        with distributed.Client(cluster) as client:
            pids = client.run(os.getpid)  # {worker address: pid}

            def kill_a_busy_worker():
                """SIGKILL the first worker seen computing a run (the nanny starts a fresh one)."""
                deadline = time.monotonic() + 120
                while time.monotonic() < deadline and not killed:
                    for address, tasks in client.processing().items():
                        if tasks and address in pids:
                            killed[address] = list(tasks)
                            os.kill(pids[address], signal.SIGKILL)
                            return
                    time.sleep(0.01)

            killer = threading.Thread(target=kill_a_busy_worker)
            killer.start()
            rows = run_study(study, tmp_path / "study", scheduler=cluster.scheduler_address, progress=False)
            killer.join()
    # a worker died while computing a run (else the test proves nothing)
    assert killed and all(str(k).startswith("run_row") for tasks in killed.values() for k in tasks), killed
    assert _rows_without_wall_time(rows) == expected
