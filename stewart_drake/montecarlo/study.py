"""Running a study: runs on Dask (or in this process), streamed back, resumable from the output folder.

The output folder holds, while a study runs, ``montecarlo.partial.jsonl``: a header line with the
study's key (``study_key``: a hash of every setting except the number of runs) and one JSON row per
finished run, flushed as each arrives (a ``system.journal``: a chain of per-line MACs). A study started again
with the same settings and ``--out`` verifies every line, checks each row's drawn values against the study's
draws for its run, and runs only the missing indices (JSON keeps every float bit for bit). At the end the folder is
replaced atomically by the final files (``summary.write_outputs``).

Dask: ``--workers K`` starts a ``LocalCluster`` of K single-threaded worker processes; ``--scheduler``
connects to an existing one. Each task is the ``Study`` (a few kB pickled) and one run index, so a run on a worker
that dies is re-run elsewhere (``retries``); a scattered study would be lost for good with a worker holding its
only replica (distributed: "lost scattered data, which can't be recovered"). Each run's result depends only on the
study and its index, so the rows are the same with any number of workers.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import logging
import math
import sys
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from stewart_drake.core.geometry import base_joints
from stewart_drake.drake.systems import make_law
from stewart_drake.errors import JournalError, OutputError, SpecError, StudyError
from stewart_drake.montecarlo.draw_checks import check_draws
from stewart_drake.montecarlo.scenario import Study, draw, nominal_value, run_scenario, scenario
from stewart_drake.montecarlo.summary import VERDICT_COLUMNS
from stewart_drake.spec import Gains, Machine, apply_overrides
from stewart_drake.spec.machine import FIELDS
from stewart_drake.system.journal import JournalWriter, header_line, read_rows
from stewart_drake.system.output_folder import claim_in_manifest, write_text_atomic

PARTIAL = "montecarlo.partial.jsonl"
STUDY_FILE = "study.json"
# Work bounds, checked before anything runs: runs, simulated seconds per run and in total.
MAX_RUNS = 100_000
MAX_RUN_SECONDS = 600.0
MAX_TOTAL_SECONDS = 500_000.0
# ... and plant steps (the work and each run's log scale with them, not with simulated seconds): the same
# bounds at the default 1 ms step, so that a fine --plant-step cannot ask for days or a log beyond memory
MAX_RUN_STEPS = MAX_RUN_SECONDS / 1e-3
MAX_TOTAL_STEPS = MAX_TOTAL_SECONDS / 1e-3
RETRIES = 3
# How a study's messages name its settings: the API's parameters and spec paths; the command line passes its flags.
NAMES = {
    "runs": "runs",
    "seed": "seed",
    "duration": "run.duration",
    "plant_step": "run.plant_step",
    "vary": "vary",
    "out": "out",
    "workers": "workers",
    "lost_tracking": "lost_tracking",
}


def option_names(names: dict | None = None) -> dict:
    """The message templates' fields (``{"runs_opt": "runs", ...}``) of ``NAMES`` updated by ``names``."""
    return {f"{k}_opt": v for k, v in (NAMES | (names or {})).items()}


def study_settings(study: Study) -> dict:
    """The study's settings as JSON-able data (the platform by value), without the number of runs. A
    platform whose legs share base joints adds ``base_joints`` (each leg's joint, ``geometry.base_joints``):
    its anchors are drawn per joint, so its key differs from that of a study whose draws split them."""
    p = study.platform
    joints, leg_joint = base_joints(p)
    shared = {"base_joints": leg_joint.tolist()} if len(joints) < 6 else {}
    plat = {f.name: getattr(p, f.name) for f in dataclasses.fields(p)}
    plat["legs"] = dataclasses.asdict(p.legs)
    plat = {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in plat.items()}
    return {
        "platform": plat,
        "vary": study.spec.to_dict(),
        "seed": study.seed,
        "trajectory": study.trajectory,
        "program": list(study.program) if study.program else None,
        "table": list(study.table) if study.table else None,
        "fit": study.fit,
        "controller": study.controller,
        "integrator": study.integrator,
        "engine": study.engine,
        "duration": study.duration,
        "plant_step": study.plant_step,
        "lost_tracking": study.lost_tracking,
        "grid": list(study.grid) if study.grid is not None else None,
        "motion": motion_settings(study),
        **shared,
        **machine_settings(study.machine),
        **study.extra,
    }


