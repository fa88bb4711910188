"""``stewart-drake montecarlo``: closed-loop runs over drawn tolerances, on Dask; summary, sensitivity, replay."""

from __future__ import annotations

import dataclasses
import json
import sys
from pathlib import Path

from stewart_drake.commands._common import (
    FLAG_PATHS,
    add_machine_args,
    add_platform_arg,
    dumps_strict,
    flag_error,
    machine_from_args,
    print_json,
    reject_unused,
)
from stewart_drake.commands.simulate import add_loop_args, write_plots
from stewart_drake.drake.montecarlo_animation import write_animation
from stewart_drake.errors import OptionError, StewartError
from stewart_drake.firmware.engine import resolve_engine
from stewart_drake.montecarlo.api import REPLAY_COMMAND, make_study, run_montecarlo
from stewart_drake.montecarlo.scenario import draw, plant_platform, run_scenario
from stewart_drake.montecarlo.study import (
    STUDY_FILE,
    settings_key,
    study_from_settings,
    study_settings,
)
from stewart_drake.montecarlo.summary import read_table
from stewart_drake.script import ScriptError
from stewart_drake.system.output_folder import OutputFolder, atomic_folder


def register(sub) -> None:
    p = sub.add_parser(
        "montecarlo",
        help="robustness study: many closed-loop runs with drawn tolerances (Dask), or --replay one of them",
    )
    add_platform_arg(p, default=None)
    add_machine_args(p)
    src = p.add_mutually_exclusive_group()
    src.add_argument(
        "--trajectory",
        default=None,
        metavar="seed|rotating|FILE.csv",
        help="the pose reference (default: the machine's first motion, seed)",
    )
    src.add_argument("--program", metavar="P.stw", help="a motion program as the reference instead")
    p.add_argument("--length-unit", choices=["m", "mm"], default="m", help="CSV length unit (default m)")
    p.add_argument("--angle-unit", choices=["rad", "deg", "pi"], default="rad", help="CSV angle unit (default rad)")
    p.add_argument("--fit", action="store_true", help="move and scale the trajectory to the platform's home and stroke")
    p.add_argument("--runs", type=int, default=100, metavar="N", help="number of runs (default 100)")
    p.add_argument(
        "--seed",
        type=int,
        default=0,
        metavar="S",
        help="study seed; run i draws from SeedSequence(S, spawn_key=(i,)) (default 0)",
    )
    p.add_argument(
        "--vary",
        nargs="+",
        default=[],
        metavar="SPEC",
        help="what varies: key=value words or one YAML file (keys: anchor, leg_offset, sensor_resolution, sensor_noise, "
        "latency, latency_jitter, actuator_lag, force_limit, plate_mass, plate_com, gain_scale, sample_period, payload, payload_position; values X, ±T, ±P%%, A..B, a|b; "
        "units m mm um s ms us N kg g)",
    )
    add_loop_args(p)
    p.set_defaults(controller=None)  # None: the machine's controller.law (fixed)
    p.add_argument(
        "--duration", default=None, metavar="S", help="simulated seconds per run, e.g. 0.5s (default the trajectory's)"
    )
    p.add_argument(
        "--plant-step",
        default=None,
        metavar="S",
        help="plant step / log period, e.g. 1ms (default: the machine's period, at most 1 ms)",
    )
    p.add_argument(
        "--lost-tracking",
        type=float,
        default=5.0,
        metavar="MM",
        help="leg error that counts as lost tracking, mm (default 5)",
    )
    where = p.add_mutually_exclusive_group()
    where.add_argument(
        "--workers",
        type=int,
        default=1,
        metavar="K",
        help="LocalCluster worker processes, 1 thread each (default 1; 0: in this process, no Dask)",
    )
    where.add_argument(
        "--scheduler", metavar="tcp://HOST:PORT", help="an existing Dask scheduler instead of a LocalCluster"
    )
    p.add_argument(
        "--out",
        default="montecarlo",
        metavar="DIR",
        help="output folder (default montecarlo/); a study there with the same settings resumes",
    )
    p.add_argument(
        "--replay",
        type=int,
        default=None,
        metavar="K",
        help="re-run run K of the study in --out alone: full log in DIR/replay-K/, checked against its row",
    )
    p.add_argument("--no-animation", action="store_true", help="with --replay: no Meshcat HTML animation")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=run)


