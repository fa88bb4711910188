"""Where a closed-loop tick's microseconds go (item 1 of the speed issue): the plant alone, the loop with
the compiled firmware (C engine) and with the float law, and the same loop with the law's ``step``
replaced by a constant (what is left is the LeafSystems' own Python: port reads, state writes, the pose
and feed-forward sources) — all in one run, interleaved, best of ``--repeat``.

Run by hand: ``python benchmarks/bench_tick.py [--duration 2] [--repeat 3]``. At 1 kHz a simulated
millisecond is one tick, so µs per tick = 1000 / real-time factor. Prints the load (``uptime``) first and
last; on a shared machine the ratios are what travel. Measures only: it changes nothing in the loop.
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("MPLBACKEND", "Agg")

import numpy as np  # noqa: E402
from bench_integrators import bare_plant  # noqa: E402  (benchmarks/ is the script's folder)

from stewart_drake.core.geometry import load_preset  # noqa: E402
from stewart_drake.drake.integrators import DEFAULT_INTEGRATOR  # noqa: E402
from stewart_drake.drake.simulation import Scenario, build_simulation  # noqa: E402

TARGET = 0.8  # the loop's real-time factor over the bare plant's


def load() -> str:
    return "load average " + ", ".join(f"{x:.2f}" for x in os.getloadavg())


def loop(p, kind: str, engine: str, duration: float, null_step: bool = False) -> float:
    """Real-time factor of one closed-loop run (build excluded); ``null_step``: the law's step returns
    its first result every tick (the LeafSystem's Python around it still runs)."""
    sim = build_simulation(Scenario(p, "seed", kind, engine=engine))
    if null_step:
        law = sim.controller.law
        real = law.step
        first = []

        def step(state, reference, measured, feedforward=None):
            if not first:
                first.append(real(state, reference, measured, feedforward))
            return first[0]

        law.step = step
    t0 = time.perf_counter()
    sim.run(duration)
    return duration / (time.perf_counter() - t0)


def step_us(p, engine: str, n: int = 3000) -> float:
    """µs of one ``law.step`` alone (the C engine's: one sd_host_tick call and its Python)."""
    sim = build_simulation(Scenario(p, "seed", "fixed", engine=engine))
    law = sim.controller.law
    ref, L = p.home_pose(), np.full(6, 0.7)
    pid, ff = law.initial_pid_state(L, np.zeros(6)), np.zeros(6)
    if hasattr(law, "prime"):
        law.prime(ref[None])
    law.step(pid, ref, L, ff)
    t0 = time.perf_counter()
    for _ in range(n):
        law.step(pid, ref, L, ff)
    return 1e6 * (time.perf_counter() - t0) / n


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--duration", type=float, default=2.0)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    print(f"# closed-loop tick breakdown, utn-dynamic, seed trajectory, {DEFAULT_INTEGRATOR}; {load()}")
    p = load_preset("utn-dynamic")
    loop(p, "fixed", "c", 0.01)  # compile and cache the firmware before timing
    runs = {
        "plant": lambda: bare_plant(p, DEFAULT_INTEGRATOR, args.duration)["realtime_factor"],
        "fixed, C engine": lambda: loop(p, "fixed", "c", args.duration),
        "fixed, C, null step": lambda: loop(p, "fixed", "c", args.duration, null_step=True),
        "float": lambda: loop(p, "float", "python", args.duration),
        "float, null step": lambda: loop(p, "float", "python", args.duration, null_step=True),
    }
    best = dict.fromkeys(runs, 0.0)
    for _ in range(args.repeat):
        for k, f in runs.items():
            best[k] = max(best[k], f())
    us = {k: 1e3 / v for k, v in best.items()}
    for k, v in best.items():
        extra = "" if k == "plant" else f"  ({v / best['plant']:.2f} × plant; target >= {TARGET} × plant)"
        print(f"{k:22s} real-time factor {v:6.2f}x = {us[k]:6.1f} µs per tick{extra}")
    for kind, full, null in (
        ("fixed/C", "fixed, C engine", "fixed, C, null step"),
        ("float", "float", "float, null step"),
    ):
        sys_us = us[null] - us["plant"]
        law_us = us[full] - us[null]
        print(
            f"{kind:8s} tick {us[full]:6.1f} µs = plant {us['plant']:6.1f} + LeafSystems' Python (ports, state, sources) "
            f"{sys_us:5.1f} + law.step {law_us:5.1f}"
        )
    print(f"law.step alone, C engine: {step_us(p, 'c'):.1f} µs per call (of it the sd_host_tick C call is < 1 µs)")
    print(f"# {load()}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
