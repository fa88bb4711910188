"""The PIL link's cost per tick beside the host C's: a closed-loop run's sensor stream (utn-dynamic, the seed motion,
``--record`` s of the host-C loop: its reference poses and measured leg lengths at each tick) replayed in a row
through (a) ``sd_tick`` compiled for the host and called through cffi (``TickRunner``: the host-C loop's tick),
``--ticks`` times; (b) the PIL link to the host build of the PIL program (``sd_pil_stdio.c``) behind two pipes,
``--ticks`` times: the link's framing, CRC, sequence checks and a process round trip; (c) the link to the Cortex-M4
build in QEMU on its UART (``pil.target qemu``), ``--qemu-ticks`` times; (d) the link to the semihosting build in
QEMU (``pil.target qemu:semihosting``), ``--semihosting-ticks`` times. One SENSOR/COMMAND exchange a tick in lock
step; the plant is replaced by the replayed log so that the link alone is timed; every command is compared with the
host C's (the same ``sd_tick``, the same state from ``sd_init``: they must be equal).

A run, quoted (``--ticks 1000000 --qemu-ticks 10000 --record 2``, 2-core machine at load 5-7): host C 4.65 µs/tick;
the link to a pipe 137.9 µs/tick (29.6 × host C), commands equal 1000000/1000000; the link to QEMU 4468 µs/tick (960
× host C, 224 ticks/s), commands equal 10000/10000. An earlier run of 10⁵ ticks to QEMU (load 9-11): 4258 µs/tick,
235 ticks/s, equal 100000/100000. QEMU's UART model takes one byte per trip through its main loop: 10⁶ ticks over it
would take about 75 min; the semihosting console takes a frame a call (``--ticks 100000 --qemu-ticks 5000
--semihosting-ticks 100000``, load 0.1-0.4: host C 2.34 µs/tick, a pipe 92.6, the UART 2986, semihosting 123.5
µs/tick: 24.2 × faster than the UART, commands equal 100000/100000). The whole closed loop over 10⁶ ticks:
``bench_pil_loop.py``.

Run by hand: ``python benchmarks/bench_pil.py [--ticks 1000000] [--qemu-ticks 10000] [--semihosting-ticks 100000]
[--record 2]``. Prints wall µs per tick for each, their ratios to the host C, the QEMU ticks/s and the load first
and last. Measures only.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

import stewart_drake as sd
from stewart_drake.api.simulation import plan_run
from stewart_drake.firmware.generate import generate
from stewart_drake.firmware.link import LinkHost, format_fingerprint, pipe_reader
from stewart_drake.firmware.module import TickRunner, compile_generated
from stewart_drake.firmware.pil import program_module
from stewart_drake.firmware.pil_target import QemuTarget, target_elf
from stewart_drake.firmware.target_build import build_host
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


def through(target, files, words, counts, ticks: int, host: list) -> tuple[float, int]:
    """(wall s per tick, ticks whose command equals ``host``'s) of ``ticks`` lock-step exchanges with ``target``."""
    n = len(words)
    try:
        link = LinkHost(target.write, target.read, format_fingerprint(files["sd_firmware.h"].splitlines()[0]))
        link.handshake(30.0)
        t0 = time.perf_counter()
        same = 0
        for k in range(ticks):
            r = link.tick(words[k % n], counts[k % n], None, timeout=30.0)
            same += list(r.command) == host[k].tolist()
        return (time.perf_counter() - t0) / ticks, same
    finally:
        target.close()


class PipeTarget:
    """The host build of the PIL program (``sd_pil_stdio.c``) behind two pipes."""

    def __init__(self, exe: Path):
        self.p = subprocess.Popen([str(exe)], stdin=subprocess.PIPE, stdout=subprocess.PIPE, bufsize=0)
        self.read, self.write = pipe_reader(self.p.stdout.fileno()), self.p.stdin.write

    def close(self) -> None:
        self.p.stdin.close()
        self.p.wait(10)
        self.p.stdout.close()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--ticks", type=int, default=1_000_000, help="through the host C and the link to a pipe")
    ap.add_argument("--qemu-ticks", type=int, default=10_000, help="through the link to QEMU's UART")
    ap.add_argument("--semihosting-ticks", type=int, default=100_000, help="through the link to QEMU's semihosting")
    ap.add_argument("--record", type=float, default=2.0, help="seconds of the closed loop replayed")
    a = ap.parse_args()
    print(f"load {os.getloadavg()[0]:.2f}")
    words, counts, sc = stream(a.record)
    files = program_module(sc.platform, sc.config)
    n = len(words)
    runner = TickRunner(compile_generated(generate(sc.platform, sc.config)))
    t0 = time.perf_counter()
    host = np.empty((max(a.ticks, a.qemu_ticks, a.semihosting_ticks), 6), dtype=np.int16)  # the commands, Q15 words
    for k in range(len(host)):
        host[k] = runner.tick(words[k % n], counts[k % n], None)
    t_host = (time.perf_counter() - t0) / len(host)
    with tempfile.TemporaryDirectory() as work:
        exe = build_host(files, Path(work))
        t_pipe, same_pipe = through(PipeTarget(exe), files, words, counts, a.ticks, host)
    t_qemu, same_qemu = through(QemuTarget(target_elf(files)), files, words, counts, a.qemu_ticks, host)
    semi = QemuTarget(target_elf(files, "cortex-m4-semihosting"), "qemu:semihosting")
    t_semi, same_semi = through(semi, files, words, counts, a.semihosting_ticks, host)
    print(f"{n} ticks replayed; host C (cffi) {t_host * 1e6:.2f} µs/tick")
    print(f"link to a pipe: {a.ticks} ticks, {t_pipe * 1e6:.1f} µs/tick ({t_pipe / t_host:.1f} × host C), "
          f"equal commands {same_pipe}/{a.ticks}")  # fmt: skip
    print(f"link to QEMU: {a.qemu_ticks} ticks, {t_qemu * 1e6:.0f} µs/tick ({t_qemu / t_host:.0f} × host C, "
          f"{1 / t_qemu:.0f} ticks/s), equal commands {same_qemu}/{a.qemu_ticks}")  # fmt: skip
    print(f"link to QEMU, semihosting: {a.semihosting_ticks} ticks, {t_semi * 1e6:.1f} µs/tick "
          f"({t_semi / t_host:.0f} × host C, {t_qemu / t_semi:.1f} × faster than the UART, {1 / t_semi:.0f} ticks/s), "
          f"equal commands {same_semi}/{a.semihosting_ticks}")  # fmt: skip
    print(f"load {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
