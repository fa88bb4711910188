"""How much of each report section is Drake stepping a plant (item 3 of the speed issue: the floor under the report's
run time that a bit-for-bit speed-up cannot lower): per section, its process CPU seconds built in-process (one fresh
process per section, ``report.build_section``, matplotlib and the analysis imported before the clock) and the CPU
seconds spent inside ``Simulator.AdvanceTo`` (timed by a wrapper on pydrake's class: the closed loops' compiled
kernel calls it too), with their sum and the wall-time floor that sum sets on ``--jobs`` cores, perfectly packed.

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

ROOT = Path(__file__).resolve().parents[1]
CHILD = """
import sys, time
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot  # noqa: F401  (imported before the clock: every report worker has it)
from pathlib import Path
from pydrake.systems.analysis import Simulator_
import stewart_drake
from stewart_drake.report import build_section, load_analysis, loaded, parts
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
c0 = time.process_time()
build_section(a, sys.argv[2] == "quick")
print(time.process_time() - c0, stepping[0])
"""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mode", default="full", choices=["quick", "full"])
    ap.add_argument("--sections", nargs="+", help="analysis names (default: every analysis of the report)")
    ap.add_argument("--jobs", type=int, default=2, help="cores the floor is spread over")
    args = ap.parse_args()
    sections = args.sections or sorted(p.stem for p in (ROOT / "stewart_drake" / "analyses").glob("[!_]*.py"))
    print(f"# load average {os.getloadavg()}; {args.mode} mode")
    total_cpu = total_stepping = 0.0
    for name in sections:
        out = subprocess.run(
            [sys.executable, "-c", CHILD, name, args.mode],
            cwd=ROOT,
            env={**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg", "OPENBLAS_NUM_THREADS": "1"},
            capture_output=True,
            text=True,
            check=True,
        ).stdout.split()
        cpu, stepping = float(out[-2]), float(out[-1])
        total_cpu += cpu
        total_stepping += stepping
        print(f"{name:24s} CPU {cpu:6.2f} s   Drake stepping {stepping:6.2f} s ({stepping / cpu:4.0%})")
    print(
        f"{'all':24s} CPU {total_cpu:6.2f} s   Drake stepping {total_stepping:6.2f} s: "
        f"a floor of {total_stepping / args.jobs:.1f} s of wall on {args.jobs} cores"
    )
    print(f"# load average {os.getloadavg()}")


if __name__ == "__main__":
    main()
