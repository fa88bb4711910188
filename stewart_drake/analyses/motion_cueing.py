"""Motion cueing on seed 001's ship simulator (``gonzalez-dutra-2009``) in sea states 3–6: hand-set classical washout,
classical washout tuned over the four drives and MPC side by side, each through the limit guard and then in the loop
with the machine's fixed-point controller and the Drake plant; the perceived-motion scores of the simulated motion,
and the issue's checks: 0 samples outside the stroke or over the leg speed, commanded and simulated, the loop
tracking, every MPC solve inside the stroke by the exact IK, and tuned washout no worse than hand-set on the perceived
specific-force RMSE."""

from __future__ import annotations

import numpy as np

from stewart_drake.api.cueing import cue
from stewart_drake.control.cueing.classical import HAND_SET
from stewart_drake.control.cueing.generators import ship_drive
from stewart_drake.control.cueing.tuning import tune_classical
from stewart_drake.drake.cueing_mpc import MpcParams
from stewart_drake.report import run_standalone
from stewart_drake.spec import load_machine

TITLE = "Motion cueing: seed 001's ship simulator in sea states 3–6"
ORDER = 92
COST = 63  # CPU seconds (full report, measured): the report's workers start the costliest first
PRESET_ONLY = (
    "it studies seed 001's ship simulator (gonzalez-dutra-2009); `stewart-drake cue --machine FILE` cues a drive on "
    "yours"
)

PLATFORM = "gonzalez-dutra-2009"
SEA_STATES = (3, 4, 5, 6)
RATE = 100.0  # Hz: the drives' sampling, the cueing laws' rate
SECONDS = {True: 6.0, False: 20.0}  # s of each drive, quick and full: bounded CPU (MPC ~0.35 s per drive second)
BUDGET = {True: 128, False: 400}  # the tuning's cost evaluations: one generation (quick), tune_classical's default
LAWS = ("hand-set", "tuned", "mpc")

# The side-by-side table's columns: header -> the value from a run's scores (SI; delay: the specific-force channels'
# mean lag of the perceived platform motion behind the vehicle's, by cross-correlation)
COLUMNS = {
    "f RMSE (m/s²)": lambda s: s["specific_force_rmse"],
    "ω RMSE (rad/s)": lambda s: s["angular_velocity_rmse"],
    "f Pearson": lambda s: s["specific_force_pearson"],
    "ω Pearson": lambda s: s["angular_velocity_pearson"],
    "f delay (s)": lambda s: float(np.mean([s["channels"][c]["delay_s"] for c in ("fx", "fy", "fz")])),
    "false cues (%)": lambda s: 100 * s["false_cue_share"],
    "stroke use (%)": lambda s: s["stroke_use_pct"],
}


def cue_runs(machine, drives, simulate: bool, budget: int = BUDGET[False]) -> dict:
    """``{(drive name, law): CueResult}``: each drive cued by hand-set classical washout, by classical washout tuned
    over all the drives together (one tuning of ``budget`` evaluations) and by MPC (its default parameters), in the
    loop when ``simulate``."""
    tuned = tune_classical(drives, machine.platform, budget=budget)
    laws = {"hand-set": ("classical", HAND_SET), "tuned": ("tuned", tuned), "mpc": ("mpc", MpcParams())}
    return {
        (drive.name, label): cue(machine, drive, algorithm=algorithm, params=params, simulate=simulate)
        for drive in drives
        for label, (algorithm, params) in laws.items()
    }


def score_table(runs: dict, plant: bool) -> tuple[list, list]:
    """``(header, rows)``: one row per run of ``cue_runs`` with ``COLUMNS`` of its scores (the plant's when
    ``plant``)."""
    rows = [
        [drive, law, *(f(r.plant_scores if plant else r.scores) for f in COLUMNS.values())]
        for (drive, law), r in runs.items()
    ]
    return ["drive", "law", *COLUMNS], rows


