"""``sd.montecarlo``: a robustness study, many closed-loop runs with drawn tolerances (each run built by
``api.simulation.plan_run``, the one home of a closed-loop run), summarised with its sensitivities."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

from stewart_drake.api.result import Result
from stewart_drake.core.geometry import Platform
from stewart_drake.core.trajectory import Trajectory
from stewart_drake.errors import OptionError, UsageError
from stewart_drake.firmware.engine import default_engine
from stewart_drake.montecarlo.scenario import LOST_TRACKING, STUDY_KEYWORDS, Study, reference_data
from stewart_drake.montecarlo.spec import parse_spec
from stewart_drake.montecarlo.study import NAMES, run_study, study_key, study_settings
from stewart_drake.montecarlo.summary import summarise, write_outputs
from stewart_drake.spec import Machine, load_machine
from stewart_drake.system.output_folder import OutputFolder
from stewart_drake.system.processes import check_workers

if TYPE_CHECKING:  # annotations only: pandas is optional
    import pandas


REPLAY_COMMAND = "montecarlo --replay"  # a replay's files are recorded under "montecarlo --replay K"


def make_study(
    machine, motion, vary, runs: int, seed: int, overrides: dict, *, lost_tracking: float = LOST_TRACKING,
    units=("m", "rad"), workers: int | None = None, names: dict | None = None, lost_tracking_shown=None,
) -> Study:  # fmt: skip
    """The ``Study`` of ``montecarlo``'s arguments, checked: ``machine`` with ``overrides`` (spec paths, or the
    keywords of earlier versions: ``STUDY_KEYWORDS``, ``trajectory``, ``program``), its engine resolved (C where a
    compiler is found), ``motion`` (None: the machine's first) read with ``units`` (a CSV's length and angle
    units). ``names``: how messages name the settings (``study.NAMES``: the parameters and spec paths; the command
    line's flags); ``lost_tracking_shown``: ``(unit, value)`` as the user wrote ``lost_tracking`` (default m, SI)."""
    names = NAMES | (names or {})
    overrides = dict(overrides)
    program, trajectory = overrides.pop("program", None), overrides.pop("trajectory", None)
    motion = program or (motion if motion is not None else trajectory)
    given = {STUDY_KEYWORDS.get(k, k): v for k, v in overrides.items() if not (k in STUDY_KEYWORDS and v is None)}
    m = load_machine(machine, given)
    spec = parse_spec(vary, names["vary"])
    if workers is not None:
        check_workers(names["workers"], workers, minimum=0)  # the one rule (system.processes)
    ctl = m.controller
    if ctl.engine == "c" and ctl.law != "fixed":
        raise UsageError(UsageError.ENGINE_C.format(controller=ctl.law))
    engine = default_engine(ctl.engine, ctl.law, "stewart-drake montecarlo")
    m = replace(m, controller=replace(ctl, engine=engine))
    if not lost_tracking > 0:
        unit, value = lost_tracking_shown or ("m", lost_tracking)
        raise OptionError(OptionError.POSITIVE.format(option=names["lost_tracking"], unit=unit, value=value))
    ref = reference_data(motion if motion is not None else m.motion, *units)
    return Study(m, spec, seed, runs, lost_tracking=lost_tracking, **ref)


@dataclass(repr=False)
class MonteCarloResult(Result):
    """A robustness study (``montecarlo``).

    Attributes:
        summary: runs, error percentiles, the worst run, sensitivities (Spearman), lost-tracking and failed
            runs and the files written (the dict ``stewart-drake montecarlo --json`` prints).
        rows: one dict per run: its seed, drawn parameters (SI), metrics and ``simulate``'s verdicts
            (``force_ripple_rms_N``, ``chatter``, ``saturated``, ``tracking_failed``, ``failures``).
        out: the study's folder (``results.parquet``, ``study.json``, plots).
    """

    summary: dict
    rows: list
    out: Path

    @property
    def lost_tracking_runs(self) -> list:
        """The runs that lost tracking (or failed)."""
        return self.summary["lost_tracking_runs"]

    @property
    def ok(self) -> bool:
        """Every run passed: none lost tracking, none failed (its simulation, or one of ``simulate``'s verdicts:
        chatter, saturation, tracking; ``summary["failed_runs"]`` gives each with its reason)."""
        return self.summary["ok"]

    def _fields(self) -> dict:
        return self.summary

    def to_pandas(self) -> pandas.DataFrame:
        """One row per run (pandas must be installed).

        Returns:
            A ``pandas.DataFrame`` of the runs' seeds, drawn parameters and metrics.
        """
        # deferred: pandas is optional (a notebook's), the study does not need it
        import pandas as pd

        return pd.DataFrame([{k: v for k, v in r.items() if k != "log"} for r in self.rows])


def montecarlo(
    machine: Machine | Platform | str | Path,
    motion: str | Path | Trajectory | None = None,
    *,
    out: str | Path,
    vary: Sequence[str] | str = (),
    runs: int = 100,
    seed: int = 0,
    workers: int = 1,
    scheduler: str | None = None,
    progress: bool = False,
    lost_tracking: float = LOST_TRACKING,
    length_unit: str = "m",
    angle_unit: str = "rad",
    **overrides,
) -> MonteCarloResult:
    """Many closed-loop runs of a machine with drawn tolerances (on Dask), summarised with their sensitivities.

    Args:
        machine: the nominal machine: a ``Machine`` (``load_machine``'s), a machine file, a preset name or a
            ``Platform`` (every other section at its defaults). Its controller, firmware format, sensors,
            actuators, payload and run settings reach every run; the controller keeps its nominal model.
        motion: the pose reference: ``"seed"``, ``"rotating"``, a CSV file of t, pose rows, a ``.stw`` motion
            program, or a `Trajectory` (pickled to the workers with the study, by value where its functions are
            not importable; a study run from one cannot be replayed from the command line: its study.json
            records the motion by its hash); default the machine's first motion.
        out: the study's folder (a finished or partial study there is resumed).
        vary: what each run draws, as ``"key=law"`` words (``"anchor=±0.5mm"``, ``"sensor_noise=10um"``, ...)
            or a YAML file's path; a key with a spec path (``sample_period``: ``controller.period``, ...) draws
            about the machine's value there (``montecarlo.spec.KEYS``).
        runs: number of runs.
        seed: the study's seed (run k's seed derives from it: any run can be replayed alone).
        workers: Dask worker processes (0: in this process). They do not import the caller's ``__main__``: a
            script calling ``montecarlo`` needs no ``if __name__ == "__main__":`` guard, and the functions it
            defines (a `Trajectory`'s) reach the workers by value.
        scheduler: a Dask scheduler's address instead of a local cluster.
        progress: show a progress bar.
        lost_tracking: a run with a leg error beyond this (m) lost tracking.
        length_unit: a CSV reference's length unit.
        angle_unit: a CSV reference's angle unit.
        **overrides: any spec path, ``**{"firmware.length_lsb": "30um", "run.duration": 0.5}`` (values in SI or
            in the quantity grammar); the keywords of earlier versions (``duration``, ``controller``, ``engine``,
            ``integrator``, ``plant_step``, ``fit``; ``trajectory`` and ``program``: the motion) set their spec paths.

    Returns:
        The study's summary and rows.

    Raises:
        StewartError: a bad ``vary`` word, a study too large, bad settings (``MachineError`` naming the spec
            path), a draw that ``simulate`` would refuse.
    """
    study = make_study(
        machine, motion, vary, runs, seed, overrides, lost_tracking=lost_tracking, units=(length_unit, angle_unit),
        workers=workers,
    )  # fmt: skip
    return run_montecarlo(study, out, workers=workers, scheduler=scheduler, progress=progress)


def run_montecarlo(
    study: Study, out, workers: int = 1, scheduler: str | None = None, progress: bool = False, names=None
) -> MonteCarloResult:
    """Run a checked ``Study`` into ``out`` and summarise it (``names``: how messages name the settings,
    ``study.NAMES``)."""
    # out checked before any run: new, empty, or this study's own (its replays kept beside it)
    option = (NAMES | (names or {}))["out"]
    folder = OutputFolder(out, companions=(REPLAY_COMMAND,), option=option)
    study.reference()  # the reference (program compiled, CSV read) checked here, before any run starts
    rows = run_study(study, out, workers=workers, scheduler=scheduler, progress=progress, names=names)
    summary = summarise(rows, study_settings(study), study_key(study))
    summary["files"] = [str(p) for p in write_outputs(folder, rows, summary)]
    return MonteCarloResult(summary, rows, Path(out))
