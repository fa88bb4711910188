"""``stewart-drake optimize``: design synthesis from a requirements file (NSGA-II on Dask), with a proof."""

from __future__ import annotations

import sys

from stewart_drake.commands._common import add_force_arg, output_folder, print_json
from stewart_drake.synthesis.api import optimize
from stewart_drake.synthesis.outputs import write_outputs
from stewart_drake.synthesis.proof import MAX_CELLS, START_CELLS
from stewart_drake.synthesis.requirements import OBJECTIVES
from stewart_drake.synthesis.search import CACHE, DEFAULT_POP
from stewart_drake.synthesis.synthesize import cells_note, not_proven
from stewart_drake.system.output_folder import claim_in_manifest, run_lock

HELP = "design synthesis: the geometry with the smallest actuators that meets a requirements file, proven"


def register(sub) -> None:
    p = sub.add_parser("optimize", help=HELP)
    p.add_argument(
        "--requirements",
        required=True,
        metavar="R.yaml",
        help="the requirements (stewart-drake init --requirements-template)",
    )
    p.add_argument(
        "--out",
        required=True,
        metavar="DIR",
        help="output folder; a search there with the same requirements and seed resumes",
    )
    p.add_argument(
        "--budget", type=int, default=480, metavar="N", help="design evaluations (whole generations; default 480)"
    )
    p.add_argument(
        "--pop-size", type=int, default=DEFAULT_POP, metavar="P", help=f"NSGA-II population (default {DEFAULT_POP})"
    )
    p.add_argument("--seed", type=int, default=0, metavar="S", help="search seed (default 0)")
    where = p.add_mutually_exclusive_group()
    where.add_argument(
        "--workers",
        type=int,
        default=1,
        metavar="K",
        help="LocalCluster worker processes (default 1; 0: in this process, no Dask)",
    )
    where.add_argument(
        "--scheduler", metavar="tcp://HOST:PORT", help="an existing Dask scheduler instead of a LocalCluster"
    )
    p.add_argument(
        "--pick",
        default="knee",
        metavar="knee|OBJECTIVE|ROW",
        help=f"the design written to design.yaml: knee (default), the best of an objective ({', '.join(OBJECTIVES)}) or a row of the front",
    )
    p.add_argument(
        "--max-cells",
        type=int,
        default=MAX_CELLS,
        metavar="N",
        help=f"the most cells each proof may examine: the box's, and force/speed/frequency/condition's (default "
        f"{MAX_CELLS}; a proof starts with {START_CELLS} and doubles them while the volume left unproven shrinks)",
    )
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    add_force_arg(p)
    p.set_defaults(func=run)


def run(args) -> int:
    out = output_folder(args)
    with run_lock(out.path, option="--out", typed=out.typed):  # one run at a time in the folder, to its end
        return _run(args, out)


def _run(args, out) -> int:
    r = optimize(
        args.requirements,
        budget=args.budget,
        seed=args.seed,
        workers=args.workers,
        scheduler=args.scheduler,
        pick=args.pick,
        pop_size=args.pop_size,
        max_cells=args.max_cells,
        cache=out.path,
        progress=not args.no_progress and sys.stderr.isatty(),
    )
    result = r.synthesis
    with out.writing() as tmp:
        write_outputs(result, tmp, args.requirements, cache_from=out.path / CACHE)
    # the journal stays append-only: a later run with a larger --budget continues it (claimed whole, its growth
    # read as a change and the run refused at its end)
    claim_in_manifest(out.path, [CACHE], prefix=True)
    if args.json:
        print_json(result.to_dict())
    else:
        s, d = result.search, result.design
        print(
            f"optimize {args.requirements}: {len(s.rows)} designs ({s.evaluated} evaluated now, {s.cached} from {args.out}), "
            f"{len(s.front)} on the Pareto front; chosen ({args.pick}):"
        )
        for name, value in zip(s.requirements.variables, d["x"], strict=True):
            shown = f"{value * 57.29577951308232:.3f} deg" if name.endswith("half_angle") else f"{value:.4f} m"
            print(f"  {name} = {shown}")
        print(
            f"  stroke [{d['L_min']:.4f}, {d['L_max']:.4f}] m, peak force {d['peak_force']:.1f} N, lowest frequency {d['frequency']:.1f} Hz"
        )
        pr, perf = result.proof, result.performance
        if pr.status == "unresolved":
            print(f"  proof of the box: {not_proven(pr.cells_examined, pr.unresolved_count, pr.stopped)}")
        else:
            print(f"  proof of the box: {pr.status} ({pr.cells_examined} cells, {pr.seconds:.2f} s)")
        print(f"  proof of force, speed, frequency, condition: {perf.cells_examined} cells, {perf.seconds:.2f} s")
        if pr.witness:
            print(
                f"  witness: pose {pr.witness['pose']} leg {pr.witness['leg']} {pr.witness['what']} (L = {pr.witness['length_m']:.6f} m)"
            )
        for r in result.table:
            unresolved = r.get("status", r["achieved"]) == "unresolved"
            mark = "met" if r["met"] else "not proven yet" if unresolved else "NOT MET"
            note = cells_note(r["cells_used"], r["cells_left"], r["stopped"]) if "cells_left" in r else ""
            if isinstance(r["achieved"], str):
                room = f" (least stroke margin {r['margin'] * 1e3:.2f} mm)" if r["margin"] is not None else ""
                print(f"  {mark:14s} {r['requirement']}: {note if unresolved else r['achieved'] + room}")
            else:
                proof = ""
                if unresolved:
                    proof = f" {note}"
                elif "status" in r:  # the performance proof's verdict
                    proof = f"; {r['status']}" + (f", bound {r['bound']:.6g}" if r["bound"] is not None else "")
                    if r.get("witness"):
                        proof += f" (witness pose {r['witness']['pose']}: {r['witness']['value']:.6g})"
                shown = "sampled" if unresolved else "achieved"
                print(
                    f"  {mark:14s} {r['requirement']}: required {r['required']:g}, {shown} {r['achieved']:.6g} {r['unit']}{proof}"
                )
        print(f"  wrote {args.out}/ (design.yaml, pareto.parquet/.csv/.png, requirements.json)")
    return 0 if result.ok else 1
