"""Hand-set vs tuned classical washout on a platform: the perceived-motion scores, side by side.

Tunes the classical washout for each car drive and sea state (``tune_classical`` from the default parameters, a
fixed seed and budget), then scores a still platform (home throughout), the hand set, the default parameters and
the drive's tuned set, all through the workspace guard, and prints a Markdown table and the tuned parameters.

    python benchmarks/bench_cueing_tuning.py [--platform gonzalez-dutra-2009] [--budget 384] [--out DIR]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from stewart_drake.control.cueing.classical import HAND_SET, ClassicalParams, classical
from stewart_drake.control.cueing.generators import DRIVES
from stewart_drake.control.cueing.guard import WorkspaceGuard
from stewart_drake.control.cueing.platform_motion import platform_drive
from stewart_drake.control.cueing.scores import score
from stewart_drake.control.cueing.tuning import save_params, tune_classical
from stewart_drake.core.geometry import load_platform

NAMES = ("car-lane-change", "car-braking", "car-slalom", "ship-ss3", "ship-ss4", "ship-ss5", "ship-ss6")


def row(drive, params, guard, platform) -> dict:
    """The scores of ``params`` on ``drive`` (None: the platform still at home)."""
    still = np.tile(guard.home, (len(drive), 1))
    q = still if params is None else guard.guard(classical(drive, params, guard.home), drive.t)
    s = score(drive, platform_drive(q, drive.t, guard.home), q, platform)
    limits = guard.check(q, drive.t, stroke=platform.stroke)
    main = max(("fx", "fy", "fz"), key=lambda c: s["channels"][c]["rmse"])
    return {
        "f_rmse": s["specific_force_rmse"],
        "f_r": s["specific_force_pearson"],
        "delay": s["channels"][main]["delay_s"],
        "false": s["false_cue_share"],
        "spurious": s["spurious_rotation_share"],
        "stroke": s["stroke_use_pct"],
        "out": limits.outside_stroke + limits.over_speed + limits.over_accel,
    }


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--platform", default="gonzalez-dutra-2009")
    ap.add_argument("--budget", type=int, default=384)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default=None, help="folder for the tuned parameters (YAML) and the table (JSON)")
    args = ap.parse_args()
    platform = load_platform(args.platform)
    guard = WorkspaceGuard.for_platform(platform)
    results, tuned = {}, {}
    for name in NAMES:
        d = DRIVES[name]()
        t0 = time.perf_counter()
        tuned[name] = tune_classical([d], platform, guard, budget=args.budget, seed=args.seed)
        print(f"# tuned for {name} in {time.perf_counter() - t0:.0f} s: {tuned[name]}")
        results[(name, "still")] = row(d, None, guard, platform)
        for label, params in (("hand-set", HAND_SET), ("default", ClassicalParams()), ("tuned", tuned[name])):
            results[(name, label)] = row(d, params, guard, platform)
    print(f"\nplatform {platform.name}, budget {args.budget}, seed {args.seed}\n")
    print(
        "| drive | washout | f RMSE m/s² | f corr | delay s | false cues % | false rotation % | stroke use % "
        "| limit samples |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for (name, label), r in results.items():
        print(
            f"| {name} | {label} | {r['f_rmse']:.3f} | {r['f_r']:.2f} | {r['delay']:.2f} | {100 * r['false']:.1f} "
            f"| {100 * r['spurious']:.1f} "
            f"| {r['stroke']:.0f} | {r['out']} |"
        )
    if args.out:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        for name, params in tuned.items():
            save_params(params, out / f"tuned-{name}.yaml")
        table = {f"{n}/{lab}": r for (n, lab), r in results.items()}
        (out / "table.json").write_text(json.dumps(table, indent=1))


if __name__ == "__main__":
    main()
