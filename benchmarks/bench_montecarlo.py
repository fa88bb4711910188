"""Monte Carlo throughput on LocalClusters of each worker count, in one run, and the rows compared.

Runs the same study (``stewart-drake montecarlo`` settings) once per ``--workers`` entry into
``--out``/workers-K (each a complete study folder: table, summary, plots), times it from the cluster's
start to the last row (runs per second), prints the ratio to the first entry and checks that every row
(wall time excluded) equals the first entry's.

Where a study's wall time goes, per worker count (rows' arrival times recorded by wrapping the study's
row loop): ``start`` (from the call to the first row's start: cluster, worker processes importing pydrake,
the study scattered), ``runs`` (Σ the rows' own wall times / workers: the ideal parallel time),
``bookkeeping`` (the partial journal written per row, then the Parquet/CSV table, summary and plots), and
the rest (``idle``: waiting for the last runs while other workers have none left, scheduling). And the
reference the issue asks for: a run (``run_scenario``: draw, build, loop, metrics) against the loop alone
(``Simulation.run`` of the same scenario), by process CPU time, over the first ``--alone`` runs, in this
process.

    PYTHONPATH=. python benchmarks/bench_montecarlo.py --runs 200 --workers 1,2 --out /tmp/mc-bench \
        --vary anchor=±0.5mm sensor_resolution=10um latency_jitter=200us plate_mass=±20%
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

import stewart_drake.montecarlo.study as study_module
import stewart_drake.montecarlo.summary as summary_module
from stewart_drake.core.geometry import load_platform
from stewart_drake.drake.integrators import DEFAULT_INTEGRATOR, INTEGRATORS
from stewart_drake.drake.simulation import Simulation
from stewart_drake.firmware.engine import ENGINES, default_engine
from stewart_drake.montecarlo.scenario import Study, run_scenario
from stewart_drake.montecarlo.spec import parse_spec
from stewart_drake.montecarlo.study import run_study, study_key, study_settings
from stewart_drake.montecarlo.summary import summarise, write_outputs


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--platform", default="utn-dynamic")
    ap.add_argument("--trajectory", default="seed")
    ap.add_argument("--controller", default="fixed")
    ap.add_argument("--runs", type=int, default=20)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--duration", type=float, default=None)
    ap.add_argument(
        "--vary",
        nargs="+",
        default=["anchor=±0.5mm", "sensor_resolution=10um", "latency_jitter=200us", "plate_mass=±20%"],
    )
    ap.add_argument("--engine", choices=ENGINES, default=None, help="default: the montecarlo command's")
    ap.add_argument("--integrator", choices=INTEGRATORS, default=DEFAULT_INTEGRATOR)
    ap.add_argument("--workers", default="1,2", help="comma-separated worker counts")
    ap.add_argument("--out", required=True, help="a new folder; one study folder per worker count inside")
    ap.add_argument("--alone", type=int, default=5, help="runs timed against the loop alone (default 5)")
    args = ap.parse_args(argv)
    study = Study(
        load_platform(args.platform),
        parse_spec(args.vary),
        args.seed,
        args.runs,
        trajectory=args.trajectory,
        controller=args.controller,
        duration=args.duration,
        engine=default_engine(args.engine, args.controller, "bench_montecarlo"),
        integrator=args.integrator,
    )
    print(f"engine {study.engine}, integrator {study.integrator}, {args.runs} runs", flush=True)
    counts = [int(k) for k in args.workers.split(",")]
    base, first, report = Path(args.out), None, {}
    if base.exists():
        raise SystemExit(f"{base} exists: give a new folder")
    print(f"load average {', '.join(f'{x:.2f}' for x in os.getloadavg())}", flush=True)
    alone, whole = loop_alone(study, max(1, min(args.alone, args.runs - 1)))
    print(f"a run (draw, build, loop, metrics) vs the loop alone, CPU: {whole / alone:.3f} × (target <= 1.1)")
    for k in counts:
        out = base / f"workers-{k}"
        arrivals, journal, plots = [], [0.0], [0.0]
        t0 = time.perf_counter()
        with _timed(arrivals, journal, plots):
            rows = run_study(study, out, workers=k, progress=False)
            wall_runs = time.perf_counter() - t0
            summary = summarise(rows, study_settings(study), study_key(study))
            write_outputs(out, rows, summary)
        wall = time.perf_counter() - t0
        first = min(range(len(arrivals)), key=lambda i: arrivals[i][0])
        start = arrivals[first][0] - arrivals[first][1] - t0
        busy = sum(r["wall_s"] for r in rows) / k
        books = journal[0] + (wall - wall_runs) - plots[0]
        print(
            f"  workers {k}: wall {wall:.1f} s = start {start:.1f} + runs {busy:.1f} + bookkeeping (journal, "
            f"Parquet/CSV, summary) {books:.2f} ({100 * books / wall:.1f} %, target <= 2 %) + plots {plots[0]:.2f} "
            f"+ idle/scheduling {wall - start - busy - books - plots[0]:.1f}",
            flush=True,
        )
        same = [{c: v for c, v in r.items() if c != "wall_s"} for r in rows]
        first = first or same
        report[k] = {
            "wall_s": wall,
            "runs_per_s": len(rows) / wall,
            "rows_equal_first": _equal(same, first),
            "worst_run": summary["worst_run"]["run"],
        }
        print(
            f"workers {k:2d}: {wall:8.1f} s  {len(rows) / wall:7.3f} runs/s  ×{report[counts[0]]['wall_s'] / wall:.2f}  "
            f"rows equal to workers {counts[0]}: {report[k]['rows_equal_first']}",
            flush=True,
        )
    print(json.dumps(report, indent=2))
    return 0 if all(r["rows_equal_first"] for r in report.values()) else 1


def loop_alone(study, n: int) -> tuple[float, float]:
    """CPU seconds of runs 1 … ``n`` (after run 0, which fills this process's caches as a worker's first run
    does): ``(their loops alone, the whole runs)``, the loop (``Simulation.run``) timed inside each run, so
    that both figures come from the same calls (on a loaded machine separate calls differ by more than
    the build)."""
    run_scenario(study, 0)
    inner, real_run = [0.0], Simulation.run

    def timed_run(sim, *a, **kw):
        c = time.process_time()
        try:
            return real_run(sim, *a, **kw)
        finally:
            inner[0] += time.process_time() - c

    whole = 0.0
    Simulation.run = timed_run
    try:
        for i in range(1, n + 1):
            c0 = time.process_time()
            run_scenario(study, i)
            whole += time.process_time() - c0
    finally:
        Simulation.run = real_run
    return inner[0], whole


class _timed:
    """Record each row's (arrival time, its own wall time), the journal's write time and the plots' time."""

    def __init__(self, arrivals: list, journal: list, plots: list):
        self.arrivals, self.journal, self.plots = arrivals, journal, plots

    def __enter__(self):
        self.results, self.write = study_module._results, study_module.PartialWriter.write
        self.write_plots = summary_module.write_plots
        arrivals, journal, results, write = self.arrivals, self.journal, self.results, self.write
        plots, write_plots = self.plots, self.write_plots

        def timed_plots(*a, **kw):
            c = time.perf_counter()
            try:
                return write_plots(*a, **kw)
            finally:
                plots[0] += time.perf_counter() - c

        summary_module.write_plots = timed_plots

        def timed_results(*a, **kw):
            for row in results(*a, **kw):
                arrivals.append((time.perf_counter(), row["wall_s"]))
                yield row

        def timed_write(writer, obj):
            c = time.perf_counter()
            write(writer, obj)
            journal[0] += time.perf_counter() - c

        study_module._results, study_module.PartialWriter.write = timed_results, timed_write

    def __exit__(self, *exc):
        study_module._results, study_module.PartialWriter.write = self.results, self.write
        summary_module.write_plots = self.write_plots


def _equal(a, b) -> bool:
    return len(a) == len(b) and all(
        x.keys() == y.keys() and all(x[c] == y[c] or (x[c] != x[c] and y[c] != y[c]) for c in x) for x, y in zip(a, b)
    )


if __name__ == "__main__":
    raise SystemExit(main())