# spec paths study_settings records under names of their own (controller, engine, duration, ...)
RECORDED_PATHS = ("controller.law", "controller.engine", "run.duration", "run.plant_step", "run.integrator", "run.fit")


def machine_settings(machine: Machine) -> dict:
    """``{"machine": {spec path: value}}`` (SI; lists, the gains as a mapping) of the machine's fields that differ
    from a machine with defaults (those of ``RECORDED_PATHS`` left to their own settings); ``{}`` when none does,
    so that a study of a platform keeps its settings and key."""
    default = Machine(machine.platform)
    out = {}
    for path in FIELDS:
        if path in RECORDED_PATHS:
            continue
        section, name = path.split(".")
        v = getattr(getattr(machine, section), name)
        if v != getattr(getattr(default, section), name):
            out[path] = dataclasses.asdict(v) if isinstance(v, Gains) else list(v) if isinstance(v, tuple) else v
    return {"machine": out} if out else {}


def motion_settings(study: Study) -> dict | None:
    """A Python ``Trajectory`` reference as ``{"name", "sha256"}``: its name and a hash of its poses at the plant
    steps of a run (what the runs follow), so that the study's key changes with the motion; None for others."""
    if study.motion is None:
        return None
    t = np.arange(int(math.floor(study.run_duration() / study.plant_step + 1e-9)) + 1) * study.plant_step
    poses = np.ascontiguousarray(study.reference().pose(t), dtype="<f8")
    return {"name": study.motion.name, "sha256": hashlib.sha256(poses.tobytes()).hexdigest()}


def study_from_settings(settings: dict, runs: int) -> Study:
    """The ``Study`` of ``study_settings`` (as stored in ``study.json``)."""
    from stewart_drake.core.geometry import LegConfig, Platform
    from stewart_drake.montecarlo.spec import spec_from_dict

    if settings.get("motion"):  # its poses' hash alone: the Trajectory object stayed in the process that ran it
        raise StudyError(StudyError.MOTION_NOT_STORED.format(name=settings["motion"].get("name")))
    plat = dict(settings["platform"])
    plat["legs"] = LegConfig(**plat["legs"])
    plat["leg_top"] = np.asarray(plat["leg_top"], dtype=np.intp)
    fields = {f.name for f in dataclasses.fields(Study)}
    known = {
        "platform",
        "vary",
        "seed",
        "trajectory",
        "program",
        "table",
        "fit",
        "controller",
        "integrator",
        "engine",
        "duration",
        "plant_step",
        "lost_tracking",
        "grid",
        "base_joints",
        "motion",
        "machine",
    }
    extra = {k: v for k, v in settings.items() if k not in known}
    return Study(
        apply_overrides(Machine(Platform(**plat)), settings.get("machine") or {}),
        spec=spec_from_dict(settings["vary"]),
        seed=settings["seed"],
        runs=runs,
        trajectory=settings["trajectory"],
        program=tuple(settings["program"]) if settings["program"] else None,
        table=tuple(settings["table"]) if settings.get("table") else None,
        fit=settings["fit"],
        controller=settings["controller"],
        # a study stored without an integrator ran under the default of its time, CENIC
        integrator=settings["integrator"] or "cenic",
        engine=settings.get("engine", "python"),
        duration=settings["duration"],
        plant_step=settings["plant_step"],
        lost_tracking=settings["lost_tracking"],
        grid=tuple(settings["grid"]) if settings.get("grid") is not None else None,
        extra={k: v for k, v in extra.items() if k not in fields},
    )


def study_key(study: Study) -> str:
    """A hash of ``study_settings`` (settings left at None out, so that a setting added later keeps the
    keys of studies that do not use it): two studies with the same key draw and run the same runs."""
    return settings_key(study_settings(study))


def settings_key(settings: dict) -> str:
    """``study_key`` of stored ``study_settings`` (e.g. a finished study's ``study.json``)."""
    settings = {k: v for k, v in settings.items() if v is not None}
    return hashlib.sha256(json.dumps(settings, sort_keys=True, default=repr).encode()).hexdigest()[:16]