def rmse_ratios(runs: dict, law: str) -> str:
    """Per drive of ``cue_runs``' ``runs``, ``law``'s perceived specific-force RMSE over hand-set washout's."""
    rmse = {key: r.scores["specific_force_rmse"] for key, r in runs.items()}
    return ", ".join(f"{d} {rmse[d, law] / rmse[d, 'hand-set']:.2f}" for d, x in rmse if x == law)


def build(section) -> None:
    machine = load_machine(PLATFORM)
    seconds = SECONDS[section.quick]
    drives = [ship_drive(s, duration=seconds, rate=RATE, seed=s) for s in SEA_STATES]
    section.text(
        f"Ship drives (a JONSWAP sea through the ship response model of control.cueing.generators) in sea states "
        f"{SEA_STATES[0]}–{SEA_STATES[-1]}, {seconds:g} s each at {RATE:g} Hz, cued on {PLATFORM} by classical "
        "washout with hand-set (FlyPT-like) parameters, with parameters tuned over the four drives together "
        "(tune_classical) and by MPC (drake.cueing_mpc, default MpcParams: no preview of the drive), each through "
        "the workspace guard, then run in the loop with the machine's fixed-point controller and the Drake plant "
        "(sd.cue(..., simulate=True)). The scores compare what a rider perceives (otolith and semicircular-canal "
        "models) on the simulated plant with what the ship's rider perceives."
    )
    runs = cue_runs(machine, drives, simulate=True, budget=BUDGET[section.quick])
    section.table(
        *score_table(runs, plant=True),
        caption="Perceived motion of the simulated plant against the ship's, per drive and law (per-channel "
        "values: stewart-drake cue's scores.json)",
        fmt="{:.3g}",
    )
    for (drive, law), r in runs.items():
        commanded = r.limits["outside_stroke"] + r.limits["over_speed"]
        plant = r.plant_limits["outside_stroke"] + r.plant_limits["over_speed"]
        section.check(f"{drive}, {law}: samples outside the stroke or over the leg speed, commanded", commanded, 0)
        section.check(f"{drive}, {law}: samples outside the stroke or over the leg speed, plant", plant, 0)
        section.check(f"{drive}, {law}: the loop's failures (tracking, saturation, chatter)", len(r.failures), 0)
        if r.mpc is not None:
            section.check(
                f"{drive}, MPC: largest stroke excess of a solve (exact IK)", r.mpc["max_stroke_violation_m"], 0
            )
    # the tuning minimises the perceived error over the four drives together: judged on their mean
    hand, tuned = (np.mean([runs[d.name, law].scores["specific_force_rmse"] for d in drives]) for law in LAWS[:2])
    section.check("tuned / hand-set perceived specific-force RMSE, mean over the drives (commanded)", tuned / hand, 1)
    solves = [r.mpc for r in runs.values() if r.mpc is not None]
    worst, mean = max(m["worst_solve_s"] for m in solves), np.mean([m["mean_solve_s"] for m in solves])
    worst_cpu = max(m["worst_solve_cpu_s"] for m in solves)
    section.text(
        f"Perceived specific-force RMSE over hand-set washout's (commanded), tuned: {rmse_ratios(runs, 'tuned')}; "
        f"MPC: {rmse_ratios(runs, 'mpc')}. MPC's solves took {mean * 1e3:.1f} ms on average and {worst * 1e3:.1f} ms "
        f"at worst (wall time in this run, which shares its machine with the report's other sections; "
        f"{worst_cpu * 1e3:.1f} ms of CPU at worst; the MPC benchmark measures it on one core)."
    )
    shown = runs[drives[2].name, "tuned"]
    section.figure(
        shown.plot(),
        "cueing_perception",
        f"{drives[2].name}, tuned classical washout: perceived specific force and angular velocity of the ship "
        "(black), the commanded platform and the simulated plant",
    )
    section.figure(shown.plot_legs(), "cueing_legs", f"{drives[2].name}, tuned: the legs against the stroke")


def main(argv=None):
    return run_standalone(__file__, argv)


if __name__ == "__main__":
    raise SystemExit(main())
