"""The report's ℓ1 gain (``drake.simulation.setpoint_step_gain``): what its set-point step runs cost.

1. CPU seconds per simulated second, in one run, best of ``--repeat``: the float loop on the seed trajectory,
   and the ℓ1 gain's two runs (at rest, and with the 1 mm set-point offset on leg 1): all on the compiled loop
   (``firmware.loop_kernel``: the offset is in its set-point table), so they cost what the loop costs.
2. The doubling of the controller-in-the-loop section for utn-kinematic's rotating gains (6 s not settled,
   so 12 s): continuing the runs (``settle``/``max_duration``: ``Simulation.extend``) against running 6 s and
   then 12 s afresh (what the section did before); both give the same numbers, bit for bit (asserted).

CPU time (``time.process_time``), not wall: on a shared machine it is the runs' own cost (the load is printed).
Run by hand:  .venv/bin/python benchmarks/bench_l1_gain.py [--repeat 3]
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from stewart_drake.analyses.controller_in_the_loop import L1_MAX_S, L1_S, L1_SETTLED, loop_plan
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.trajectory import ROTATING, fit_trajectory
from stewart_drake.drake.simulation import Scenario, _setpoint_step_runs, build_simulation, setpoint_step_gain


def cpu(f) -> float:
    """CPU seconds of ``f()``."""
    t0 = time.process_time()
    f()
    return time.process_time() - t0


def per_simulated_second(p, duration: float, repeat: int) -> dict:
    """Best-of-``repeat`` CPU seconds per simulated second of the float loop and of the ℓ1 runs."""
    out: dict[str, list] = {}
    for _ in range(repeat):
        sim = build_simulation(Scenario(p, "seed", "float"))
        out.setdefault("float loop, seed trajectory", []).append(cpu(lambda: sim.run(duration)))
        rest, step = _setpoint_step_runs(p, None, 0, 1e-3, None)
        assert rest.controller.kernel is not None and step.controller.kernel is not None  # the compiled loop
        out.setdefault("ℓ1 run at rest", []).append(cpu(lambda: rest.run(duration)))
        out.setdefault("ℓ1 run, 1 mm set-point offset", []).append(cpu(lambda: step.run(duration)))
    return {k: min(v) / duration for k, v in out.items()}


def doubling(repeat: int) -> tuple[float, float]:
    """Best-of-``repeat`` CPU seconds of utn-kinematic's rotating ℓ1 gain: continued, and re-run afresh."""
    p = load_preset("utn-kinematic")
    cfg = loop_plan(p, fit_trajectory(ROTATING, p), "float", 4.0).config
    continued, fresh = [], []
    for _ in range(repeat):
        got = {}
        continued.append(
            cpu(
                lambda: got.update(
                    a=setpoint_step_gain(p, cfg, duration=L1_S, settle=L1_SETTLED, max_duration=L1_MAX_S)
                )
            )
        )

        def afresh():
            d = L1_S
            while True:
                g = setpoint_step_gain(p, cfg, duration=d)
                if g["settled"] <= L1_SETTLED or 2 * d > L1_MAX_S:
                    got["b"] = g
                    return
                d *= 2

        fresh.append(cpu(afresh))
        assert all(np.array_equal(got["a"][k], got["b"][k]) for k in got["a"]), "continued ≠ afresh"
    assert got["a"]["t"][-1] == 2 * L1_S  # it did double once
    return min(continued), min(fresh)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--duration", type=float, default=4.0, help="simulated seconds per run of part 1")
    args = ap.parse_args(argv)
    rates = per_simulated_second(load_preset("utn-dynamic"), args.duration, args.repeat)
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    print(
        f"utn-dynamic, cenic-fixed, 1 ms plant step, {args.duration:g} s per run, best of {args.repeat} (load average {load}):"
    )
    base = rates["float loop, seed trajectory"]
    for name, r in rates.items():
        print(
            f"  {name:32s} {r * 1e3:6.1f} ms CPU per simulated s ({1 / r:5.1f}x real time, {r / base:.2f} × the float loop)"
        )
    c, f = doubling(args.repeat)
    print(
        f"utn-kinematic rotating ℓ1 gain ({L1_S:g} s not settled → {2 * L1_S:g} s): continued {c:.2f} s CPU, "
        f"re-run afresh {f:.2f} s ({c / f:.2f}×; same numbers, bit for bit)"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
