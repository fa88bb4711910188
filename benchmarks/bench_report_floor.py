"""The floor under the report's run time that a bit-for-bit speed-up of our own code cannot lower (item 3 of the
speed issue), beside its target: per section, its process CPU seconds built in-process (one fresh process per
section, ``report.build_section``, matplotlib and the analysis imported before the clock), the CPU seconds spent
inside ``Simulator.AdvanceTo`` (Drake stepping a plant, timed by a wrapper on pydrake's class: the closed loops'
compiled kernel calls it too) and inside ``report.figures.png_bytes`` (matplotlib laying out and drawing the
section's figures: the same pictures cost the same artists), and what is left (our own numerics and the
figures' plotting calls). Then a worker's start (interpreter and the imports every report worker makes, from
process start) and the wall floor on ``--jobs`` cores, perfectly packed: Drake + drawing + one start per worker
— what the report would take if everything else cost nothing.

    PYTHONPATH=. python benchmarks/bench_report_floor.py [--mode full|quick] [--sections controller_in_the_loop ...]
        [--jobs 2]

Measures only; run it on an idle machine (the load is printed first and last).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
CHILD = """
import sys, time
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot  # noqa: F401  (imported before the clock: every report worker has it)
from pathlib import Path
from pydrake.systems.analysis import Simulator_
import stewart_drake
from stewart_drake.report import build_section, figures, load_analysis, loaded, parts
parts.IN_WORKER = True  # a section's parallel_map runs in this process
a = load_analysis(Path(stewart_drake.__file__).parent / "analyses" / (sys.argv[1] + ".py"))
loaded(a.path)
advance, stepping = Simulator_[float].AdvanceTo, [0.0]
def timed(simulator, t):
    c = time.process_time()
    try:
        return advance(simulator, t)
    finally:
        stepping[0] += time.process_time() - c
Simulator_[float].AdvanceTo = timed
png, drawing = figures.png_bytes, [0.0]
def drawn(fig):
    c = time.process_time()
    try:
        return png(fig)
    finally:
        drawing[0] += time.process_time() - c
figures.png_bytes = drawn
c0 = time.process_time()
build_section(a, sys.argv[2] == "quick")
print(time.process_time() - c0, stepping[0], drawing[0])
"""
# a report worker's start: the interpreter and the imports every worker makes, CPU from process start
START = """
import resource
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot  # noqa: F401
from pydrake.systems.analysis import Simulator_  # noqa: F401
import stewart_drake.report  # noqa: F401
r = resource.getrusage(resource.RUSAGE_SELF)
print(r.ru_utime + r.ru_stime)
"""
TARGET_S = {"full": 30.0, "quick": 10.0}  # the wall-time targets on the 2-core machine


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mode", default="full", choices=["quick", "full"])
    ap.add_argument("--sections", nargs="+", help="analysis names (default: every analysis of the report)")
    ap.add_argument("--jobs", type=int, default=2, help="cores the floor is spread over")
    args = ap.parse_args()
    sections = args.sections or sorted(p.stem for p in (ROOT / "stewart_drake" / "analyses").glob("[!_]*.py"))
    print(f"# load average {os.getloadavg()}; {args.mode} mode")
    total = np.zeros(3)
    for name in sections:
        cpu, stepping, drawing = map(float, _child(CHILD, name, args.mode)[-3:])
        total += (cpu, stepping, drawing)
        print(
            f"{name:24s} CPU {cpu:6.2f} s   Drake stepping {stepping:6.2f} s ({stepping / cpu:4.0%})   "
            f"figures {drawing:5.2f} s   rest {cpu - stepping - drawing:5.2f} s"
        )
    cpu, stepping, drawing = total
    start = min(float(_child(START)[-1]) for _ in range(3))
    floor = (stepping + drawing) / args.jobs + start
    print(
        f"{'all':24s} CPU {cpu:6.2f} s   Drake stepping {stepping:6.2f} s   figures {drawing:5.2f} s   "
        f"rest {cpu - stepping - drawing:5.2f} s"
    )
    print(f"a worker's start (interpreter and imports) {start:.2f} s CPU")
    print(
        f"floor on {args.jobs} cores (Drake + figures spread over them, one start each): {floor:.1f} s of wall; "
        f"the rest at the same packing adds {(cpu - stepping - drawing) / args.jobs:.1f} s; "
        f"target {TARGET_S[args.mode]:g} s"
    )
    print(f"# load average {os.getloadavg()}")


def _child(code: str, *argv) -> list[str]:
    """The words a fresh interpreter running ``code`` with ``argv`` prints (the report workers' environment)."""
    return subprocess.run(
        [sys.executable, "-c", code, *argv],
        cwd=ROOT,
        env={**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg", "OPENBLAS_NUM_THREADS": "1"},
        capture_output=True,
        text=True,
        check=True,
    ).stdout.split()


if __name__ == "__main__":
    main()
