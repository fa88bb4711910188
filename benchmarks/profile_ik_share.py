"""Which sweeps are IK-bound? The share of inverse kinematics in the workspace sweep, the condition and
stiffness/frequency maps and the design search's batch evaluation, by profile (cProfile, one run each).

Run by hand: ``python benchmarks/profile_ik_share.py``. For each sweep it prints its CPU time under the
profiler and the cumulative share of every function that evaluates leg lengths for many poses: the numpy IK
(``core.kinematics.leg_lengths``, which ``core.ik_kernel`` replaces) and the sweeps' own closed forms
(``workspace.slabs.inside_block``: lengths on a grid at one orientation, separable in x, y, z, its own time
only: with its callees it includes the optional limits; ``synthesis.batch.leg_ranges``: extreme lengths over
the box, per design), beside the largest other costs (own time).
By Amdahl's law a sweep whose IK share is s gains at most 1 / (1 − s) from a faster IK: a switch to the
kernel pays only where s is large.
"""

from __future__ import annotations

import contextlib
import cProfile
import io
import os
import pstats
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import stewart_drake  # noqa: E402
from stewart_drake.cli import main as cli  # noqa: E402
from stewart_drake.core.geometry import load_preset  # noqa: E402
from stewart_drake.design.maps import slice_maps  # noqa: E402
from stewart_drake.synthesis.batch import evaluate_designs  # noqa: E402
from stewart_drake.synthesis.requirements import load_requirements  # noqa: E402

IK_LIKE = ("leg_lengths", "inside_block", "leg_ranges")


def share(label: str, fn) -> None:
    """Profile ``fn`` once; print its CPU time, the IK-like functions' cumulative shares and the top costs."""
    pr = cProfile.Profile()
    c0 = time.process_time()
    pr.enable()
    with contextlib.redirect_stdout(io.StringIO()):
        fn()
    pr.disable()
    cpu = time.process_time() - c0
    stats = pstats.Stats(pr)
    total = sum(v[2] for v in stats.stats.values())  # the profiler's own clock: shares add up to 100 %
    print(f"\n## {label}: {cpu:.2f} CPU s, {total:.2f} s profiled")
    for (f, _, name), (_, calls, own, cum, _) in stats.stats.items():
        if name in IK_LIKE and "stewart_drake" in f:
            where = f.split("stewart_drake/")[-1]
            print(
                f"IK: {name} ({where}): {calls} calls, {100 * cum / total:.1f} % with its callees, "
                f"{100 * own / total:.1f} % own time"
            )
    top = sorted(stats.stats.items(), key=lambda kv: -kv[1][2])[:4]
    for (f, line, name), (_, calls, tt, _, _) in top:
        print(f"   top: {name} ({os.path.basename(f)}:{line}) {tt:.3f} s own time, {calls} calls")


def cli_run(argv):
    def run():
        with contextlib.suppress(SystemExit):
            cli(argv)

    return run


def main() -> int:
    print(f"# IK share of the sweeps; load average {', '.join(f'{x:.2f}' for x in os.getloadavg())}")
    share("workspace (gonzalez-dutra-2009, stroke, 10 mm grid)", cli_run(["workspace", "--json"]))
    share(
        "workspace, all limits",
        cli_run(["workspace", "--json", "--limits", "stroke,joints,collision,dexterity"]),
    )
    p = load_preset("utn-dynamic")
    xy = ((-0.45, 0.45), (-0.45, 0.45))
    share("condition map (design.maps.slice_maps, 81 x 81)", lambda: slice_maps(p, (0, 1), xy, 81))
    share(
        "stiffness/frequency map (slice_maps, modes, 81 x 81)",
        lambda: slice_maps(p, (0, 1), xy, 81, k=np.full(6, 1e7), modes=True),
    )
    req = load_requirements(
        os.path.join(os.path.dirname(stewart_drake.__file__), "examples", "seed_001_requirements.yaml")
    )
    X = req.lower + np.random.default_rng(0).random((200, len(req.lower))) * (req.upper - req.lower)
    share(
        "design search batch evaluation (synthesis.batch.evaluate_designs, 200 designs)",
        lambda: evaluate_designs(req, X),
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
