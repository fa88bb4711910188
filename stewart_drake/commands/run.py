"""``stewart-drake run``: run a motion program (.stw, seed 004 part 3): trajectory → IK → forces.

Everything is computed (and every error reported, as ``file:line:column: error: ...``) before any
file is written; the output folder is then written in one go.
"""

from __future__ import annotations

import csv
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from stewart_drake.commands._common import (
    OutputFolder,
    add_force_arg,
    add_platform_arg,
    dumps_strict,
    platform_from_args,
    print_json,
    reject_unused,
)
from stewart_drake.core.rotations import CONVENTIONS
from stewart_drake.errors import (
    OPTION_NEEDS_BRANCHES,
    OPTION_NON_NEGATIVE,
    OPTION_RUN_RATE,
    OPTION_SIMULATE_EMPTY,
    OPTION_SIMULATE_UTN,
    OptionError,
    UsageError,
)
from stewart_drake.script.source import read_program
from stewart_drake.system.output_folder import atomic_folder

SIMULATE_CONTROLLERS = ("fixed", "float")
SETTLE = 0.5  # s simulated after the program's end (the reference holds the final pose)
MAX_PRINTED = 20  # moves listed on the terminal


def register(sub) -> None:
    p = sub.add_parser("run", help="run a motion program (.stw): leg lengths and forces along its trajectory")
    p.add_argument("program", metavar="PROGRAM.stw", help="motion-language source file")
    add_platform_arg(p)
    p.add_argument("--out", metavar="DIR", help="output folder (default: runs/<program name>)")
    p.add_argument("--rate", type=float, default=100.0, help="trajectory samples per second (default 100)")
    p.add_argument(
        "--convention",
        choices=list(CONVENTIONS),
        default="utn",
        help="Euler convention of alpha, beta, gama (default utn: Ry·Rx·Rz)",
    )
    p.add_argument(
        "--coriolis",
        choices=["on", "off"],
        default="on",
        help="include C(q, q̇) q̇ in the forces (default on; off = the seed's model)",
    )
    add_branch_args(p)
    p.add_argument(
        "--simulate",
        action="store_true",
        help="also run the trajectory through the controller-in-the-loop Drake simulation",
    )
    p.add_argument(
        "--controller",
        choices=SIMULATE_CONTROLLERS,
        default="fixed",
        help="with --simulate: fixed-point (DSP) or float controller (default fixed)",
    )
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    add_force_arg(p)
    p.set_defaults(func=run)


def run(args) -> int:
    from stewart_drake.script import ScriptError, run_program

    reject_unused(args, "--simulate", args.simulate, controller="fixed")
    text = read_program(args.program)
    out = Path(args.out) if args.out else Path("runs") / Path(args.program).stem
    out_folder = OutputFolder(str(out), force=args.force, force_option="--force")
    platform = platform_from_args(args)
    if not (np.isfinite(args.rate) and args.rate > 0):
        raise OptionError(OPTION_RUN_RATE.format(value=args.rate))
    try:
        result = run_program(
            text, args.program, platform, rate=args.rate, convention=args.convention, coriolis=args.coriolis == "on"
        )
        sim = simulate(platform, result, args) if args.simulate else None
        branches = check_branches(platform, result, args)
    except ScriptError as e:
        print(e.render(), file=sys.stderr)
        return 2
    summary = summarize(result, args.program, platform.stroke)
    if branches is not None:
        summary["branches"] = branches
    if sim is not None:
        summary["simulation"] = sim["summary"]
    write_outputs(out_folder, result, summary, sim)
    if args.json:
        print_json(summary)
    else:
        print_summary(summary, out)
    failures = summary.get("simulation", {}).get("failures", [])
    for f in failures:
        print(f"stewart-drake run: {f}", file=sys.stderr)
    return max(branch_exit(branches, args), 1 if failures else 0)


BRANCH_DEFAULTS = {"branch_margin": 20.0, "singularity_margin": 0.02, "branch_samples": 200}


def add_branch_args(p) -> None:
    """``--check-branches`` and its options (``homotopy.branches``)."""
    p.add_argument(
        "--check-branches",
        action="store_true",
        help="check branch safety: the distance from the trajectory to the nearest other assembly mode and to a singularity (complete homotopy FK at sampled poses); exit 1 below a margin",
    )
    p.add_argument(
        "--branch-margin",
        type=float,
        metavar="MM",
        help="with --check-branches: least allowed distance to another assembly mode, mm at the plate anchors (default 20)",
    )
    p.add_argument(
        "--singularity-margin",
        type=float,
        metavar="SIGMA",
        help="with --check-branches: least allowed smallest singular value of the scaled inverse Jacobian (default 0.02)",
    )
    p.add_argument(
        "--branch-samples",
        type=int,
        metavar="N",
        help="with --check-branches: trajectory samples checked, evenly spaced (default 200, at most 5000)",
    )