# the options that set a spec path (simulate's table, and the runs' duration)
MC_FLAG_PATHS = {**FLAG_PATHS, "duration": ("--duration", "run.duration")}
# how the study's messages name its settings here (montecarlo.study.NAMES: the API's names)
FLAG_NAMES = {
    "runs": "--runs",
    "seed": "--seed",
    "duration": "--duration",
    "plant_step": "--plant-step",
    "vary": "--vary",
    "out": "--out",
    "workers": "--workers",
    "lost_tracking": "--lost-tracking",
}
# option (argparse dest) -> (flag, spec path) of the draws' checks' messages (``commands._common.flag_text``)
STUDY_FLAGS = {"plant_step": ("--plant-step", "run.plant_step")}


def build_study(args):
    """The ``Study`` the options describe: the machine of ``--machine``/``--platform`` with the options of
    ``MC_FLAG_PATHS`` and each ``--set``, checked by the API (``montecarlo.api.make_study``)."""
    return make_study(
        machine_from_args(args, MC_FLAG_PATHS), args.program or args.trajectory, args.vary, args.runs, args.seed, {},
        lost_tracking=args.lost_tracking * 1e-3, units=(args.length_unit, args.angle_unit), workers=args.workers,
        names=FLAG_NAMES, lost_tracking_shown=("mm", args.lost_tracking),
    )  # fmt: skip


def run(args) -> int:
    reject_unused(args, "--replay", args.replay is not None, no_animation=False)
    if args.replay is not None:
        return replay(args)
    study = build_study(args)
    try:
        result = run_montecarlo(
            study, args.out, args.workers, args.scheduler, progress=not args.no_progress, names=FLAG_NAMES
        )
    except ScriptError as e:  # the reference (program compiled, CSV read) is checked before any run starts
        print(e.render(), file=sys.stderr)
        return 2
    except StewartError as e:  # the draws' checks name spec paths; the user gave flags
        raise flag_error(e, STUDY_FLAGS) from None
    rows, summary = result.rows, result.to_dict()
    if args.json:
        print_json(summary)
    else:
        print_text(summary)
    lost, failed = summary["lost_tracking_runs"], summary["failed_runs"]
    if lost:
        print(
            f"stewart-drake montecarlo: {len(lost)} of {len(rows)} runs lost tracking (leg error > {args.lost_tracking:g} mm or failed): "
            f"runs {', '.join(map(str, lost[:10]))}{' …' if len(lost) > 10 else ''}",
            file=sys.stderr,
        )
    if failed:
        print(f"stewart-drake montecarlo: {len(failed)} of {len(rows)} runs failed:", file=sys.stderr)
        for f in failed[:10]:
            print(f"  run {f['run']}: {f['reason']}", file=sys.stderr)
        if len(failed) > 10:
            print(f"  … and {len(failed) - 10} more (results.csv, column 'failures')", file=sys.stderr)
    return 0 if summary["ok"] else 1


def print_text(summary: dict) -> None:
    """The study summary as text: error (mm, deg) and force ripple (N) percentiles, the worst run, the strongest
    sensitivities, the files."""
    m = summary["metrics"]
    print(f"{summary['runs']} runs (study {summary['key']})")
    for k, scale, unit in (
        ("max_leg_error_m", 1e3, "mm"),
        ("max_position_error_m", 1e3, "mm"),
        ("max_angle_error_rad", 57.29577951308232, "deg"),
        ("force_ripple_rms_N", 1.0, "N"),
    ):
        s = m[k]
        if s:
            print(
                f"  {k.rsplit('_', 1)[0].removesuffix('_rms'):22s} p50 {s['p50'] * scale:.4g}  p95 {s['p95'] * scale:.4g}  max {s['max'] * scale:.4g} {unit}"
            )
    w = summary["worst_run"]
    print(f"  worst run {w['run']} (seed {w['seed']}): max leg error {w['max_leg_error_m'] * 1e3:.4g} mm")
    for d in summary["sensitivity"]["max_leg_error_m"][:5]:
        print(f"  sensitivity {d['parameter']:24s} ρ = {d['spearman']:+.3f}")
    print(f"  files: {', '.join(summary['files'])}")


