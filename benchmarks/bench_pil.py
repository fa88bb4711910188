"""The PIL link's cost per tick beside the host C's: a closed-loop run's sensor stream (utn-dynamic, the seed
motion, ``--record`` s of the host-C loop: its reference poses and measured leg lengths at each tick) replayed
``--ticks`` times in a row through (a) ``sd_tick`` compiled for the host and called through cffi (``TickRunner``:
the host-C loop's tick) and (b) the PIL link to the Cortex-M4 build in QEMU (``firmware.pil_target``), one
SENSOR/COMMAND exchange a tick in lock step. The plant is replaced by the replayed log so that the link alone is
timed; the two streams of commands are compared tick by tick (they must be equal: the same ``sd_tick``, the same
state from ``sd_init``).

A run, quoted (``--ticks 100000 --record 2``, 2-core machine at load 9-11): host C 9.88 µs/tick, PIL over QEMU
4258 µs/tick (235 ticks/s, 431 × the host C), commands equal 100000/100000; 10⁶ ticks would take ~70 min.

Run by hand: ``python benchmarks/bench_pil.py [--ticks 1000000] [--record 2]``. Prints wall µs per tick for
each, their ratio, the QEMU ticks/s and the load first and last. Measures only. On a 2-core machine shared with
other work QEMU passes 50-200 ticks/s (each byte of a frame is one trip through its UART model: see
docs/simulation-to-board.md), so 10⁶ ticks take hours: ``--ticks`` sizes the run.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

import stewart_drake as sd
from stewart_drake.api.simulation import plan_run
from stewart_drake.firmware.generate import generate
from stewart_drake.firmware.link import LinkHost, format_fingerprint
from stewart_drake.firmware.module import TickRunner, compile_generated
from stewart_drake.firmware.pil import program_module
from stewart_drake.firmware.pil_target import QemuTarget, target_elf
from stewart_drake.fixedpoint.generic import pose_words

PLATFORM = "utn-dynamic"


def stream(record: float) -> tuple:
    """(pose words, measured counts) at each tick of a ``record`` s host-C run, and the run's scenario."""
    plan = plan_run(PLATFORM, duration=record, engine="c")
    sc, r = plan.scenario, sd.simulate(PLATFORM, duration=record, engine="c")
    t, tick = r.log["t"], r.log["t_ref"]
    rows = np.searchsorted(t, tick)  # the plant's state logged at each tick (the tick reads it there)
    L = r.log["lengths"][rows]
    counts = np.rint(L / sc.config.timing.sensor_resolution).astype(np.int64)
    return pose_words(r.log["reference"], sc.config.ik_format), counts, sc


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--ticks", type=int, default=1_000_000)
    ap.add_argument("--record", type=float, default=2.0, help="seconds of the closed loop replayed")
    a = ap.parse_args()
    print(f"load {os.getloadavg()[0]:.2f}")
    words, counts, sc = stream(a.record)
    files = program_module(sc.platform, sc.config)
    n = len(words)
    runner = TickRunner(compile_generated(generate(sc.platform, sc.config)))
    t0 = time.perf_counter()
    host = [runner.tick(words[k % n], counts[k % n], None) for k in range(a.ticks)]
    t_host = (time.perf_counter() - t0) / a.ticks
    target = QemuTarget(target_elf(files))
    try:
        link = LinkHost(target.write, target.read, format_fingerprint(files["sd_firmware.h"].splitlines()[0]))
        link.handshake(30.0)
        t0 = time.perf_counter()
        same = 0
        for k in range(a.ticks):
            r = link.tick(words[k % n], counts[k % n], None, timeout=30.0)
            same += list(r.command) == list(host[k])
        t_pil = (time.perf_counter() - t0) / a.ticks
    finally:
        target.close()
    print(f"{a.ticks} ticks ({n} replayed): host C {t_host * 1e6:.2f} µs/tick, PIL over QEMU {t_pil * 1e6:.0f} µs/tick")
    print(f"ratio PIL / host C: {t_pil / t_host:.0f}; QEMU {1 / t_pil:.0f} ticks/s; equal commands {same}/{a.ticks}")
    print(f"load {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