def check_branches(platform, result, args) -> dict | None:
    """Branch-safety summary of the program's trajectory (``homotopy.branches``), or None without
    ``--check-branches`` (its options are then refused)."""
    given = [k for k in BRANCH_DEFAULTS if getattr(args, k) is not None]
    if not args.check_branches:
        if given:
            raise UsageError(OPTION_NEEDS_BRANCHES.format(option=given[0].replace("_", "-")))
        return None
    for k, v in BRANCH_DEFAULTS.items():
        if getattr(args, k) is None:
            setattr(args, k, v)
    for name, v in (("--branch-margin", args.branch_margin), ("--singularity-margin", args.singularity_margin)):
        if not (np.isfinite(v) and v >= 0):
            raise OptionError(OPTION_NON_NEGATIVE.format(name=name, value=v))
    from stewart_drake.homotopy.branches import branch_safety

    traj = result.trajectory
    rep = branch_safety(platform, traj.t, traj.q, args.convention, samples=args.branch_samples)
    return rep.summary(args.branch_margin * 1e-3, args.singularity_margin)


def branch_exit(b: dict | None, args) -> int:
    """Exit status after the outputs are written: 1 (with a one-line reason) when not branch-safe."""
    if b is None or b["safe"]:
        return 0
    print(
        f"run --check-branches: not branch-safe: nearest other assembly mode {b['min_branch_distance_m'] * 1e3:.3f} mm "
        f"(margin {args.branch_margin:g} mm) at t = {b['min_branch_distance_t_s']:.3f} s; smallest sigma_min "
        f"{b['min_sigma_min']:.4g} (margin {args.singularity_margin:g}) at t = {b['min_sigma_min_t_s']:.3f} s"
        + ("" if b["all_complete"] else f"; FK not complete at samples {b['incomplete_samples']}")
        + (
            "" if b["fk_certified_every_sample"] else f"; real-time FK not certified at t = {b['fk_uncertified_t_s']} s"
        ),
        file=sys.stderr,
    )
    return 1


def simulate(platform, result, args) -> dict:
    """Controller in the loop along the program's trajectory, built and checked by ``api.simulation.plan_run``
    (the one home of a closed-loop run: the timing, size and reference checks of ``simulate``)."""
    # Deferred: only --simulate needs Drake; the rest of run is numpy.
    from stewart_drake.api.simulation import plan_run, run_plan

    if args.convention != "utn":
        raise UsageError(OPTION_SIMULATE_UTN)
    traj = result.trajectory
    if traj.duration <= 0:
        raise UsageError(OPTION_SIMULATE_EMPTY)
    reference = replace(traj, name=Path(args.program).stem)
    plan = plan_run(platform, reference, args.controller, traj.duration + SETTLE, command="run --simulate")
    warn = lambda w: print(f"stewart-drake run: warning: {w}", file=sys.stderr)  # noqa: E731
    sim = run_plan(plan, progress=True, on_warning=warn)
    log, err = sim.log.raw, sim.log.length_error
    return {
        "log": log,
        "length_error": err,
        "summary": {
            "controller": args.controller,
            "engine": plan.scenario.engine,
            "integrator": plan.scenario.integrator,
            "plant_steps": len(log.t),
            "settle_s": SETTLE,
            "max_abs_length_error_mm": np.abs(err).max(axis=0) * 1e3,
            "max_abs_actuator_force_N": np.abs(log.force).max(axis=0),
            **sim.verdict,
            "warnings": sim.warnings,
            **{k: sim.summary[k] for k in LOOP_MEASURES},  # the loop verdict's measures (control/chatter.py)
        },
    }


# the chatter measure's numbers in the run's summary (``control.chatter.chatter_measure``)
LOOP_MEASURES = ("force_ripple_N", "working_force_rms_N", "chatter_ratio", "ripple_range_fraction", "chatter_cause")


def segment_ends(traj) -> dict:
    """segment index -> index of its last sample."""
    return {int(k): i for i, k in enumerate(traj.segment)}


def summarize(result, program: str, stroke=None) -> dict:
    traj, L, F = result.trajectory, result.L, result.F
    ends = segment_ends(traj)
    moves = []
    for k, s in enumerate(traj.segments):
        if s.kind != "move":
            continue
        n = ends[k]
        mask = traj.segment == k
        moves.append(
            {
                "move": s.ordinal,
                "at": str(s.at) if s.at else None,
                "target": list(s.values),
                "units": list(s.units),
                "t_end_s": float(traj.t[n]),
                "lengths_mm": L[n] * 1e3,
                "max_abs_force_N": None if F is None else np.abs(F[mask]).max(axis=0),
            }
        )
    return {
        "program": program,
        "platform": result.platform,
        "convention": result.convention,
        "samples": len(traj.t),
        "duration_s": traj.duration,
        "moves": moves,
        "stroke_mm": None if stroke is None else [float(v) * 1e3 for v in stroke],
        "length_min_mm": L.min(axis=0) * 1e3,
        "length_max_mm": L.max(axis=0) * 1e3,
        "max_abs_force_N": None if F is None else np.abs(F).max(axis=0),
        "notes": list(result.notes),
    }


