"""Real-time factor of the controller-in-the-loop simulation (simulated seconds per wall-clock second).

Seed trajectory on utn-dynamic, plant step 1 ms (or the period if shorter), fixed-point and float
controllers, and how the cost scales with the controller rate. Run by hand:

    .venv/bin/python benchmarks/bench_simulation.py [--duration 4]

Build time (Diagram + Simulator) is reported apart from the run. Figures are ratios measured in one run.
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("MPLBACKEND", "Agg")

from bench_integrators import bare_plant  # noqa: E402  (benchmarks/ is the script's folder)

from stewart_drake.drake.integrators import DEFAULT_INTEGRATOR  # noqa: E402


def rtf(platform, kind, period, duration, plant_step=None):
    from stewart_drake.control import ControllerConfig, DspTiming
    from stewart_drake.core.trajectory import SEED
    from stewart_drake.drake.simulation import Scenario, build_simulation

    t0 = time.perf_counter()
    sim = build_simulation(
        Scenario(
            platform,
            SEED,
            kind,
            ControllerConfig(timing=DspTiming(sample_period=period)),
            plant_time_step=plant_step or min(period, 1e-3),
        )
    )
    t1 = time.perf_counter()
    sim.run(duration)
    t2 = time.perf_counter()
    return duration / (t2 - t1), t1 - t0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--duration", type=float, default=4.0, help="simulated seconds per run (default 4)")
    args = ap.parse_args(argv)
    from stewart_drake.core.geometry import load_preset

    p = load_preset("utn-dynamic")
    # the plant alone (held at home by its static leg forces), under the closed loops' integrator: the ceiling
    plant_rtf = bare_plant(p, DEFAULT_INTEGRATOR, args.duration)["realtime_factor"]
    print(f"plant alone ({DEFAULT_INTEGRATOR}):                real-time factor {plant_rtf:6.2f}x")
    for kind in ("fixed", "float"):
        r, build = rtf(p, kind, 1e-3, args.duration)
        print(f"{kind:5s} controller at 1 kHz, 1 ms plant: real-time factor {r:6.2f}x  (build {build:.2f} s)")
    print("scaling with the controller rate (fixed point; plant step = min(T, 1 ms)):")
    scaling = {period: rtf(p, "fixed", period, args.duration / 2)[0] for period in (4e-3, 2e-3, 1e-3, 5e-4, 2.5e-4)}
    for period, r in scaling.items():
        print(f"  {1 / period:7.0f} Hz: real-time factor {r:6.2f}x   ({r / scaling[1e-3]:.2f} × the 1 kHz figure)")
    print("controller rate at a fixed 0.25 ms plant step (isolates the controller's cost):")
    for period in (2e-3, 1e-3, 5e-4, 2.5e-4):
        r, _ = rtf(p, "fixed", period, args.duration / 4, plant_step=2.5e-4)
        print(f"  {1 / period:7.0f} Hz: real-time factor {r:6.2f}x")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
