"""Monte Carlo throughput on LocalClusters of each worker count, in one run, and the rows compared.

Runs the same study (``stewart-drake montecarlo`` settings) once per ``--workers`` entry into
``--out``/workers-K (each a complete study folder: table, summary, plots), times it from the cluster's
start to the last row (runs per second), prints the ratio to the first entry and checks that every row
(wall time excluded) equals the first entry's.

    PYTHONPATH=. python benchmarks/bench_montecarlo.py --runs 200 --workers 1,2 --out /tmp/mc-bench \
        --vary anchor=±0.5mm sensor_resolution=10um latency_jitter=200us plate_mass=±20%
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from stewart_drake.core.geometry import load_platform
from stewart_drake.drake.integrators import DEFAULT_INTEGRATOR, INTEGRATORS
from stewart_drake.firmware.engine import ENGINES, default_engine
from stewart_drake.montecarlo.scenario import Study
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
    for k in counts:
        out = base / f"workers-{k}"
        t0 = time.perf_counter()
        rows = run_study(study, out, workers=k, progress=False)
        wall = time.perf_counter() - t0
        summary = summarise(rows, study_settings(study), study_key(study))
        write_outputs(out, rows, summary)
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


def _equal(a, b) -> bool:
    return len(a) == len(b) and all(
        x.keys() == y.keys() and all(x[c] == y[c] or (x[c] != x[c] and y[c] != y[c]) for c in x) for x, y in zip(a, b)
    )


if __name__ == "__main__":
    raise SystemExit(main())
