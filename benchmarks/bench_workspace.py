"""Workspace throughput and scaling (run by hand: ``.venv/bin/python benchmarks/bench_workspace.py``).

Prints, from one run on this machine:
1. poses classified per second: the constant-orientation grid kernel, general (..., 6) poses through
   ``kinematics.leg_vectors``, and the optional limits (joint cones, leg collision, dexterity);
2. the paper's analysis (seed 001: workspace at zero orientation + six rotation limits) at 2.5 mm;
3. time and peak traced memory against resolution, and memory against the slab size;
4. the sweep on 1 vs 2 worker processes, and on a local Dask cluster if installed.
Figures are ratios and rates measured in this run, never pass/fail.
"""

from __future__ import annotations

import argparse
import math
import time
import tracemalloc

import numpy as np

from stewart_drake import workspace as ws
from stewart_drake.core.geometry import load_preset


def timed(fn, *args, repeat=1, **kwargs):
    best, out = math.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn(*args, **kwargs)
        best = min(best, time.perf_counter() - t0)
    return best, out


def peak_mib(fn, *args, **kwargs) -> float:
    tracemalloc.start()
    fn(*args, **kwargs)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return peak / 2**20


def nodes(w) -> int:
    return math.prod(len(a) for a in w.axes)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--fine", action="store_true", help="also run 1.25 mm (about 8x the 2.5 mm cost)")
    ap.add_argument("--no-parallel", action="store_true", help="skip the process-pool and Dask runs")
    args = ap.parse_args(argv)
    p = load_preset("gonzalez-dutra-2009")

    print("1. poses classified per second")
    t, w = timed(ws.constant_orientation_workspace, p, resolution=0.005, refine=False, repeat=3)
    grid_rate = nodes(w) / t
    print(f"   grid kernel, stroke, 5 mm grid ({nodes(w):,} nodes): {grid_rate:,.0f} /s")
    rng = np.random.default_rng(0)
    q = np.tile(p.home_pose(), (200_000, 1))
    q[:, :3] += rng.uniform(-0.3, 0.3, (len(q), 3))
    q[:, 3:] += rng.uniform(-0.5, 0.5, (len(q), 3))
    rates = {}
    for name, lim in [
        ("stroke", ws.Limits()),
        ("stroke + joint cones", ws.Limits(base_cone=0.7, top_cone=0.7)),
        ("stroke + collision", ws.Limits(leg_diameter=0.1)),
        ("stroke + dexterity", ws.Limits(max_condition=10)),
    ]:
        n = len(q) if name != "stroke + dexterity" else 50_000
        t, inside = timed(ws.classify, p, q[:n], lim, repeat=2)
        rates[name] = n / t
        print(f"   general 6-D poses, {name:22s}: {rates[name]:>12,.0f} /s   ({inside.mean():.1%} inside)")
    print(f"   ratio grid kernel / general stroke classification: {grid_rate / rates['stroke']:.1f}x")

    print("2. the paper's analysis at 2.5 mm (workspace + extents refinement + six rotation limits)")
    t_ws, w = timed(ws.constant_orientation_workspace, p, resolution=0.0025)
    t_rot, _ = timed(ws.orientation_limits, p)
    print(
        f"   workspace {t_ws:.2f} s ({nodes(w):,} nodes, volume {w.volume * 1e3:.3f} ± {w.volume_error * 1e3:.3f} L), "
        f"rotation limits {t_rot * 1e3:.1f} ms, total {t_ws + t_rot:.2f} s"
    )

    print("3. time and peak memory against resolution (slab 2^21 nodes)")
    print(f"   {'h (mm)':>7} {'nodes':>12} {'time (s)':>9} {'peak (MiB)':>10} {'time ratio':>10} {'memory ratio':>12}")
    steps = [0.02, 0.01, 0.005, 0.0025] + ([0.00125] if args.fine else [])
    prev = None
    for h in steps:
        t, w = timed(ws.constant_orientation_workspace, p, resolution=h)
        mem = peak_mib(ws.constant_orientation_workspace, p, resolution=h)
        ratio = "" if prev is None else f"{t / prev[0]:10.1f} {mem / prev[1]:12.1f}"
        print(f"   {h * 1e3:7.2f} {nodes(w):12,} {t:9.2f} {mem:10.1f} {ratio}")
        prev = (t, mem)
    print("   (nodes x8 per halving; memory grows with the slab, the views and the boundary, not the volume)")
    print("   peak memory against the slab size at 2.5 mm:")
    for chunk in (1 << 16, 1 << 19, 1 << 21, 1 << 23):
        mem = peak_mib(ws.constant_orientation_workspace, p, resolution=0.0025, chunk_nodes=chunk, refine=False)
        print(f"     slab {chunk:>9,} nodes: {mem:7.1f} MiB")

    if not args.no_parallel:
        import os

        print(
            f"4. back ends: 1 vs 2 worker processes (load average now {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs)"
        )
        lim = ws.Limits(base_cone=0.9, top_cone=0.9, leg_diameter=0.1)
        h = p.home_pose()
        grids = [np.linspace(-0.3, 0.3, 13)] * 2 + [h[2] + np.linspace(-0.2, 0.2, 9)] + [np.linspace(-0.4, 0.4, 9)] * 3
        jobs = [
            (
                "stroke grid, 2.5 mm",
                ws.constant_orientation_workspace,
                (p,),
                dict(resolution=0.0025, chunk_nodes=1 << 19, refine=False),
            ),
            (
                "joints + collision grid, 5 mm",
                ws.constant_orientation_workspace,
                (p,),
                dict(resolution=0.005, limits=lim, chunk_nodes=1 << 18, refine=False),
            ),
            (
                f"6-D sweep, {math.prod(len(g) for g in grids):,} poses",
                ws.count_reachable,
                (p, grids),
                dict(chunk=1 << 16),
            ),
        ]
        serial = {}
        for name, fn, a, kw in jobs:
            t1, _ = timed(fn, *a, **kw)
            t2, _ = timed(fn, *a, workers=2, **kw)
            serial[name] = (fn, a, kw, t1)
            print(
                f"   {name:32s}: 1 process {t1:6.2f} s, 2 processes {t2:6.2f} s -> speed-up {t1 / t2:.2f}x (incl. pool start)"
            )
        try:
            from stewart_drake.workspace.dask_sweep import close_client, dask_executor, local_client
        except ImportError:
            print("   dask: not installed")
        else:
            try:
                client = local_client(n_workers=2)
            except ImportError as e:
                print(f"   dask: {e}")
            else:
                try:
                    ex = dask_executor(client)
                    for name, (fn, a, kw, t1) in serial.items():
                        td, _ = timed(fn, *a, executor=ex, **kw)
                        print(
                            f"   {name:32s}: dask LocalCluster (2 workers) {td:6.2f} s -> {t1 / td:.2f}x the single process"
                        )
                finally:
                    close_client(client)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
