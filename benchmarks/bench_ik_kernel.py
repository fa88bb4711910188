"""The compiled IK kernel (``core.ik_kernel``) beside its references in one run: the numpy path
(``kinematics.leg_lengths``), a memory copy of the same poses and an in-place square root over them.

Run by hand: ``python benchmarks/bench_ik_kernel.py [--n 2000000] [--repeat 5]``. One core (OMP/OPENBLAS
threads 1); the sides are timed interleaved, best of ``--repeat``, wall and process CPU time; the load
(``uptime``) is printed first and last: on a shared machine the ratios are what travel.
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from stewart_drake.core import ik_kernel  # noqa: E402
from stewart_drake.core.geometry import load_preset  # noqa: E402
from stewart_drake.core.kinematics import leg_lengths  # noqa: E402
from stewart_drake.core.sampling import random_poses  # noqa: E402

TARGET = 2e7  # poses/s on one core


def load() -> str:
    return "load average " + ", ".join(f"{x:.2f}" for x in os.getloadavg())


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=2_000_000)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args(argv)
    print(f"# IK kernel, {args.n} poses; {load()}")
    p = load_preset("utn-kinematic")
    q = np.ascontiguousarray(random_poses(p, args.n, seed=0, within_stroke=False))
    scratch, positive = np.empty_like(q), np.abs(q)
    sides = {
        "compiled": lambda: ik_kernel.leg_lengths(p, q, engine="c"),
        "numpy": lambda: leg_lengths(p, q),
        "memory copy": lambda: np.copyto(scratch, q),
        "sqrt in place": lambda: np.sqrt(positive, out=positive),
    }
    best = {k: (np.inf, np.inf) for k in sides}
    for _ in range(args.repeat):
        for k, f in sides.items():
            t0, c0 = time.perf_counter(), time.process_time()
            f()
            t, c = time.perf_counter() - t0, time.process_time() - c0
            best[k] = (min(best[k][0], t), min(best[k][1], c))
    rate = {k: (args.n / t, args.n / c) for k, (t, c) in best.items()}
    for k, (w, c) in rate.items():
        extra = f"   (target >= {TARGET:.0e} poses/s)" if k == "compiled" else ""
        print(f"{k:14s} {w:10.3g} poses/s wall, {c:10.3g} per CPU s{extra}")
    cw = rate["compiled"][0]
    print(
        f"compiled / numpy {cw / rate['numpy'][0]:.1f}x; memory copy / compiled {rate['memory copy'][0] / cw:.1f}x; "
        f"sqrt in place / compiled {rate['sqrt in place'][0] / cw:.1f}x (the issue's before: numpy 68x below a copy)"
    )
    d = np.abs(ik_kernel.leg_lengths(p, q, engine="c") - leg_lengths(p, q)).max()
    print(
        f"max |compiled - numpy| = {d:.1e} m absolute (target <= 1e-15 m), legs {leg_lengths(p, q[:1000]).min():.2f}-"
        f"{leg_lengths(p, q[:1000]).max():.2f} m"
    )
    print(f"# {load()}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
