"""Design-synthesis throughput: design evaluations per second per core (the full constraint set: leg range,
envelope sizing, frequency and condition over the box), and the search's speed-up on 2 Dask workers.

    PYTHONPATH=. python benchmarks/bench_optimize.py [--requirements R.yaml] [--designs 480] [--repeats 3]
        [--pop-size 24,48,96] [--generations 20]

Prints, in one run:

- evaluations per CPU second in this process (per core), in the search's tasks of ``CHUNK_DESIGNS``, and one
  design at a time through the per-platform functions (``evaluate_design``);
- for each population size (designs per generation; the search's default is 24) the search of ``--generations``
  generations (same seed, a fresh output folder each time, so its journal is written as ``optimize`` writes it) in
  this process and on LocalClusters of 1 and 2 workers, each started before its timing: wall seconds (the best of
  ``--repeats``, the configurations interleaved so that a change of the machine's load hits them alike), the
  2-worker speed-up against 1 worker of the same run beside its target, whether the Pareto sets are identical, the
  machine's load average;
- the CPU milliseconds per generation of this process (its main thread: NSGA-II and the loop; its other threads:
  the Dask client, and the LocalCluster's scheduler and nannies) and of each worker process, and from them the
  speed-up the same work gives on an idle machine (each worker with a core of its own and this process serial with
  them: (this + worker) / (this + the busiest worker)), which the machine's load changes less than the wall clock.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import threading
import time
from importlib import resources
from pathlib import Path

import numpy as np
import psutil

from stewart_drake.synthesis.batch import evaluate_designs
from stewart_drake.synthesis.evaluate import evaluate_design
from stewart_drake.synthesis.requirements import load_requirements
from stewart_drake.synthesis.search import CHUNK_DESIGNS, Evaluations, run_search

DEFAULT = resources.files("stewart_drake") / "examples" / "seed_001_requirements.yaml"
TARGET = 1.8  # issue 26: the 2-worker speed-up over 1 worker


class CpuMeter:
    """CPU seconds of this process's main thread, of its other threads, and of each worker process."""

    def __init__(self, engine: Evaluations):
        self.me, self.main = psutil.Process(), threading.get_native_id()
        pids = engine.client.run(os.getpid).values() if engine.client is not None else []
        self.workers = [psutil.Process(p) for p in pids]

    def read(self) -> tuple[float, float, list[float]]:
        threads = {t.id: t.user_time + t.system_time for t in self.me.threads()}
        main = threads.pop(self.main, 0.0)
        return main, sum(threads.values()), [sum(w.cpu_times()[:2]) for w in self.workers]


def timed_search(req, engine, meter, folder, pop, generations, seed):
    """One search in a fresh folder: (wall s, main-thread CPU s, other threads' CPU s, [worker CPU s], front)."""
    m0, o0, w0 = meter.read()
    t0 = time.perf_counter()
    res = run_search(req, out=folder, budget=pop * generations, seed=seed, pop_size=pop, engine=engine)
    wall = time.perf_counter() - t0
    m1, o1, w1 = meter.read()
    workers = sorted((b - a for a, b in zip(w0, w1, strict=True)), reverse=True)
    return wall, m1 - m0, o1 - o0, workers, [res.rows[i]["x"] for i in res.front]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--requirements", default=str(DEFAULT))
    ap.add_argument("--designs", type=int, default=480, help="designs evaluated in this process")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--repeats", type=int, default=3, help="timed searches per configuration (best kept)")
    ap.add_argument(
        "--pop-size", default="24,48,96", help="NSGA-II populations (designs per generation), comma-separated"
    )
    ap.add_argument("--generations", type=int, default=20, help="generations per search (budget = pop × generations)")
    args = ap.parse_args(argv)
    pops = [int(p) for p in args.pop_size.split(",")]
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
    rows, _ = local(X)
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
        assert [r["f"] for r in engines[k](X)[0]] == [r["f"] for r in rows], (
            f"{k}-worker results differ from in-process"
        )
    meters = {k: CpuMeter(e) for k, e in engines.items()}
    summary = []
    try:
        with tempfile.TemporaryDirectory() as tmp:
            for pop in pops:
                best, fronts = {}, {}
                for rep in range(args.repeats):
                    for k, engine in engines.items():
                        folder = Path(tmp) / f"p{pop}-k{k}-r{rep}"
                        got = timed_search(req, engine, meters[k], folder, pop, args.generations, args.seed)
                        if got[0] < best.get(k, (np.inf,))[0]:
                            best[k] = got
                        fronts[k] = got[4]
                summary.append(report(pop, args, best, fronts))
    finally:
        for engine in engines.values():
            engine.close()
    print(
        f"summary (target >= {TARGET:.1f}x; reference: 1 worker in the same run; load average {os.getloadavg()[0]:.2f} now):"
    )
    for line in summary:
        print("  " + line)
    return 0


def report(pop: int, args, best: dict, fronts: dict) -> str:
    """Prints one population's figures; returns its summary line."""
    g = args.generations
    print(f"search, {pop * g} designs in {g} generations of {pop} (best of {args.repeats}):")
    for k, (wall, main, other, workers, _) in best.items():
        where = "in this process" if k == 0 else f"{k} worker(s)"
        per = f"this process {1000 * main / g:.1f} (main thread) + {1000 * other / g:.1f} (other threads) ms CPU"
        if workers:
            per += ", workers " + " + ".join(f"{1000 * w / g:.1f}" for w in workers) + " ms CPU"
        print(f"  {where}: {wall:.2f} s wall ({1000 * wall / g:.1f} ms per generation); per generation: {per}")
    cpu = {k: best[k][1] + best[k][2] for k in (1, 2)}
    measured = best[1][0] / best[2][0]
    idle = (cpu[1] + best[1][3][0]) / (cpu[2] + best[2][3][0])
    same = fronts[0] == fronts[1] == fronts[2]
    line = (
        f"population {pop}: 2-worker speed-up {measured:.2f}x measured (target >= {TARGET:.1f}x: "
        f"{'met' if measured >= TARGET else 'not met'}), {idle:.2f}x from the CPU seconds; "
        f"Pareto sets identical (0, 1, 2 workers): {same}"
    )
    print("  " + line + f" (load average {os.getloadavg()[0]:.2f})")
    return line


if __name__ == "__main__":
    raise SystemExit(main())
