"""``sd.montecarlo``: a robustness study, many closed-loop runs with drawn tolerances (each run built by
``api.simulation.plan_run``, the one home of a closed-loop run), summarised with its sensitivities."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from stewart_drake.api.result import Result
from stewart_drake.core.geometry import Platform
from stewart_drake.core.output_folder import OutputFolder
from stewart_drake.core.processes import check_workers
from stewart_drake.core.quantisation import check_finite_rates, check_quantisation
from stewart_drake.core.trajectory import TRAJECTORIES, Trajectory, read_trajectory_table
from stewart_drake.drake.integrators import DEFAULT_INTEGRATOR
from stewart_drake.errors import OptionError, UsageError
from stewart_drake.firmware.engine import default_engine
from stewart_drake.montecarlo.scenario import LOST_TRACKING, Study
from stewart_drake.montecarlo.spec import parse_spec
from stewart_drake.montecarlo.study import run_study, study_key, study_settings
from stewart_drake.montecarlo.summary import summarise, write_outputs
from stewart_drake.script.source import read_program

if TYPE_CHECKING:  # annotations only: pandas is optional
    import pandas


REPLAY_COMMAND = "montecarlo --replay"  # a replay's files are recorded under "montecarlo --replay K"


def make_study(
    platform: Platform,
    trajectory: str | Trajectory = "seed",
    *,
    runs: int = 100,
    seed: int = 0,
    vary=(),
    program: str | None = None,
    controller: str = "fixed",
    engine: str | None = None,
    integrator: str | None = None,
    duration: float | None = None,
    plant_step: float = 1e-3,
    lost_tracking: float = LOST_TRACKING,
    fit: bool = False,
    length_unit: str = "m",
    angle_unit: str = "rad",
    workers: int | None = None,
    lost_tracking_shown=None,
) -> Study:
    """The ``Study`` the arguments describe, checked (see ``montecarlo``; ``lost_tracking_shown``: the value
    as the user wrote it, in mm)."""
    spec = parse_spec(vary)
    program_text = (program, read_program(program)) if program else None
    if workers is not None:
        check_workers("--workers", workers, minimum=0)  # the one rule for worker counts (core.processes)
    if engine == "c" and controller != "fixed":
        raise UsageError(UsageError.ENGINE_C.format(controller=controller))
    engine = default_engine(engine, controller, "stewart-drake montecarlo")
    if not lost_tracking > 0:
        shown = lost_tracking * 1e3 if lost_tracking_shown is None else lost_tracking_shown
        raise OptionError(OptionError.POSITIVE.format(option="--lost-tracking", unit="mm", value=shown))
    trajectory = None if program_text else trajectory
    table, motion = None, None
    if isinstance(trajectory, Trajectory):
        motion, trajectory = trajectory, None
    elif trajectory is not None and trajectory not in TRAJECTORIES:
        table = csv_table(str(trajectory), length_unit, angle_unit)
        trajectory = None
    return Study(
        platform=platform,
        spec=spec,
        seed=seed,
        runs=runs,
        trajectory=trajectory,
        program=program_text,
        table=table,
        fit=fit,
        controller=controller,
        integrator=integrator or DEFAULT_INTEGRATOR,
        engine=engine,
        duration=duration,
        plant_step=plant_step,
        lost_tracking=lost_tracking,
        motion=motion,
    )


def csv_table(path: str, length_unit: str, angle_unit: str) -> tuple:
    """A (t, pose) CSV reference as ``(name, times, poses SI)`` lists (``Study.table``), read here once as a
    stream (``read_trajectory_table`` names a bad line; a FIFO works) and checked as ``load_trajectory_csv``
    checks it (finite rates; rounding noise refused)."""
    name, ts, poses = read_trajectory_table(path, length_unit, angle_unit)
    check_finite_rates(path, ts, poses)
    check_quantisation(path, ts, poses)
    return (name, ts.tolist(), poses.tolist())


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
    platform: Platform,
    trajectory: str | Trajectory = "seed",
    *,
    out: str | Path,
    runs: int = 100,
    seed: int = 0,
    vary: Sequence[str] | str = (),
    program: str | None = None,
    controller: str = "fixed",
    engine: str | None = None,
    integrator: str | None = None,
    duration: float | None = None,
    plant_step: float = 1e-3,
    lost_tracking: float = LOST_TRACKING,
    fit: bool = False,
    length_unit: str = "m",
    angle_unit: str = "rad",
    workers: int = 1,
    scheduler: str | None = None,
    progress: bool = False,
) -> MonteCarloResult:
    """Many closed-loop runs with drawn tolerances (on Dask), summarised with their sensitivities.

    Args:
        platform: the nominal platform (the controller's model).
        trajectory: ``"seed"``, ``"rotating"``, a CSV file of t, pose rows, or a `Trajectory` (pickled to the
            workers with the study, by value where its functions are not importable; a study run from one
            cannot be replayed from the command line: its study.json records the motion by its hash).
        out: the study's folder (a finished or partial study there is resumed).
        runs: number of runs.
        seed: the study's seed (run k's seed derives from it: any run can be replayed alone).
        vary: what each run draws, as ``"key=law"`` words (``"anchor=±0.5mm"``, ``"sensor_noise=10um"``, ...)
            or a YAML file's path.
        program: a motion program (``.stw``) as the reference instead of ``trajectory``.
        controller: ``"fixed"`` or ``"float"``.
        engine: the fixed-point tick: ``"c"`` or ``"python"`` (default ``"c"`` where a compiler is found).
        integrator: ``"cenic-fixed"`` (default), ``"cenic"`` or ``"sap"``.
        duration: simulated seconds per run (default the reference's).
        plant_step: plant time step, s.
        lost_tracking: a run with a leg error beyond this (m) lost tracking.
        fit: move the reference to the platform's home.
        length_unit: a CSV reference's length unit.
        angle_unit: a CSV reference's angle unit.
        workers: Dask worker processes (0: in this process). They do not import the caller's ``__main__``: a
            script calling ``montecarlo`` needs no ``if __name__ == "__main__":`` guard, and the functions it
            defines (a `Trajectory`'s) reach the workers by value.
        scheduler: a Dask scheduler's address instead of a local cluster.
        progress: show a progress bar.

    Returns:
        The study's summary and rows.

    Raises:
        StewartError: a bad ``vary`` word, a study too large, bad options.
    """
    study = make_study(
        platform,
        trajectory,
        runs=runs,
        seed=seed,
        vary=vary,
        program=program,
        controller=controller,
        engine=engine,
        integrator=integrator,
        duration=duration,
        plant_step=plant_step,
        lost_tracking=lost_tracking,
        fit=fit,
        length_unit=length_unit,
        angle_unit=angle_unit,
        workers=workers,
    )
    return run_montecarlo(study, out, workers=workers, scheduler=scheduler, progress=progress)


def run_montecarlo(study: Study, out, workers: int = 1, scheduler: str | None = None, progress: bool = False):
    """Run a checked ``Study`` into ``out`` and summarise it (``MonteCarloResult``)."""
    # --out checked before any run: new, empty, or this study's own (its replays kept beside it)
    folder = OutputFolder(out, companions=(REPLAY_COMMAND,))
    study.reference()  # the reference (program compiled, CSV read) checked here, before any run starts
    rows = run_study(study, out, workers=workers, scheduler=scheduler, progress=progress)
    summary = summarise(rows, study_settings(study), study_key(study))
    summary["files"] = [str(p) for p in write_outputs(folder, rows, summary)]
    return MonteCarloResult(summary, rows, Path(out))
