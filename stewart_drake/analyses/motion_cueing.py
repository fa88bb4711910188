"""Motion cueing on seed 001's ship simulator (``gonzalez-dutra-2009``) in sea states 3–6: hand-set and tuned
classical washout side by side, each through the limit guard and then in the loop with the machine's fixed-point
controller and the Drake plant; the perceived-motion scores of the commanded and the simulated motion, and the
checks of the issue: 0 samples outside the stroke or over the leg speed, commanded and simulated."""

from __future__ import annotations

from stewart_drake.api.cueing import cue
from stewart_drake.control.cueing.classical import HAND_SET
from stewart_drake.control.cueing.generators import ship_drive
from stewart_drake.control.cueing.tuning import tune_classical
from stewart_drake.report import run_standalone
from stewart_drake.spec import load_machine

TITLE = "Motion cueing: seed 001's ship simulator in sea states 3–6"
ORDER = 92
COST = 30  # CPU seconds (full report, estimated): the report's workers start the costliest first
PRESET_ONLY = (
    "it studies seed 001's ship simulator (gonzalez-dutra-2009); `stewart-drake cue --machine FILE` cues a drive on "
    "yours"
)

PLATFORM = "gonzalez-dutra-2009"
SEA_STATES = (3, 4, 5, 6)
RATE = 100.0  # Hz: the drives' sampling, the cueing laws' rate
SECONDS = {True: 8.0, False: 40.0}  # s of each drive: quick, full (bounded CPU: the loop runs ~4× real time)


def scalar_scores(scores: dict) -> dict:
    """The scores' scalar entries (the per-channel ones are in ``scores.json`` of ``stewart-drake cue``)."""
    return {k: float(v) for k, v in scores.items() if isinstance(v, (int, float))}


def cue_runs(machine, drives, simulate: bool) -> dict:
    """``{(drive name, law): CueResult}``: each drive cued by hand-set classical washout and by classical washout
    tuned over all the drives together (one tuning), in the loop when ``simulate``."""
    tuned = tune_classical(drives, machine.platform)
    laws = (("hand-set", "classical", HAND_SET), ("tuned", "tuned", tuned))
    return {
        (drive.name, label): cue(machine, drive, algorithm=algorithm, params=params, simulate=simulate)
        for drive in drives
        for label, algorithm, params in laws
    }


def score_table(runs: dict, plant: bool) -> tuple[list, list]:
    """``(header, rows)``: one row per run of ``cue_runs``, its scalar scores (the plant's when ``plant``)."""
    scores = {key: scalar_scores(r.plant_scores if plant else r.scores) for key, r in runs.items()}
    names = sorted({k for s in scores.values() for k in s})
    rows = [[drive, label, *(s.get(k, float("nan")) for k in names)] for (drive, label), s in scores.items()]
    return ["drive", "classical", *names], rows


def build(section) -> None:
    machine = load_machine(PLATFORM)
    seconds = SECONDS[section.quick]
    drives = [ship_drive(s, duration=seconds, rate=RATE, seed=s) for s in SEA_STATES]
    section.text(
        f"Ship drives (JONSWAP sea through the ship response model of control.cueing.generators) in sea states "
        f"{SEA_STATES[0]}–{SEA_STATES[-1]}, {seconds:g} s each at {RATE:g} Hz, cued on {PLATFORM} by classical "
        "washout with hand-set (FlyPT-like) parameters and with parameters tuned over the four drives together "
        "(tune_classical), each through the workspace guard, then run in the loop with the machine's fixed-point "
        "controller and the Drake plant (sd.cue(..., simulate=True)). Scores compare what a rider perceives "
        "(otolith and semicircular-canal models) on the plant with what the ship's rider perceives."
    )
    runs = cue_runs(machine, drives, simulate=True)
    section.table(
        *score_table(runs, plant=True),
        caption="Perceived-motion scores of the simulated plant against the vehicle (SI; per-channel values in "
        "stewart-drake cue's scores.json)",
        fmt="{:.3g}",
    )
    for (drive, label), r in runs.items():
        commanded = r.limits["outside_stroke"] + r.limits["over_speed"]
        plant = r.plant_limits["outside_stroke"] + r.plant_limits["over_speed"]
        section.check(f"{drive}, {label}: samples outside the stroke or over the leg speed, commanded", commanded, 0)
        section.check(f"{drive}, {label}: samples outside the stroke or over the leg speed, plant", plant, 0)
        section.check(f"{drive}, {label}: the loop's tracking failures", len(r.simulation.verdict["failures"]), 0)
    worst = runs[drives[-1].name, "tuned"]
    section.figure(
        worst.plot(),
        "cueing_perception",
        f"{drives[-1].name}, tuned classical washout: perceived specific force and angular velocity of the ship "
        "(black), the commanded platform and the simulated plant",
    )
    section.figure(worst.plot_legs(), "cueing_legs", f"{drives[-1].name}, tuned: the legs against the stroke")


def main(argv=None):
    return run_standalone(__file__, argv)


if __name__ == "__main__":
    raise SystemExit(main())