def check_study(study: Study, names: dict | None = None) -> float:
    """Raise ``StudyError`` if the study is too large or inconsistent, or a run's draw fails ``simulate``'s
    checks (``draw_checks``); return the seconds per run. ``names``: how messages name the settings (``NAMES``)."""
    opt = option_names(names)
    from stewart_drake.drake.integrators import check_integrator

    check_integrator(study.integrator)
    if not (isinstance(study.runs, int) and 1 <= study.runs <= MAX_RUNS):
        raise StudyError(StudyError.RUNS.format(limit=MAX_RUNS, value=study.runs, **opt))
    if not (isinstance(study.seed, int) and study.seed >= 0):
        raise StudyError(StudyError.SEED.format(value=study.seed, **opt))
    if study.grid is not None and len(study.grid) != study.runs:
        raise StudyError(StudyError.GRID.format(runs=study.runs, points=len(study.grid)))
    if not (math.isfinite(study.plant_step) and 0 < study.plant_step <= 1e-2):
        raise StudyError(StudyError.PLANT_STEP.format(value=study.plant_step))
    duration = study.run_duration()
    if not (math.isfinite(duration) and 0 < duration <= MAX_RUN_SECONDS):
        raise StudyError(StudyError.DURATION.format(limit=MAX_RUN_SECONDS, value=duration, **opt))
    if study.runs * duration > MAX_TOTAL_SECONDS:
        raise StudyError(
            StudyError.TOTAL.format(
                runs=study.runs, duration=duration, total=study.runs * duration, limit=MAX_TOTAL_SECONDS, **opt
            )
        )
    steps = duration / study.plant_step
    if steps > MAX_RUN_STEPS:
        raise StudyError(
            StudyError.STEPS.format(step=study.plant_step, duration=duration, steps=steps, limit=MAX_RUN_STEPS, **opt)
        )
    if study.runs * steps > MAX_TOTAL_STEPS:
        raise StudyError(
            StudyError.TOTAL_STEPS.format(
                runs=study.runs, steps=steps, total=study.runs * steps, limit=MAX_TOTAL_STEPS, **opt
            )
        )
    for key, law in study.spec.laws.items():  # ±P% of a machine field whose value is zero (a payload of 0 kg)
        if law.kind == "relative" and not np.any(nominal_value(study.machine, key)):
            raise SpecError(SpecError.PERCENT_OF_ZERO.format(where=opt["vary_opt"], key=key, text=law.text))
    if study.controller == "fixed":
        law = study.spec.laws.get("sensor_resolution")
        if law is not None and law.kind not in ("fixed", "choice"):
            raise StudyError(StudyError.RESOLUTION_RANGE.format(**opt))
        lsb = study.machine.firmware.length_lsb
        for r in law.values if law is not None else ():
            if not (r > 0 and abs(lsb / r - round(lsb / r)) <= 1e-9 * lsb / r):  # r > 0 first: no lsb / 0
                raise StudyError(StudyError.RESOLUTION_DIVIDE.format(value=r, lsb=lsb, **opt))
    check_draws(study, names)
    return duration


def compile_firmware(study: Study, index: int) -> None:
    """With the C engine, compile run ``index``'s firmware into the C build cache here, before the workers
    start: they load it instead of each compiling the same module at once on a cold cache (a run whose
    gains or timing differ still compiles its own, once, in its worker)."""
    if study.engine == "c" and study.controller == "fixed":
        sc = scenario(study, index)[2]
        make_law(sc.controller, sc.platform, sc.config, sc.engine, sc.firmware)


def run_row(study: Study, index: int) -> dict:
    """The Dask task: run ``index`` of ``study`` and return its row (no log)."""
    return run_scenario(study, index)


# ----------------------------------------------------------------------------------------------
# The output folder's state.


