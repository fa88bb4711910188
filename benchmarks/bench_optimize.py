"""Design-synthesis throughput: design evaluations per second per core (the full constraint set: leg range,
envelope sizing, frequency and condition over the box), and the search's speed-up on 2 Dask workers.

    PYTHONPATH=. python benchmarks/bench_optimize.py [--requirements R.yaml] [--designs 400] [--budget 480]

Prints, in one run: evaluations per second of CPU time in this process (per core), the same per wall second,
and the search (same seed) on LocalClusters of 1 and 2 workers: wall seconds (cluster start excluded) and the
ratio, with a check that both Pareto sets are identical. The machine may be shared: say so with the figures.
"""

from __future__ import annotations

import argparse
import time
from importlib import resources

import numpy as np

from stewart_drake.synthesis.batch import evaluate_designs
from stewart_drake.synthesis.evaluate import evaluate_design
from stewart_drake.synthesis.requirements import load_requirements
from stewart_drake.synthesis.search import Evaluations, run_search

DEFAULT = resources.files("stewart_drake") / "examples" / "seed_001_requirements.yaml"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--requirements", default=str(DEFAULT))
    ap.add_argument("--designs", type=int, default=400, help="designs evaluated in this process")
    ap.add_argument("--budget", type=int, default=480, help="search budget for the 1- and 2-worker runs")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--batch", type=int, default=24, help="designs per batch (a generation of the default population)")
    args = ap.parse_args(argv)
    req = load_requirements(args.requirements)
    rng = np.random.default_rng(args.seed)
    X = req.lower + rng.random((args.designs, len(req.lower))) * (req.upper - req.lower)
    evaluate_designs(req, X[:5])  # imports and caches warm
    c0 = time.process_time()
    for x in X[: args.designs // 4]:
        evaluate_design(req, x)
    ref = (args.designs // 4) / (time.process_time() - c0)
    t0, c0 = time.perf_counter(), time.process_time()
    rows = [r for s in range(0, len(X), args.batch) for r in evaluate_designs(req, X[s : s + args.batch])]
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    ok = sum(r["error"] is None for r in rows)
    print(
        f"in-process: {args.designs} designs ({ok} evaluable) in batches of {args.batch}: {wall:.2f} s wall, {cpu:.2f} s CPU"
    )
    print(
        f"  {args.designs / cpu:.1f} evaluations per CPU second (per core), {args.designs / wall:.1f} per wall second"
    )
    print(f"  one design at a time through the per-platform functions (evaluate_design): {ref:.1f} per CPU second")
    times, fronts = {}, {}
    for workers in (1, 2):
        engine = Evaluations(req, workers)  # the cluster started here, outside the timing
        engine(X[:4])
        t0 = time.perf_counter()
        rows_w = [r for s in range(0, len(X), args.batch * 10) for r in engine(X[s : s + args.batch * 10])]
        times[workers] = time.perf_counter() - t0
        engine.close()
        assert [r["f"] for r in rows_w] == [r["f"] for r in rows], "worker results differ from in-process ones"
        res = run_search(req, budget=args.budget, seed=args.seed, workers=workers)
        fronts[workers] = [res.rows[i]["x"] for i in res.front]
        print(f"{workers} worker(s): {args.designs} designs, {args.batch * 10} per call: {times[workers]:.2f} s wall")
    print(f"2-worker speed-up: {times[1] / times[2]:.2f}x; Pareto sets identical: {fronts[1] == fronts[2]}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