def replay(args) -> int:
    """Re-run one run of the study in ``--out`` and compare its row with the study's."""
    out = Path(args.out)
    study, settings, rows = _finished_study(out)
    if not 0 <= args.replay < len(rows):
        raise OptionError(OptionError.NO_RUN.format(run=args.replay, out=str(out), last=len(rows) - 1))
    _check_replay_options(args, study, settings)
    # written into the study's folder as this replay's own files (replay-K/), beside the study's and any
    # others (force: never touched, a name clash refused); checked before the run
    study_folder = OutputFolder(out, command=f"{REPLAY_COMMAND} {args.replay}", force=True)
    # the C engine without a compiler here: Python, with the note (bit-identical, so the check still holds)
    study = dataclasses.replace(study, engine=resolve_engine(study.engine, "stewart-drake montecarlo"))
    row = run_scenario(study, args.replay, keep_log=True)
    log = row.pop("log")
    want = rows[args.replay]
    differ = [k for k in want if k != "wall_s" and not _same(want[k], row.get(k))]
    folder = out / f"replay-{args.replay}"
    result = {"run": args.replay, "bit_identical": not differ, "differing_columns": differ, "row": row}
    with atomic_folder(study_folder) as top:
        tmp = top / folder.name
        tmp.mkdir()
        files = []
        if log is not None:
            ref = study.reference()
            files += log.save(tmp) + write_plots(log, log.length_error(ref, _plant_platform(study, args.replay)), tmp)
            if not args.no_animation:
                files.append(write_animation(_plant_platform(study, args.replay), log, tmp / "animation.html"))
        (tmp / "row.json").write_text(dumps_strict(result))
        result["files"] = [str(folder / p.name) for p in files + [tmp / "row.json"]]
    if args.json:
        print_json(result)
    else:
        print(
            f"replay of run {args.replay}: {'bit-identical to its row' if not differ else 'DIFFERS in ' + ', '.join(differ)}; "
            f"max leg error {row['max_leg_error_m'] * 1e3:.6g} mm; files in {folder}"
        )
    return 0 if not differ else 1


def _finished_study(out: Path):
    """``(study, settings, rows)`` of the finished study in ``out`` (``study.json``, ``results.parquet``); a
    file missing, or one a study did not write (edited, truncated, foreign), is one line naming it."""
    for name in (STUDY_FILE, "results.parquet"):
        if not (out / name).is_file():
            raise OptionError(OptionError.NO_STUDY.format(out=str(out), file=name))
    try:
        stored = json.loads((out / STUDY_FILE).read_text())
        study = study_from_settings(stored["settings"], stored["runs"])
    except StewartError:
        raise
    except KeyError as e:
        raise OptionError(OptionError.BAD_STUDY.format(path=out / STUDY_FILE, reason=f"no {e.args[0]!r}")) from None
    except (ValueError, TypeError, AttributeError) as e:  # not JSON, or values of the wrong kind
        raise OptionError(OptionError.BAD_STUDY.format(path=out / STUDY_FILE, reason=e)) from None
    try:
        rows = read_table(out)
    except (OSError, ValueError, KeyError) as e:  # pyarrow's ArrowInvalid is a ValueError
        reason = f"no {e.args[0]!r} column" if isinstance(e, KeyError) else str(e).splitlines()[0]
        raise OptionError(OptionError.BAD_STUDY.format(path=out / "results.parquet", reason=reason)) from None
    return study, stored["settings"], rows


# the options that define a study (its settings and its number of runs)
STUDY_OPTIONS = (
    "machine",
    "set",
    "platform",
    "trajectory",
    "program",
    "length_unit",
    "angle_unit",
    "fit",
    "runs",
    "seed",
    "vary",
    "controller",
    "engine",
    "integrator",
    "duration",
    "plant_step",
    "lost_tracking",
)


def _check_replay_options(args, stored, settings: dict) -> None:
    """A replay runs the stored study; study options given with ``--replay`` must describe that same study
    (they were ignored: ``--integrator cenic`` replayed a SAP study as SAP, silently). The engine is
    compared only when given (a study's engine is the one resolved on the machine that ran it)."""
    from stewart_drake.cli import build_parser

    defaults = vars(build_parser(only="montecarlo").parse_args(["montecarlo"]))
    if all(getattr(args, n) == defaults[n] for n in STUDY_OPTIONS):
        return
    mine = study_settings(build_study(args)) | ({} if args.engine else {"engine": settings.get("engine")})
    mine = json.loads(json.dumps(mine, default=repr))  # as stored: lists, not tuples
    if settings_key(mine) == settings_key(settings) and args.runs in (defaults["runs"], stored.runs):
        return
    diff = [f"runs {stored.runs} there, {args.runs} here"] if args.runs not in (defaults["runs"], stored.runs) else []
    for k in sorted(set(mine) | set(settings)):
        a, b = settings.get(k), mine.get(k)
        if a != b:
            diff.append(
                k if isinstance(a, (dict, list)) or isinstance(b, (dict, list)) else f"{k} {a!r} there, {b!r} here"
            )
    raise OptionError(
        OptionError.REPLAY_OTHER.format(run=args.replay, out=str(args.out), diff="; ".join(diff[:3]) or "settings")
    )


def _plant_platform(study, index):
    return plant_platform(study.platform, draw(study, index)[1])


def _same(a, b) -> bool:
    """Equal values (floats bit for bit: equal, or both NaN)."""
    if isinstance(a, float) and isinstance(b, float):
        return a == b or (a != a and b != b)
    return a == b
