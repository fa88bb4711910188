"""Firmware in the loop: what the compiled C engine costs against the Python emulation.

1. Real-time factors at 1 kHz on utn-dynamic (seed trajectory, the default integrator), in one run: the plant
   alone (held at home by its static leg forces), the fixed-point controller with the Python engine, and with the C engine
   (the loop's compiled kernel calling the generated firmware's sd_tick, ``firmware.loop_kernel``) with its feed-forward
   table computed and remembered; the ratios to the plant alone beside the target (>= 0.8).
2. The per-tick cost of the controller's ``compute`` alone (Python law vs one ``sd_tick`` call).
3. IK throughput, single-threaded batch calls: the generated ``sd_ik`` (poses/s, by wall clock and by the
   process's CPU time: on a shared machine the latter is the call's own cost), the compiled tp17.C, and
   the numpy emulations for comparison.

Run by hand:  .venv/bin/python benchmarks/bench_firmware.py [--duration 4] [--poses 2000000]
Compiled modules are cached (``$STEWART_DRAKE_CACHE``); the first run also compiles them.
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("MPLBACKEND", "Agg")

import numpy as np  # noqa: E402
from bench_integrators import bare_plant  # noqa: E402  (benchmarks/ is the script's folder)

from stewart_drake.drake.integrators import DEFAULT_INTEGRATOR  # noqa: E402

TARGET = 0.8  # the C engine's loop over the bare plant's real-time factor (the speed issue, item 1)


def load() -> str:
    return "load average " + ", ".join(f"{x:.2f}" for x in os.getloadavg())


def loop_rtf(p, engine, duration, cold=True):
    """Real-time factor (wall clock) of one fixed-point closed loop with ``engine``; ``cold``: its feed-forward
    table computed (``TABLE_CACHE`` cleared), else remembered from a run before (a study's later runs)."""
    from stewart_drake.control.feedforward import TABLE_CACHE
    from stewart_drake.drake.simulation import Scenario, build_simulation

    sim = build_simulation(Scenario(p, "seed", "fixed", engine=engine))
    if cold:
        TABLE_CACHE.clear()  # a run's own feed-forward table, not one remembered from the run before
    else:
        build_simulation(Scenario(p, "seed", "fixed", engine=engine)).prepare(duration)
    t0 = time.perf_counter()
    sim.run(duration)
    return duration / (time.perf_counter() - t0), sim


def best_rate(fn, n, repeats=3):
    return best_rates(fn, n, repeats)[0]


def best_rates(fn, n, repeats=3):
    """Best items/s over ``repeats`` calls, by wall clock and by this process's CPU time (the latter is
    what a single-threaded call costs on a shared, loaded machine)."""
    wall = cpu = 0.0
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        fn()
        t1, c1 = time.perf_counter(), time.process_time()
        wall, cpu = max(wall, n / (t1 - t0)), max(cpu, n / max(c1 - c0, 1e-9))
    return wall, cpu


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--duration", type=float, default=4.0, help="simulated seconds per closed-loop run (default 4)")
    ap.add_argument("--poses", type=int, default=2_000_000, help="poses per IK batch (default 2e6)")
    args = ap.parse_args(argv)

    from stewart_drake.control import ControllerConfig
    from stewart_drake.core.geometry import load_preset
    from stewart_drake.firmware.check import workspace_poses
    from stewart_drake.firmware.generate import generate
    from stewart_drake.firmware.host import tp17_leg_lengths_c
    from stewart_drake.firmware.module import compile_generated
    from stewart_drake.fixedpoint import tp17_leg_lengths
    from stewart_drake.fixedpoint.generic import leg_length_words, pose_words

    p = load_preset("utn-dynamic")
    loop_rtf(p, "c", 0.01)  # compile and cache the module before timing
    plant = bare_plant(p, DEFAULT_INTEGRATOR, args.duration)["realtime_factor"]  # the closed loops' integrator
    py, sim_py = loop_rtf(p, "python", args.duration)
    c, sim_c = loop_rtf(p, "c", args.duration)
    c_warm, _ = loop_rtf(p, "c", args.duration, cold=False)
    print(
        f"1 kHz, plant under {DEFAULT_INTEGRATOR}, {args.duration:g} s of the seed trajectory on utn-dynamic (real-time factors, wall clock, one run; {load()}):"
    )
    print(f"  plant alone (the reference):                             {plant:6.2f}x")
    print(f"  fixed-point controller, Python engine:                   {py:6.2f}x  ({py / plant:.2f} × plant alone)")
    for label, rtf in (("C engine, tables computed (cold)", c), ("C engine, tables remembered", c_warm)):
        met = "met" if rtf / plant >= TARGET else "NOT met"
        print(
            f"  fixed-point controller, {label:33s}{rtf:6.2f}x  ({rtf / plant:.2f} × plant alone, target >= {TARGET}: "
            f"{met}; {rtf / py:.2f} × the Python engine)"
        )

    # the controller's compute alone, on the state and inputs of the last tick
    for name, sim in (("Python", sim_py), ("C", sim_c)):
        ctrl = sim.controller.law
        ref, L = p.home_pose(), np.full(6, 0.7)
        pid = ctrl.initial_pid_state(L, np.zeros(6))
        ff = np.zeros(6)
        ctrl.prime(ref[None])  # as in the run: the reference's IK / pose words are looked up
        ctrl.step(pid, ref, L, ff)
        n = 3000
        rate = best_rate(lambda: [ctrl.step(pid, ref, L, ff) for _ in range(n)], n)
        print(f"  law.step() per tick, {name:6s} engine: {1e6 / rate:7.1f} µs")

    cfg = ControllerConfig.for_platform(p)
    g = generate(p, cfg)
    m = compile_generated(g, opt="-O3")  # the optimised build (the default, module.HOST_OPT, compiles faster)
    q = workspace_poses(p, min(args.poses, 200_000), seed=1)
    w = pose_words(np.resize(q, (args.poses, 6)), cfg.ik_format)
    w16 = np.ascontiguousarray(w, dtype=m.word_dtype)
    out = np.empty_like(w16)
    m.ik_raw(w16[:1000], out[:1000])
    r_c, r_c_cpu = best_rates(lambda: m.ik_raw(w16, out), len(w16))
    n_py = min(len(w), 200_000)
    r_py, _ = best_rates(lambda: leg_length_words(p, w[:n_py], cfg.ik_format, cfg.convention), n_py, repeats=2)
    print(f"generated sd_ik (utn-dynamic, 16-bit words, tfr16), one thread, batch of {len(w)} poses:")
    print(
        f"  {r_c / 1e6:6.2f} M poses/s wall clock, {r_c_cpu / 1e6:6.2f} M poses/s of process CPU time "
        f"({r_c / r_py:.0f} × the numpy emulation's {r_py / 1e6:.2f} M poses/s, wall)"
    )
    rng = np.random.default_rng(0)
    dq = np.c_[
        rng.integers(-150, 151, (args.poses, 2)),
        rng.integers(0, 400, args.poses),
        rng.uniform(-0.3, 0.3, (args.poses, 3)),
    ]
    tp17_leg_lengths_c(dq[:1000])
    r_t, r_t_cpu = best_rates(lambda: tp17_leg_lengths_c(dq), len(dq))
    n_py = min(len(dq), 200_000)
    r_tp, _ = best_rates(lambda: tp17_leg_lengths(dq[:n_py]), n_py, repeats=2)
    print(
        f"compiled tp17.C (with validation and conversions), batch of {len(dq)}: {r_t / 1e6:6.2f} M poses/s wall, "
        f"{r_t_cpu / 1e6:6.2f} M/s CPU ({r_t / r_tp:.1f} × the numpy port's {r_tp / 1e6:.2f} M poses/s)"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
