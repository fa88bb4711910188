"""MPC cueing at 100 Hz: its per-sample time beside the 10 ms real-time budget, and its perceived-motion scores beside
the hand-set classical washout's, on the car drives and a sea state.

Each drive is cued by the MPC (``drake.cueing_mpc``: its defaults, and the variants named by ``--variants``) and by
the hand-set and default classical washouts through the workspace guard; every run is scored by
``control.cueing.scores.score`` and checked against the stroke, leg speed and acceleration by the guard's exact-IK
check. The MPC's time is per drive sample: the whole step (linearise, update, solve, re-check), wall time and the
thread's CPU time (on a shared machine the wall time includes other processes' turns). Run it on one core:

    taskset -c 0 env OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 python benchmarks/bench_cueing_mpc.py \\
        [--platform gonzalez-dutra-2009 | --machine examples/newcomer-210kg.yaml] [--drives car-braking,...]
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from stewart_drake.control.cueing.classical import HAND_SET, ClassicalParams, classical
from stewart_drake.control.cueing.generators import DRIVES
from stewart_drake.control.cueing.guard import WorkspaceGuard
from stewart_drake.control.cueing.platform_motion import platform_drive
from stewart_drake.control.cueing.scores import score
from stewart_drake.core.geometry import load_platform
from stewart_drake.drake.cueing_mpc import MpcParams, leg_speed_limit, mpc_cue
from stewart_drake.spec.load import load_machine

NAMES = "car-lane-change,car-braking,car-slalom,ship-ss4"
BUDGET = 0.010  # s per sample at 100 Hz
VARIANTS = {
    "mpc": MpcParams(),
    "mpc held": MpcParams(decay=None),
    "mpc 6°/s": MpcParams(max_tilt_rate=math.radians(6.0)),
    "mpc preview": MpcParams(preview=True),
}  # the defaults; the vehicle's motion held over the horizon; the hand set's tilt rate; the recorded future seen


def scores(drive, q, guard, platform) -> dict:
    """The table's figures for poses ``q`` cueing ``drive``: limit samples are those outside the platform's stroke
    or over its leg speed (not the guard's narrower limits)."""
    s = score(drive, platform_drive(q, drive.t, guard.home), q, platform)
    limits = guard.check(q, drive.t, stroke=platform.stroke, max_speed=leg_speed_limit(platform, MpcParams()))
    main = max(("fx", "fy", "fz"), key=lambda c: s["channels"][c]["rmse"])
    return {
        "f_rmse": s["specific_force_rmse"],
        "f_r": s["specific_force_pearson"],
        "w_rmse": s["angular_velocity_rmse"],
        "delay": s["channels"][main]["delay_s"],
        "false": s["false_cue_share"],
        "spurious": s["spurious_rotation_share"],
        "stroke": s["stroke_use_pct"],
        "out": limits.outside_stroke + limits.over_speed,
    }


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--platform", default="gonzalez-dutra-2009")
    ap.add_argument("--machine", default=None, help="a machine file: its platform instead of --platform")
    ap.add_argument("--drives", default=NAMES)
    ap.add_argument("--variants", default=",".join(VARIANTS), help=f"MPC variants among {', '.join(VARIANTS)}")
    args = ap.parse_args()
    platform = load_machine(args.machine).platform if args.machine else load_platform(args.platform)
    guard = WorkspaceGuard.for_platform(platform)
    rows, times = [], []
    for name in args.drives.split(","):
        d = DRIVES[name]()
        still = np.tile(guard.home, (len(d), 1))
        rows.append((name, "still", scores(d, still, guard, platform)))
        for label, params in (("hand-set classical", HAND_SET), ("default classical", ClassicalParams())):
            rows.append((name, label, scores(d, guard.guard(classical(d, params, guard.home), d.t), guard, platform)))
        for label in args.variants.split(","):
            run = mpc_cue(d, platform, VARIANTS[label], guard.home)
            r = scores(d, run.poses, guard, platform)
            r["fallbacks"] = sum(run.fallbacks.values())
            rows.append((name, label, r))
            times.append((name, label, run))
    print(f"platform {platform.name}, {1 / (d.t[1] - d.t[0]):.0f} Hz\n")
    print("| drive | MPC | samples | wall median ms | wall worst ms | CPU median ms | CPU worst ms | worst / 10 ms |")
    print("|---|---|---|---|---|---|---|---|")
    for name, label, run in times:
        w, c = 1e3 * run.solve_times, 1e3 * run.cpu_times
        print(
            f"| {name} | {label} | {len(w)} | {np.median(w):.2f} | {w.max():.2f} | {np.median(c):.2f} | {c.max():.2f} "
            f"| {c.max() / (1e3 * BUDGET):.2f} |"
        )
    print(
        "\n| drive | cueing | f RMSE m/s² | vs hand-set | f corr | ω RMSE rad/s | delay s | false cues % "
        "| false rotation % | stroke use % | limit samples | fallbacks |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    hand = {n: r["f_rmse"] for n, lab, r in rows if lab == "hand-set classical"}
    for name, label, r in rows:
        print(
            f"| {name} | {label} | {r['f_rmse']:.3f} | {100 * (r['f_rmse'] / hand[name] - 1):+.0f} % | {r['f_r']:.2f} "
            f"| {r['w_rmse']:.3f} | {r['delay']:.2f} | {100 * r['false']:.1f} | {100 * r['spurious']:.1f} "
            f"| {r['stroke']:.0f} | {r['out']} | {r.get('fallbacks', '')} |"
        )


if __name__ == "__main__":
    main()
