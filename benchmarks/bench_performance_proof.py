"""Time the performance proof (``synthesis.performance.prove_requirements_performance``: peak force and speed,
lowest frequency, worst condition over the required box) on seed 001's requirements and the design ``optimize``
chooses there (the one ``tests/synthesis/test_performance.py`` pins), best of ``--repeat`` runs. With ``--ref REV``
the same proof from git revision REV's ``performance.py`` runs interleaved with the working tree's, and the ratio
of the best times (wall and CPU) is printed (one run, so machine load hits both alike).

    PYTHONPATH=. python benchmarks/bench_performance_proof.py [--repeat 3] [--ref HEAD~3]
"""

from __future__ import annotations

import argparse
import importlib.util
import subprocess
import sys
import tempfile
import time
from importlib import resources
from pathlib import Path

import numpy as np

from stewart_drake.synthesis import performance
from stewart_drake.synthesis.families import design_platform
from stewart_drake.synthesis.requirements import load_requirements

SEED_001 = resources.files("stewart_drake") / "examples" / "seed_001_requirements.yaml"
X = np.array([0.4237, 0.1567, np.radians(5.737), np.radians(3.179), 0.8729])


def _module_at(rev: str):
    """The ``synthesis/performance.py`` of git revision ``rev`` as a module (it imports the working tree's
    package for everything else)."""
    src = subprocess.run(
        ["git", "show", f"{rev}:stewart_drake/synthesis/performance.py"], capture_output=True, text=True, check=True
    ).stdout
    path = Path(tempfile.mkdtemp()) / "performance_ref.py"
    path.write_text(src)
    spec = importlib.util.spec_from_file_location("performance_ref", path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules["performance_ref"] = mod
    spec.loader.exec_module(mod)
    return mod


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--ref", default=None, help="a git revision to compare with")
    args = ap.parse_args(argv)
    req = load_requirements(SEED_001)
    p = design_platform(req, X, [0.80, 1.09])
    mods = {"working tree": performance}
    if args.ref:
        mods[args.ref] = _module_at(args.ref)
    times = {k: [] for k in mods}
    cpu = {k: [] for k in mods}
    for i in range(args.repeat):
        for name, mod in mods.items():
            t0, c0 = time.perf_counter(), time.process_time()
            proof = mod.prove_requirements_performance(p, req)
            times[name].append(time.perf_counter() - t0)
            cpu[name].append(time.process_time() - c0)
            if i == 0:
                bounds = ", ".join(f"{k} {r['status']} {r['bound']:.10g}" for k, r in proof.results.items())
                print(f"{name}: {proof.cells_examined} cells; {bounds}")
    for name, t in times.items():
        print(f"{name}: best {min(t):.2f} s wall of {[round(x, 2) for x in t]}, {min(cpu[name]):.2f} s CPU")
    if args.ref:
        wall = min(times["working tree"]) / min(times[args.ref])
        print(
            f"ratio working tree / {args.ref}: {wall:.2f} wall, {min(cpu['working tree']) / min(cpu[args.ref]):.2f} CPU"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