def load_partial(out: Path, key: str, study: Study | None = None, names: dict | None = None) -> dict[int, dict]:
    """``{run: row}`` of the runs already finished in ``out`` for the study ``key`` (none if ``out`` does
    not exist). ``StudyError`` if ``out`` holds something else: another study, or files this tool did not
    write; ``JournalError`` naming the file and line if a line of the journal does not verify (``system.journal``)
    or, with ``study``, a row's drawn values are not the study's draws for its run (``names``: how messages name
    ``out``, ``NAMES``)."""
    opt = option_names(names)
    if not out.exists():
        return {}
    if not out.is_dir():
        raise StudyError(StudyError.OUT_NOT_FOLDER.format(out=str(out), **opt))
    rows: dict[int, dict] = {}
    partial = out / PARTIAL
    previous = out / STUDY_FILE
    if previous.exists():
        old = _damaged_unless(previous, lambda: json.loads(previous.read_text()), dict, opt)
        old_key = _damaged_unless(
            previous, lambda: settings_key(old["settings"]) if "settings" in old else old.get("key"), str, opt
        )
        if old_key != key:
            raise StudyError(StudyError.OUT_OTHER_STUDY.format(out=str(out), old_key=old_key, key=key, **opt))
        results = out / "results.parquet"
        if results.exists():
            import pyarrow.parquet as pq

            table = _damaged_unless(results, lambda: pq.read_table(results).to_pylist(), list, opt)
            for n, r in enumerate(table, start=1):
                rows[_checked(study, results, n, r, opt)] = r
    elif not partial.exists() and any(out.iterdir()):
        raise StudyError(StudyError.OUT_NOT_OURS.format(out=str(out), study_file=STUDY_FILE, partial=PARTIAL, **opt))
    if partial.exists():
        lines = partial.read_text(encoding="utf-8", errors="replace").splitlines()
        head = _damaged_unless(partial, lambda: json.loads(lines[0]) if lines else None, dict, opt)
        if head.get("key") != key:
            raise StudyError(StudyError.OUT_OTHER_PARTIAL.format(out=str(out), old_key=head.get("key"), key=key, **opt))
        for n, r in read_rows(partial, key):  # every line verified; a last line cut short: that run is re-run
            rows[_checked(study, partial, n, r, opt)] = r
    return rows


def _checked(study: Study | None, path: Path, line: int, row, opt: dict) -> int:
    """The run index of a stored ``row`` (line ``line`` of ``path``), its drawn values checked against ``study``'s
    draws for that run (``scenario.draw``: deterministic from the seed and the index)."""
    run = _run_index(path, row, opt)
    if study is not None and run < study.runs:
        seed, d = draw(study, run)
        for column, drawn in {"seed": seed, **d.columns()}.items():
            if row.get(column) != drawn:
                problem = JournalError.ROW_DRAW.format(run=run, column=column, value=row.get(column), drawn=drawn)
                raise JournalError(JournalError.ROW.format(path=str(path), line=line, problem=problem))
    return run


def _damaged_unless(path: Path, read, kind: type, opt: dict):
    """``read()`` if it gives a ``kind``; else ``StudyError`` naming ``path`` as damaged (a resume folder
    edited or cut short: one line, never a traceback)."""
    try:
        value = read()
    except (OSError, ValueError, KeyError, TypeError, AttributeError) as e:  # pyarrow's errors are ValueErrors
        reason = str(e).splitlines()[0][:100] if str(e) else type(e).__name__
    else:
        if isinstance(value, kind):
            return value
        reason = f"{type(value).__name__} where a {kind.__name__} belongs"
    raise StudyError(StudyError.OUT_DAMAGED.format(path=str(path), reason=reason, **opt))


def _run_index(path: Path, row, opt: dict) -> int:
    """The run index of a stored row (a JSON object with an integer "run"), else ``StudyError`` naming ``path``."""
    run = row.get("run") if isinstance(row, dict) else None
    if type(run) is not int or run < 0:
        raise StudyError(
            StudyError.OUT_DAMAGED.format(path=str(path), reason=f"a row without a run index: {str(row)[:60]}", **opt)
        )
    return run


class PartialWriter:
    """Appends finished rows to ``out/montecarlo.partial.jsonl`` (``system.journal``), one flushed line each. The file is made
    at the first row (a study that fails before any run leaves no folder), with its header written whole
    (a temporary and a rename: never a file without its key) and claimed in the folder's manifest as an
    append-only journal of this command (verified by its header's hash)."""

    def __init__(self, out: Path, key: str, option: str = "--out"):
        self.out, self.key, self.option, self.fh = out, key, option, None

    def write(self, obj: dict) -> None:
        path = self.out / PARTIAL
        try:
            if self.fh is None:
                if not path.exists():
                    self._start(path)
                self.fh = JournalWriter(path, self.key)  # a verified chain (system.journal)
            self.fh.append(obj)
        except OSError as e:  # disk full, ...: one line naming the file and the option
            raise OutputError(
                OutputError.UNWRITABLE.format(
                    option=self.option, typed=str(self.out), reason=f"{path}: {e.strerror or e}"
                )
            ) from None

    def _start(self, path: Path) -> None:
        """The header, then its claim; if the claim cannot be written, neither is left (nor the folder, if
        made here): the rerun finds the folder as it was."""
        made = not self.out.exists()
        self.out.mkdir(parents=True, exist_ok=True)
        try:
            write_text_atomic(path, header_line(self.key) + "\n")
            claim_in_manifest(self.out, [PARTIAL], prefix=True)  # the final write replaces it
        except OSError:
            path.unlink(missing_ok=True)  # written just now by this process, not yet claimed
            if made:
                try:
                    self.out.rmdir()
                except OSError:
                    pass
            raise

    def close(self) -> None:
        if self.fh is not None:
            self.fh.close()


