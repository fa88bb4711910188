"""Design-synthesis throughput: design evaluations per second per core (the full constraint set: leg range,
envelope sizing, frequency and condition over the box), and the search's speed-up on 2 Dask workers.

    PYTHONPATH=. python benchmarks/bench_optimize.py [--requirements R.yaml] [--designs 480] [--budget 480] [--repeats 3]
        [--pop-size 24]

Prints, in one run:

- evaluations per CPU second in this process (per core), in the search's tasks of ``CHUNK_DESIGNS``, and one
  design at a time through the per-platform functions (``evaluate_design``);
- the search (same seed) in this process and on LocalClusters of 1 and 2 workers, each started before its timing:
  wall seconds (the best of ``--repeats``, the configurations interleaved so that a change of the machine's load
  hits them alike), the 2-worker speed-up, whether the Pareto sets are identical, the machine's load average;
- the CPU seconds spent by this process (NSGA-II, the Dask client and scheduler) and by each worker, and from
  them the speed-up the same work gives on an idle machine (each worker with a core of its own and this process
  serial with them: (this + worker) / (this + the busiest worker)), which the load does not change.
"""

from __future__ import annotations

import argparse
import os
import time
from importlib import resources

import numpy as np

from stewart_drake.synthesis.batch import evaluate_designs
from stewart_drake.synthesis.evaluate import evaluate_design
from stewart_drake.synthesis.requirements import load_requirements
from stewart_drake.synthesis.search import CHUNK_DESIGNS, Evaluations, run_search

DEFAULT = resources.files("stewart_drake") / "examples" / "seed_001_requirements.yaml"


def _worker_cpu(engine) -> dict:
    if engine.client is None:
        return {}
    return engine.client.run(time.process_time)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--requirements", default=str(DEFAULT))
    ap.add_argument("--designs", type=int, default=480, help="designs evaluated in this process")
    ap.add_argument("--budget", type=int, default=480, help="search budget for the timed searches")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--repeats", type=int, default=3, help="timed searches per configuration (best kept)")
    ap.add_argument("--pop-size", type=int, default=24, help="NSGA-II population: designs per generation (round trip)")
    args = ap.parse_args(argv)
    req = load_requirements(args.requirements)
    rng = np.random.default_rng(args.seed)
    X = req.lower + rng.random((args.designs, len(req.lower))) * (req.upper - req.lower)
    print(f"load average at start: {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs")
    evaluate_designs(req, X[:5])  # imports and caches warm
    c0 = time.process_time()
    for x in X[: args.designs // 4]:
        evaluate_design(req, x)
    ref = (args.designs // 4) / (time.process_time() - c0)
    local = Evaluations(req, 0)
    t0, c0 = time.perf_counter(), time.process_time()
    rows = local(X)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    ok = sum(r["error"] is None for r in rows)
    print(
        f"in-process: {args.designs} designs ({ok} evaluable) in tasks of {CHUNK_DESIGNS}: {wall:.2f} s wall, {cpu:.2f} s CPU"
    )
    print(
        f"  {args.designs / cpu:.1f} evaluations per CPU second (per core), {args.designs / wall:.1f} per wall second"
    )
    print(f"  one design at a time through the per-platform functions (evaluate_design): {ref:.1f} per CPU second")
    engines = {0: local, 1: Evaluations(req, 1), 2: Evaluations(req, 2)}  # clusters started outside the timing
    for k in (1, 2):
        assert [r["f"] for r in engines[k](X)] == [r["f"] for r in rows], f"{k}-worker results differ from in-process"
    best, fronts, cpu_main, cpu_workers = {}, {}, {}, {}
    try:
        for _ in range(args.repeats):
            for k, engine in engines.items():
                w0, c0, t0 = _worker_cpu(engine), time.process_time(), time.perf_counter()
                res = run_search(req, budget=args.budget, seed=args.seed, pop_size=args.pop_size, engine=engine)
                t = time.perf_counter() - t0
                c, w1 = time.process_time() - c0, _worker_cpu(engine)
                if t < best.get(k, np.inf):
                    best[k], cpu_main[k] = t, c
                    cpu_workers[k] = sorted((w1[a] - w0[a] for a in w0), reverse=True)
                fronts[k] = [res.rows[i]["x"] for i in res.front]
    finally:
        for engine in engines.values():
            engine.close()
    for k in engines:
        where = "in this process" if k == 0 else f"{k} worker(s)"
        extra = "" if k == 0 else ", workers " + " + ".join(f"{w:.2f}" for w in cpu_workers[k]) + " s CPU"
        print(
            f"search, {args.budget} designs in generations of {args.pop_size}, {where}: {best[k]:.2f} s wall (best of {args.repeats}); this process {cpu_main[k]:.2f} s CPU{extra}"
        )
    idle = (cpu_main[1] + cpu_workers[1][0]) / (cpu_main[2] + cpu_workers[2][0])
    print(
        f"2-worker speed-up: {best[1] / best[2]:.2f}x measured (load average {os.getloadavg()[0]:.2f} now), "
        f"{idle:.2f}x from the CPU seconds (idle machine); Pareto sets identical (0, 1, 2 workers): "
        f"{fronts[0] == fronts[1] == fronts[2]}"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
