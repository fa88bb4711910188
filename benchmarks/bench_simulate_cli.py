"""Real-time factor of ``stewart-drake simulate``'s closed loop, for each integrator and fixed-point engine
and for the command's defaults (no option), optionally beside another checkout of the project (e.g. an
older commit) timed in the same run, interleaved so that both see the same machine load:

    PYTHONPATH=. python benchmarks/bench_simulate_cli.py [--duration 2] [--repeat 3] [--compare OTHER_CHECKOUT]

Two figures per case, each the best of ``--repeat``: ``run``, simulated seconds / wall seconds of the
Simulator's run alone (the seed trajectory on utn-dynamic, fixed point, 1 kHz, default gains; measured in
a fresh interpreter of each checkout, through ``build_simulation`` — the scenario dataclass here, the
keyword arguments of older checkouts), and ``command``, simulated seconds / wall seconds of the whole
``simulate`` command (imports, gain design, build, run, logs and plots). The ``default`` case runs the
command without ``--integrator`` and ``--engine`` (each checkout's own defaults; command only). A case a
checkout does not offer (an integrator added later) prints n/a.
"""

from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CASES = [(i, e) for e in ("python", "c") for i in ("sap", "cenic", "cenic-fixed")] + [(None, None)]


def wall(checkout: Path, integrator: str | None, engine: str | None, duration: float) -> float:
    """Seconds of one ``simulate`` command run from ``checkout`` (None: the command's default), inf if the
    checkout does not offer the option."""
    env = dict(os.environ, PYTHONPATH=str(checkout), MPLBACKEND="Agg")
    options = ([] if integrator is None else ["--integrator", integrator]) + (
        [] if engine is None else ["--engine", engine]
    )
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [sys.executable, "-m", "stewart_drake.cli", "simulate", "--duration", str(duration), "--no-progress"]
        t0 = time.perf_counter()
        r = subprocess.run(
            [*cmd, *options, "--out", str(Path(tmp) / "out")], env=env, cwd=checkout, capture_output=True
        )
        return time.perf_counter() - t0 if r.returncode == 0 else math.inf


# Times the run alone in a fresh interpreter of a checkout; older checkouts take keyword arguments.
RUN_ONLY = """
import sys, time
from stewart_drake.core.geometry import load_preset
import stewart_drake.drake.simulation as S
integrator, engine, duration = sys.argv[1], sys.argv[2], float(sys.argv[3])
p = load_preset("utn-dynamic")
kw = dict(integrator=integrator, engine=engine, design_duration=max(duration, 4.0))
sim = S.build_simulation(S.Scenario(p, "seed", "fixed", **kw)) if hasattr(S, "Scenario") else S.build_simulation(p, "seed", "fixed", **kw)
t0 = time.perf_counter()
sim.run(duration)
print(time.perf_counter() - t0)
"""


def run_only(checkout: Path, integrator: str | None, engine: str | None, duration: float) -> float:
    """Seconds of the Simulator's run alone (build excluded), in a fresh interpreter of ``checkout``; inf
    for the default case (the command's defaults are not the library's) or a case the checkout lacks."""
    if integrator is None:
        return math.inf
    env = dict(os.environ, PYTHONPATH=str(checkout), MPLBACKEND="Agg")
    cmd = [sys.executable, "-c", RUN_ONLY, integrator, engine, str(duration)]
    r = subprocess.run(cmd, env=env, cwd=checkout, capture_output=True, text=True)
    return float(r.stdout.split()[-1]) if r.returncode == 0 else math.inf


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--duration", type=float, default=2.0, help="simulated seconds per command (default 2)")
    ap.add_argument("--repeat", type=int, default=3, help="commands per case; the best is reported (default 3)")
    ap.add_argument("--compare", type=Path, default=None, help="another checkout to time alongside this one")
    args = ap.parse_args(argv)
    trees = {"this": ROOT} | ({"other": args.compare.resolve()} if args.compare else {})
    best = {(kind, name, case): float("inf") for kind in ("run", "command") for name in trees for case in CASES}
    for _ in range(args.repeat):
        for case in CASES:
            for name, tree in trees.items():  # interleaved: both trees see the same machine load
                best["run", name, case] = min(best["run", name, case], run_only(tree, *case, args.duration))
                best["command", name, case] = min(best["command", name, case], wall(tree, *case, args.duration))
    print(
        f"seed on utn-dynamic, fixed point, 1 kHz, {args.duration:g} simulated s; real-time factor = simulated s / wall s, "
        f"best of {args.repeat}:"
    )
    for kind in ("run", "command"):
        print(f"{kind}:")
        for case in CASES:
            if kind == "run" and case[0] is None:
                continue

            def cell(name, case=case):
                b = best[kind, name, case]
                return f"{name}: {args.duration / b:5.3f}x ({b:6.2f} s)" if math.isfinite(b) else f"{name}: n/a"

            cells = "   ".join(cell(name) for name in trees)
            ratio = ""
            if args.compare and math.isfinite(best[kind, "other", case] + best[kind, "this", case]):
                ratio = f"   this/other {best[kind, 'other', case] / best[kind, 'this', case]:.2f}x"
            label = "(defaults)" if case[0] is None else f"--integrator {case[0]:11s} --engine {case[1]:6s}"
            print(f"  {label:40s}  {cells}{ratio}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
