"""The workspace sweeps on Dask against serial, in one run: per worker count, the ratio serial time / Dask
time (and the efficiency, ratio / workers) for the constant-orientation workspace and the 6-D reachable
count, with Dask as it comes ("plain": a LocalCluster, the core functions on its executor) and as
``workspace_dask`` runs it ("tuned": no worker profiler, warmed-up workers, tasks sized to the workers).
Cluster start-up is not timed; every result is checked equal to the serial one. Besides wall time (which
on a shared machine measures the other users too), the CPU time: this process's plus every worker
process's (all threads: the task, Dask's event loop, heartbeats) — ``cpu ratio`` = serial CPU / Dask CPU
is the share of the work that is the sweep itself, whatever the load.

    PYTHONPATH=. python benchmarks/bench_workspace_dask.py --workers 1,2 [--resolution 0.0025] [--points 10]
    (on a bigger machine: --workers 1,2,4,8,16 --points 20, the issue's 64 M poses)
"""

from __future__ import annotations

import argparse
import json
import math
import time

import numpy as np

from stewart_drake import workspace as ws
from stewart_drake.core.geometry import load_preset
from stewart_drake.workspace import dask_sweep as wd


def _cpu() -> float:
    return time.process_time()


def best_of(repeat, fn, *args, client=None, **kwargs):
    """(best wall s, best CPU s, result); CPU: this process's plus the workers' of ``client``."""
    best, best_cpu, out = math.inf, math.inf, None
    for _ in range(repeat):
        w0 = sum(client.run(_cpu).values()) if client is not None else 0.0
        c0, t0 = time.process_time(), time.perf_counter()
        out = fn(*args, **kwargs)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        if client is not None:
            cpu += sum(client.run(_cpu).values()) - w0
        best, best_cpu = min(best, wall), min(best_cpu, cpu)
    return best, best_cpu, out


def six_d_grids(platform, n: int):
    home = platform.home_pose()
    span = 0.5 * (platform.L_max - platform.L_min)
    lin = [np.linspace(home[k] - span, home[k] + span, n) for k in range(3)]
    return lin + [np.linspace(-0.3, 0.3, n)] * 3


def plain_client(k: int):
    import distributed

    cluster = distributed.LocalCluster(n_workers=k, threads_per_worker=1, processes=True, dashboard_address=None)
    client = distributed.Client(cluster)
    client._stewart_owned_cluster = cluster
    return client


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--platform", default="gonzalez-dutra-2009")
    ap.add_argument("--resolution", type=float, default=0.0025, help="constant-orientation grid, m (default 2.5 mm)")
    ap.add_argument("--points", type=int, default=10, help="6-D grid points per axis (poses = points^6; default 10)")
    ap.add_argument("--workers", default="1,2", help="comma-separated worker counts (default 1,2)")
    ap.add_argument("--repeat", type=int, default=2, help="best of this many timings (default 2)")
    ap.add_argument("--modes", default="plain,tuned")
    args = ap.parse_args(argv)
    p = load_preset(args.platform)
    grids = six_d_grids(p, args.points)
    total = args.points**6
    t_co, cpu_co, w_ser = best_of(args.repeat, ws.constant_orientation_workspace, p, resolution=args.resolution)
    t_6d, cpu_6d, c_ser = best_of(args.repeat, ws.count_reachable, p, grids)
    print(
        f"{args.platform}: workspace at {args.resolution * 1e3:g} mm ({math.prod(len(a) for a in w_ser.axes):,} nodes), "
        f"6-D count of {total:,} poses"
    )
    print(f"serial: workspace {t_co:.2f} s (CPU {cpu_co:.2f} s), 6-D {t_6d:.2f} s (CPU {cpu_6d:.2f} s)")
    report = {"serial": {"workspace_s": t_co, "workspace_cpu_s": cpu_co, "six_d_s": t_6d, "six_d_cpu_s": cpu_6d}}
    for k in (int(x) for x in args.workers.split(",")):
        for mode in args.modes.split(","):
            client = plain_client(k) if mode == "plain" else wd.local_client(n_workers=k)
            try:
                if mode == "plain":
                    ex = wd.dask_executor(client)
                    tc, cc, w = best_of(
                        args.repeat,
                        ws.constant_orientation_workspace,
                        p,
                        resolution=args.resolution,
                        executor=ex,
                        client=client,
                    )
                    t6, c6, c = best_of(args.repeat, ws.count_reachable, p, grids, executor=ex, client=client)
                else:
                    run_co = lambda: wd.workspace_on_dask(p, client=client, resolution=args.resolution)  # noqa: E731
                    run_6d = lambda: wd.count_reachable_on_dask(p, grids, client=client)  # noqa: E731
                    tc, cc, w = best_of(args.repeat, run_co, client=client)
                    t6, c6, c = best_of(args.repeat, run_6d, client=client)
            finally:
                wd.close_client(client)
            same = (
                w.inside_nodes == w_ser.inside_nodes
                and np.array_equal(w.extents, w_ser.extents)
                and c["count"] == c_ser["count"]
            )
            r = {
                "workspace_s": tc,
                "workspace_ratio": t_co / tc,
                "workspace_efficiency": t_co / tc / k,
                "workspace_cpu_ratio": cpu_co / cc,
                "six_d_s": t6,
                "six_d_ratio": t_6d / t6,
                "six_d_efficiency": t_6d / t6 / k,
                "six_d_cpu_ratio": cpu_6d / c6,
                "same_result": bool(same),
            }
            report[f"{mode}/{k}"] = r
            print(
                f"{mode:5s} {k:2d} workers: workspace {tc:6.2f} s ×{r['workspace_ratio']:.2f} (eff {r['workspace_efficiency']:.0%}, "
                f"cpu ratio {r['workspace_cpu_ratio']:.2f})   6-D {t6:6.2f} s ×{r['six_d_ratio']:.2f} (eff {r['six_d_efficiency']:.0%}, "
                f"cpu ratio {r['six_d_cpu_ratio']:.2f})   same result: {same}",
                flush=True,
            )
    print(json.dumps(report, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
