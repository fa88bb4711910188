"""The classical washout's and the limit guard's cost per drive sample (issue 39, item 6, first part), against the
budget of one sample at the drive's rate (10 ms at 100 Hz), on seed 001's ship simulator (``gonzalez-dutra-2009``)
and the 210 kg machine (``examples/newcomer-210kg.yaml``).

The numpy law and the guard run over a whole drive (``control.cueing.classical``, ``guard``): their cost per
sample is amortised over the drive. The compiled washout (``control.cueing.classical_kernel``) is the streaming
step a real-time loop runs, sample after sample from its state: timed over the drive in one call (the step's own
cost) and one sample per call (with cffi's call overhead). The guard as built is not causal (its erosion and
averages look ``smoothing`` s ahead and its last pass scales the whole sequence), so it has no streaming step yet.
The exact-IK re-check of the guarded poses (``api.cueing.limit_samples``) is timed beside them. Process CPU time, best of
``--repeat``; the ratios to the sample budget are what travel between machines.

Run by hand: ``python benchmarks/bench_cueing.py [--repeat 3] [--drive ship-ss4]``.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from stewart_drake.api.cueing import limit_samples, resolve_drive
from stewart_drake.control.cueing.classical import HAND_SET, classical
from stewart_drake.control.cueing.classical_kernel import WashoutKernel
from stewart_drake.control.cueing.guard import WorkspaceGuard
from stewart_drake.spec import load_machine

MACHINES = ("gonzalez-dutra-2009", "examples/newcomer-210kg.yaml")


def best_cpu(fn, repeat: int) -> float:
    """Best process CPU seconds of ``repeat`` calls of ``fn()``."""
    best = np.inf
    for _ in range(repeat):
        t0 = time.process_time()
        fn()
        best = min(best, time.process_time() - t0)
    return best


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--drive", default="ship-ss4")
    args = ap.parse_args()
    drive = resolve_drive(args.drive)
    n, dt = len(drive.t), float(drive.t[1] - drive.t[0])
    print(f"load average {os.getloadavg()[0]:.2f}; drive {drive.name}: {n} samples at {1 / dt:g} Hz")
    print(f"{'machine':30s} {'part':22s} {'µs/sample':>10s} {'share of budget':>16s}")
    for source in MACHINES:
        platform = load_machine(source).platform
        home = platform.home_pose()
        guard = WorkspaceGuard.for_platform(platform)
        raw = classical(drive, HAND_SET, home)
        guarded = guard.guard(raw, drive.t)
        u = np.hstack([drive.specific_force, drive.angular_velocity])
        parts = {
            "classical washout": lambda: classical(drive, HAND_SET, home),
            "compiled washout step": lambda: WashoutKernel(HAND_SET, drive.dt, home).run(u),
            "  one sample per call": lambda: [
                kernel.run(row) for kernel in [WashoutKernel(HAND_SET, drive.dt, home)] for row in u
            ],
            "guard": lambda: guard.guard(raw, drive.t),
            "exact-IK re-check": lambda: limit_samples(guard, drive.t, guarded),
        }
        for part, fn in parts.items():
            us = best_cpu(fn, args.repeat) / n * 1e6
            print(f"{platform.name:30s} {part:22s} {us:10.2f} {us * 1e-6 / dt:16.2e}")


if __name__ == "__main__":
    main()