# ----------------------------------------------------------------------------------------------
# Running.


def run_study(
    study: Study, out, workers: int = 1, scheduler: str | None = None, progress: bool = True, names: dict | None = None
) -> list[dict]:
    """Run every run of ``study`` not yet in ``out`` and return all rows in run order. ``workers`` 0
    runs them in this process (no Dask); otherwise a ``LocalCluster`` of ``workers`` processes, or the
    cluster at ``scheduler``. ``out`` None: nothing kept on disk (no resume). A finished row without the
    verdict columns (``summary.VERDICT_COLUMNS``: written before runs were judged) is run again. ``names``: how
    messages name the settings (``NAMES``)."""
    check_study(study, names)
    key = study_key(study)
    rows = load_partial(Path(out), key, study, names) if out is not None else {}
    rows = {i: r for i, r in rows.items() if all(c in r for c in VERDICT_COLUMNS)}
    todo = [i for i in range(study.runs) if i not in rows]
    writer = PartialWriter(Path(out), key, option_names(names)["out_opt"]) if out is not None else None
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=study.runs, initial=study.runs - len(todo), desc="montecarlo", unit=" run")
    try:
        for row in _results(study, todo, workers, scheduler):
            rows[row["run"]] = row
            if writer is not None:
                writer.write(row)
            if bar is not None:
                bar.update(1)
    finally:
        if writer is not None:
            writer.close()
        if bar is not None:
            bar.close()
    return [rows[i] for i in range(study.runs)]


def _results(study: Study, todo: list[int], workers: int, scheduler: str | None):
    """Rows of the runs ``todo``, as they finish."""
    if not todo:
        return
    if scheduler is None and workers == 0:
        for i in todo:
            yield run_row(study, i)
        return
    from distributed import Client

    from stewart_drake.workspace.dask_sweep import local_cluster

    compile_firmware(study, todo[0])
    cluster = None
    with main_kept_from_workers():  # open while the cluster lives: a nanny restarting a dead worker spawns too
        if scheduler is None:
            cluster = local_cluster(workers)  # single-threaded worker processes, no profiler, adaptive malloc
            client = Client(cluster)
        else:
            client = Client(scheduler)
        yield from _gathered(study, todo, client, cluster)


def _gathered(study: Study, todo: list[int], client, cluster):
    """Rows of the runs ``todo`` run on ``client``'s cluster, as they finish; closes the client (and
    ``cluster``, a ``LocalCluster`` of this study's) at the end, but not on an interrupt."""
    from distributed import as_completed

    interrupted = False
    try:
        # each task carries the study (~2 kB pickled) rather than a scattered copy: a worker killed while it
        # held the only replica would lose scattered data for good, and every run waiting on it would fail
        futures = [client.submit(run_row, study, i, retries=RETRIES, pure=False) for i in todo]
        for fut in as_completed(futures):
            yield fut.result()
            fut.release()
    except KeyboardInterrupt:  # Ctrl-C/SIGTERM: no orderly close (its workers' and scheduler's complaints
        interrupted = True  # are not the user's): the command exits now, its workers die with it
        logging.getLogger("distributed").setLevel(logging.CRITICAL + 1)
        raise
    finally:
        if not interrupted:
            client.close()
            if cluster is not None:
                cluster.close()


@contextmanager
def main_kept_from_workers():
    """While open, processes that ``multiprocessing`` spawns (Dask's nannies start their workers so, and start
    a dead worker's replacement so) do not import the caller's ``__main__``: a user's script without an
    ``if __name__ == "__main__":`` guard would run again in each worker as it starts, and fail there. Its
    functions and classes still reach the workers, by value (``distributed`` pickles what refers to
    ``__main__`` with cloudpickle). ``__main__``'s ``__file__`` and ``__spec__`` (what spawn reads to import
    it) are put back when it closes."""
    main = sys.modules.get("__main__")
    saved = {k: main.__dict__[k] for k in ("__file__", "__spec__") if k in main.__dict__} if main else {}
    if main is not None:
        main.__dict__.pop("__file__", None)
        if "__spec__" in saved:
            main.__spec__ = None
    try:
        yield
    finally:
        if main is not None:
            main.__dict__.update(saved)
