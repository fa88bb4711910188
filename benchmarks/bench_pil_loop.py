"""The processor-in-the-loop closed loop over 10⁶ ticks: ``simulate`` of a machine with the tick computed by the
Cortex-M4 build in QEMU (``pil.target``, default ``qemu:semihosting``) beside the same run with the host C
(``engine c``), the same plant, reference and seed. Every log (t, command, setpoint, force, status, lengths,
pose) must be equal bit for bit; the wall time per tick of each run, their ratio, the link's round trips and the
target's instructions per tick are printed, with the machine's load first and last.

    PYTHONPATH=. python benchmarks/bench_pil_loop.py [--machine utn-dynamic] [--ticks 1000000]
        [--target qemu:semihosting]

A run, quoted (defaults: utn-dynamic, 10⁶ ticks, ``qemu:semihosting``; 2-core machine, load 0.6-1.0): host C
loop 88.2 µs/tick; PIL loop 364.6 µs/tick (4.13 × host C, 2743 ticks/s); round trip median 166 µs, p99 255 µs,
max 25.5 ms; no tick without a command, target counters 1000003 frames and no fault; sd_tick 5680 instructions
worst, 5646.0 mean; every log equal bit for bit.

The seed motion repeats, so a long run keeps moving. ``--target qemu`` runs the UART build (about 4 ms a tick:
10⁶ ticks take over an hour); ``serial:PATH`` a board. Measures only; exits 1 if a log differs.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

import stewart_drake as sd
from stewart_drake.api.simulation import plan_run

LOGS = ("t", "command", "setpoint", "force", "status", "lengths", "pose")


def timed(machine: str, duration: float, **options) -> tuple:
    """(the run, its wall seconds)."""
    t0 = time.perf_counter()
    r = sd.simulate(machine, duration=duration, **options)
    return r, time.perf_counter() - t0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--machine", default="utn-dynamic", help="a preset or a machine file")
    ap.add_argument("--ticks", type=int, default=1_000_000, help="ticks of each run (at the machine's rate)")
    ap.add_argument("--target", default="qemu:semihosting", help="pil.target")
    a = ap.parse_args()
    print(f"load {os.getloadavg()[0]:.2f}", flush=True)
    period = plan_run(a.machine, duration=0.01).scenario.config.timing.sample_period
    duration = a.ticks * period
    host, t_host = timed(a.machine, duration, engine="c")
    print(f"host C: {host.summary['ticks']} ticks in {t_host:.1f} s", flush=True)
    pil, t_pil = timed(a.machine, duration, **{"pil.target": a.target})
    n = pil.summary["ticks"]
    differ = [k for k in LOGS if host.log[k].shape != pil.log[k].shape or not np.array_equal(host.log[k], pil.log[k])]
    r = pil.summary["pil"]
    rt, timing = r["round_trip_s"], r["timing"]
    print(f"{a.machine}, {n} ticks ({duration:g} s at {1 / period:g} Hz)")
    print(f"host C loop: {t_host / n * 1e6:.1f} µs/tick")
    print(
        f"PIL loop ({a.target}): {t_pil / n * 1e6:.1f} µs/tick ({t_pil / t_host:.2f} × host C, {n / t_pil:.0f} ticks/s)"
    )
    print(f"round trip: median {rt['median'] * 1e6:.0f} µs, p99 {rt['p99'] * 1e6:.0f} µs, max {rt['max'] * 1e3:.1f} ms")
    print(f"ticks without a command {r['ticks_without_command']}; target counters {r['target_counters']}")
    print(
        f"sd_tick on the target: {timing['instructions_worst']} instructions worst, {timing['instructions_mean']:.1f} mean"
    )
    print(
        "logs equal bit for bit: " + ("all of " + ", ".join(LOGS) if not differ else "NO, differ: " + ", ".join(differ))
    )
    print(f"load {os.getloadavg()[0]:.2f}")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
