"""Real-time FK (``core.realtime_fk``): the compiled Newton with its branch certificate vs the numpy Newton
(``newton_fk.forward_kinematics``), per call from Python and batched, in one run.

Run by hand: ``python benchmarks/bench_realtime_fk.py [--n 100000] [--repeat 5]``. The two sides are timed
interleaved, best of ``--repeat``; each line prints its target beside the figure and its reference, and
the load (``uptime``) is printed first and last: on a shared machine the ratios are what travel. Single
core: OMP/OPENBLAS threads are set to 1 before numpy loads. References from the same run: the numpy Newton
(per call and batched) and a memory copy of the length sets. Agreement with the numpy Newton is printed
where certified and over all: near a singularity (uncertified, uniqueness radius below 0.1 mm) both
Newtons' answers differ by the conditioning times rounding.
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from stewart_drake.core.geometry import load_preset  # noqa: E402
from stewart_drake.core.kinematics import leg_lengths  # noqa: E402
from stewart_drake.core.newton_fk import forward_kinematics  # noqa: E402
from stewart_drake.core.realtime_fk import RealtimeFK  # noqa: E402
from stewart_drake.core.sampling import random_poses  # noqa: E402

PER_CALL_TARGET_US = 10.0
BATCH_TARGET = 1e6


def load() -> str:
    return "load average " + ", ".join(f"{x:.2f}" for x in os.getloadavg())


def interleaved(fns: dict, repeat: int) -> dict:
    """Best-of-``repeat`` (wall, process CPU) seconds per function, the functions run in turn within each
    repetition (CPU time: on a shared machine wall time includes waiting for a core)."""
    best = {k: (np.inf, np.inf) for k in fns}
    for _ in range(repeat):
        for k, f in fns.items():
            t0, c0 = time.perf_counter(), time.process_time()
            f()
            t, c = time.perf_counter() - t0, time.process_time() - c0
            best[k] = (min(best[k][0], t), min(best[k][1], c))
    return best


def trajectory(p, n: int) -> np.ndarray:
    """``(n, 6)`` poses of a smooth motion sampled at 1 kHz (tens of mm, tenths of a radian)."""
    t = np.arange(n)[:, None] * 1e-3
    amp = np.r_[0.02, 0.015, 0.01, 0.05, 0.04, 0.1]
    return p.home_pose() + amp * np.sin(2 * np.pi * 0.5 * t + np.arange(6))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=100_000, help="length sets per batch")
    ap.add_argument("--calls", type=int, default=2_000, help="single calls timed")
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args(argv)
    print(f"# real-time FK; {load()}")
    for name in ("utn-dynamic", "gonzalez-dutra-2009", "utn-kinematic"):
        p = load_preset(name)
        fk = RealtimeFK(p, engine="c")
        q = random_poses(p, args.n, seed=1, region="workspace")
        L = leg_lengths(p, q)
        q0 = q + 1e-3  # the previous pose 1 mm / 1 mrad off
        Ltr = leg_lengths(p, trajectory(p, args.n))
        m = args.calls
        scratch = np.empty_like(L)

        def c_calls():
            for k in range(m):
                fk.solve(L[k], q0[k])

        def np_calls():
            for k in range(m // 10):
                forward_kinematics(p, L[k], q0[k], check_singularity=False)

        tc = interleaved(
            {
                "c_call": c_calls,
                "np_call": np_calls,
                "c_batch": lambda: fk.solve_batch(L, q0),
                "np_batch": lambda: forward_kinematics(p, L, q0, check_singularity=False),
                "c_track": lambda: fk.track(Ltr, trajectory(p, 1)[0]),
                "copy": lambda: np.copyto(scratch, L),
            },
            args.repeat,
        )
        t = {k: v[0] for k, v in tc.items()}
        c = {k: v[1] for k, v in tc.items()}
        r = fk.solve_batch(L, q0)
        ref = forward_kinematics(p, L, q0, check_singularity=False)
        tr = fk.track(Ltr, trajectory(p, 1)[0])
        us_c, us_np = 1e6 * t["c_call"] / m, 1e6 * t["np_call"] / (m // 10)
        rate_c, rate_np, rate_tr = args.n / t["c_batch"], args.n / t["np_batch"], args.n / t["c_track"]
        cpu_c, cpu_tr = args.n / c["c_batch"], args.n / c["c_track"]
        cpu_np, cpu_copy = args.n / c["np_batch"], args.n / c["copy"]
        print(f"\n## {name}: {args.n} length sets, previous pose 1 mm / 1 mrad off; track: a 1 kHz trajectory")
        print(
            f"per call from Python: {us_c:7.2f} µs, {1e6 * c['c_call'] / m:5.2f} CPU µs (target <= {PER_CALL_TARGET_US:.0f} µs)   "
            f"numpy Newton per call {us_np:7.1f} µs -> {us_np / us_c:.0f}x"
        )
        print(
            f"batched:              {rate_c:9.3g} solves/s, {cpu_c:9.3g} per CPU s (target >= {BATCH_TARGET:.0e})   "
            f"numpy Newton batched {rate_np:9.3g} solves/s, {cpu_np:9.3g} per CPU s -> {cpu_c / cpu_np:.1f}x; "
            f"memory copy of the length sets {cpu_copy:9.3g} rows per CPU s ({cpu_copy / cpu_c:.0f}x the solves)"
        )
        print(
            f"track (1 kHz motion): {rate_tr:9.3g} solves/s, {cpu_tr:9.3g} per CPU s (target >= {BATCH_TARGET:.0e}), "
            f"{tr.iterations.mean():.2f} Newton iterations per solve, certified {tr.certified.mean():.4f}"
        )
        d = np.abs(r.poses - ref.poses)
        dp, da = np.nanmax(d[:, :3]), np.nanmax(d[:, 3:])
        cp = np.nanmax(d[r.certified, :3]) if r.certified.any() else np.nan
        over = int(np.sum(np.nanmax(d[:, :3], axis=1) > 1e-12))
        print(
            f"same answer: max |compiled - numpy| = {cp:.2e} m where certified (target <= 1e-12), {dp:.2e} m over all "
            f"({over} solves above 1e-12 m, {int(np.sum(r.certified & (np.nanmax(d[:, :3], axis=1) > 1e-12)))} of them certified), "
            f"{da:.2e} rad; certified {r.certified.mean():.4f}, median uniqueness radius {1e3 * np.median(r.radius):.1f} mm, "
            f"{r.iterations.mean():.2f} iterations per solve"
        )
    print(f"\n# {load()}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