def write_outputs(out, result, summary: dict, sim: dict | None) -> None:
    """Write ``trajectory.csv`` (t, q, q̇, q̈ in SI: readable by ``stewart-drake dynamics --trajectory``),
    ``legs.csv`` (t, L mm, F N), ``summary.json``, ``lengths.png``, ``forces.png`` (and the simulation's
    logs) into ``out``, replacing it atomically."""
    with atomic_folder(out) as tmp:
        traj = result.trajectory
        with (tmp / "trajectory.csv").open("w", newline="") as fh:
            w = csv.writer(fh)
            names = ("px", "py", "pz", "alpha", "beta", "gama")
            w.writerow(["t"] + list(names) + [f"{n}_dot" for n in names] + [f"{n}_ddot" for n in names])
            for row in np.concatenate([traj.t[:, None], traj.q, traj.qd, traj.qdd], axis=1):
                w.writerow([repr(float(v)) for v in row])
        with (tmp / "legs.csv").open("w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(
                ["t_s"]
                + [f"L{i}_mm" for i in range(1, 7)]
                + ([f"F{i}_N" for i in range(1, 7)] if result.F is not None else [])
            )
            cols = [traj.t[:, None], result.L * 1e3] + ([result.F] if result.F is not None else [])
            for row in np.concatenate(cols, axis=1):
                w.writerow([f"{v:.10g}" for v in row])
        (tmp / "summary.json").write_text(dumps_strict(summary), encoding="utf-8")
        _plots(tmp, result, summary, sim)
        if sim is not None:
            sim["log"].save(tmp / "simulation")


def _plots(folder: Path, result, summary: dict, sim: dict | None) -> None:
    import matplotlib

    matplotlib.use("Agg")
    from stewart_drake.script.plots import plot_forces, plot_lengths, plot_tracking

    plot_lengths(result, summary["platform"], summary.get("stroke_mm")).savefig(
        folder / "lengths.png", dpi=110, bbox_inches="tight"
    )
    if result.F is not None:
        plot_forces(result).savefig(folder / "forces.png", dpi=110, bbox_inches="tight")
    if sim is not None:
        plot_tracking(sim["log"], sim["length_error"]).savefig(folder / "simulation.png", dpi=110, bbox_inches="tight")
    import matplotlib.pyplot as plt

    plt.close("all")


def print_summary(summary: dict, out: Path) -> None:
    print(
        f"{summary['program']}: {len(summary['moves'])} moves, {summary['duration_s']:.3f} s, "
        f"{summary['samples']} samples, platform {summary['platform']}"
    )
    shown = summary["moves"][:MAX_PRINTED]
    for m in shown:
        L = " ".join(f"{v:8.2f}" for v in m["lengths_mm"])
        F = "" if m["max_abs_force_N"] is None else f"   max |F| {np.max(m['max_abs_force_N']):8.2f} N"
        print(f"  #{m['move']:<3} {m['at']:<22} t = {m['t_end_s']:7.3f} s  L (mm) = {L}{F}")
    if len(summary["moves"]) > len(shown):
        print(f"  ... and {len(summary['moves']) - len(shown)} more moves (see summary.json)")
    for note in summary["notes"]:
        print(f"  note: {note}")
    if "simulation" in summary:
        s = summary["simulation"]
        print(
            f"  simulation ({s['controller']} controller): max |L - L_ref| = {np.max(s['max_abs_length_error_mm']):.3f} mm"
        )
    if "branches" in summary:
        b = summary["branches"]
        print(
            f"  branches ({b['samples_checked']} samples, {b['modes_min']}-{b['modes_max']} real modes, complete: {b['all_complete']}): "
            f"nearest other mode {b['min_branch_distance_m'] * 1e3:.3f} mm at t = {b['min_branch_distance_t_s']:.3f} s, "
            f"smallest sigma_min {b['min_sigma_min']:.4g} at t = {b['min_sigma_min_t_s']:.3f} s; real-time FK certified on the "
            f"branch at {'every' if b['fk_certified_every_sample'] else 'NOT every'} one of {b['fk_samples_followed']} samples "
            f"-> {'safe' if b['safe'] else 'NOT SAFE'}"
        )
    print(f"wrote {out}/")
