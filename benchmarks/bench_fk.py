"""Forward-kinematics throughput: batched Newton, Drake MathematicalProgram, all assembly modes
(multi-start search and the complete parameter homotopy of ``stewart_drake.homotopy``).

Run by hand: ``.venv/bin/python benchmarks/bench_fk.py [--quick] [--homotopy|--homotopy-only] [--fksgp DIR]``.
The homotopy section times both path-tracker engines (compiled ``c``, the default, and the ``numpy`` reference)
in the same run, and, with ``--fksgp``, fkSGP's own Python solver from a checkout of it. Pins nothing; prints absolute
figures for this machine and ratios measured in the same run (the ratios travel between machines,
the absolute numbers do not). Single core: set OMP/OPENBLAS threads to 1 before numpy loads.
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from stewart_drake.core.geometry import load_preset  # noqa: E402
from stewart_drake.core.kinematics import leg_lengths  # noqa: E402
from stewart_drake.core.newton_fk import forward_kinematics  # noqa: E402
from stewart_drake.core.sampling import random_poses  # noqa: E402


def best_of(f, repeat=3):
    ts = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = f()
        ts.append(time.perf_counter() - t0)
    return min(ts), out


def newton_rates(n: int) -> list[tuple]:
    rows = []
    for name in ("utn-dynamic", "gonzalez-dutra-2009", "utn-kinematic"):
        p = load_preset(name)
        q = random_poses(p, n, seed=1, region="workspace")
        L = leg_lengths(p, q)
        t_chk, r = best_of(lambda: forward_kinematics(p, L, on_singular="ignore"))
        t_raw, _ = best_of(lambda: forward_kinematics(p, L, check_singularity=False))
        # Trajectory following: start 1 mm / 1 mrad from the answer.
        t_trk, r2 = best_of(lambda: forward_kinematics(p, L, q + 1e-3, check_singularity=False))
        one = L[0]
        t_one, _ = best_of(lambda: [forward_kinematics(p, one, check_singularity=False) for _ in range(200)])
        rows.append(
            (
                name,
                n,
                n / t_chk,
                n / t_raw,
                n / t_trk,
                200 / t_one,
                r.iterations.mean(),
                r2.iterations.mean(),
                r.converged.mean(),
            )
        )
    return rows


def program_times(repeat: int) -> list[tuple]:
    from stewart_drake.drake.program_fk import ProgramFK

    p = load_preset("gonzalez-dutra-2009")
    q = p.home_pose() + [0.05, -0.03, 0.02, 0.1, -0.05, 0.2]
    L = leg_lengths(p, q)
    guess = q + [0.02, 0.01, -0.02, 0.1, 0.05, -0.1]
    rows = []
    for rot in ("quaternion", "matrix"):
        for solver in ("snopt", "ipopt"):
            prog = ProgramFK(p, rot, solver)
            ts = [prog.solve(L, guess).solve_time_s for _ in range(repeat)]
            wall, _ = best_of(lambda: prog.solve(L, guess))
            rows.append((rot, solver, 1e3 * float(np.median(ts)), 1e3 * wall))
    t_build, _ = best_of(lambda: ProgramFK(p))
    rows.append(("(build program)", "", 1e3 * t_build, 1e3 * t_build))
    return rows


def assembly_times() -> list[tuple]:
    from stewart_drake.core.reference_platforms import dietmaier_platform, general_platform
    from stewart_drake.drake.program_fk import assembly_modes

    cases = [("dietmaier-1998",) + dietmaier_platform()]
    for seed in (0, 4):
        cases.append((f"general 6-6 (seed {seed})",) + general_platform(seed))
    for name in ("utn-dynamic", "gonzalez-dutra-2009"):
        p = load_preset(name)
        cases.append((f"{name} at home", p, leg_lengths(p, p.home_pose())))
    rows = []
    for label, p, L in cases:
        t_fast, a = best_of(lambda: assembly_modes(p, L, polish=None), 2)
        t_full, b = best_of(lambda: assembly_modes(p, L), 2)
        rows.append(
            (label, len(b), b.max_solutions, b.complete, sum(m.certified for m in b.modes), t_fast, t_full, b.starts)
        )
    return rows


# fkSGP (Martyushev, elimination templates, Mech. Mach. Theory 215 (2025) 106170, arXiv 2505.00634), per-case
# times in Python as quoted by the project's issue 15: ~11-15 ms on Dietmaier's general 6-6, ~5 ms on a planar
# 6-6; it does not handle the 3-fold symmetric 6-6 (roots at infinity) nor 3-6 platforms. Not measured here
# unless --fksgp points at a checkout of github.com/martyushev/fkSGP (MIT; not part of this project).
FKSGP_MS = {
    "dietmaier-1998": "11-15",
    "planar": "~5",
    "gonzalez-dutra-2009": "fails",
    "utn-dynamic": "fails",
    "utn-kinematic": "fails",
}


def fksgp_times(path, cases, repeat: int) -> dict:
    """{label: (median CPU ms per length set, real postures it returned per set)} of fkSGP's Python solver
    (``solver66``; ``solver6p6p`` when both plates are planar) on the same cases, from a checkout at
    ``path``. Its frames put the first base and plate anchors at the origin (a change of pose
    coordinates only); its squared-length input is L²; its internal random rotations are seeded."""
    import sys

    sys.path.insert(0, str(path))
    import python as fk  # the checkout's python/ package

    out = {}
    for label, _, p, Ls in cases:
        X = p.base_anchors - p.base_anchors[0]
        x = p.top_anchors_per_leg - p.top_anchors_per_leg[0]
        planar = np.all(np.abs(X[:, 2]) < 1e-12) and np.all(np.abs(x[:, 2]) < 1e-12)
        solver = fk.solver6p6p if planar else fk.solver66
        np.random.seed(0)
        cs, n_real = [], []
        for L in Ls:
            for _ in range(repeat):
                c0 = time.process_time()
                try:
                    Rt, _ = solver(X, x, L**2, 1)
                    n = len(Rt)
                except Exception as err:  # its template assumes 40 finite roots: report how it fails
                    n = type(err).__name__
                cs.append(time.process_time() - c0)
            n_real.append(n)
        out[label] = (1e3 * float(np.median(cs)), n_real)
    return out


def homotopy_cases(n_poses: int):
    """(label, fkSGP key, platform, (k, 6) length sets) for the homotopy benchmark."""
    from stewart_drake.core.reference_platforms import dietmaier_platform, planar_platform

    p, L = dietmaier_platform()
    cases = [("dietmaier-1998 (6-6, 40 real)", "dietmaier-1998", p, L[None])]
    for seed in range(3):
        p, L = planar_platform(seed)
        cases.append((f"planar 6-6 seed {seed}", "planar", p, L[None]))
    rng = np.random.default_rng(0)
    for name in ("gonzalez-dutra-2009", "utn-dynamic", "utn-kinematic"):
        p = load_preset(name)
        q = p.home_pose() + np.c_[rng.uniform(-0.05, 0.05, (n_poses, 3)), rng.uniform(-0.2, 0.2, (n_poses, 3))]
        cases.append((f"{name} ({n_poses} poses)", name, p, leg_lengths(p, q)))
    return cases


ENGINES = ("c", "numpy")  # the compiled tracker (default) and the numpy reference it replaced


def homotopy_times(n_poses: int, repeat: int, with_multistart: bool) -> list[tuple]:
    """Per case, per tracker engine: median time per length set (stage one cached; wall and process CPU),
    its one-time stage-one cost, the outcome; whether both engines gave the same path classes and modes;
    the multi-start search's time (polish off) on the same sets."""
    from stewart_drake.core.assembly_modes import assembly_modes
    from stewart_drake.homotopy import solve
    from stewart_drake.homotopy.solve import _PLATFORM_STARTS
    from stewart_drake.homotopy.track import TrackOptions

    rows = []
    for label, key, p, Ls in homotopy_cases(n_poses):
        per_engine, outs = {}, {}
        for engine in ENGINES:
            o = TrackOptions(engine=engine)
            _PLATFORM_STARTS.clear()
            t0 = time.perf_counter()
            solve(p, Ls[0], options=o)
            t_first = time.perf_counter() - t0
            ts, cs, ok, cert, paths, res = [], [], True, True, None, []
            for L in Ls:
                for _ in range(repeat):
                    t0, c0 = time.perf_counter(), time.process_time()
                    r = solve(p, L, options=o)
                    ts.append(time.perf_counter() - t0)
                    cs.append(time.process_time() - c0)
                ok &= r.complete
                cert &= all(m.certified for m in r.modes)
                paths = (r.n_paths, r.max_solutions, r.counts())
                res.append(r)
            med = float(np.median(ts))
            per_engine[engine] = (paths, ok, cert, 1e3 * med, 1e3 * float(np.median(cs)), 1e3 * (t_first - med))
            outs[engine] = res
        same = all(
            a.classes == b.classes
            and len(a.modes) == len(b.modes)
            and all(np.abs(m.position - n.position).max() < 1e-9 for m, n in zip(a.modes, b.modes))
            for a, b in zip(*outs.values())
        )
        t_ms, c_ms = [], []
        if with_multistart:
            for L in Ls:
                t0, c0 = time.perf_counter(), time.process_time()
                assembly_modes(p, L, polish=None)
                t_ms.append(time.perf_counter() - t0)
                c_ms.append(time.process_time() - c0)
        nan = float("nan")
        n_real = [sum(c == "real" for c in r.classes) for r in outs["c"]]
        rows.append(
            (
                label,
                key,
                per_engine,
                same,
                1e3 * float(np.median(t_ms)) if t_ms else nan,
                1e3 * float(np.median(c_ms)) if c_ms else nan,
                n_real,
            )
        )
    return rows


def homotopy_batch(n: int) -> list[tuple]:
    """Batched mode: n length sets of one platform in one call, per-set time, per engine."""
    from stewart_drake.core.reference_platforms import dietmaier_platform, planar_platform
    from stewart_drake.homotopy import solve_batch
    from stewart_drake.homotopy.track import TrackOptions

    rows = []
    rng = np.random.default_rng(1)
    platforms = {"dietmaier-1998": dietmaier_platform()[0], "planar 6-6 seed 0": planar_platform(0)[0]}
    platforms.update({name: load_preset(name) for name in ("gonzalez-dutra-2009", "utn-dynamic")})
    for name, p in platforms.items():
        q = p.home_pose() + np.c_[rng.uniform(-0.05, 0.05, (n, 3)), rng.uniform(-0.2, 0.2, (n, 3))]
        L = leg_lengths(p, q)
        for engine in ENGINES:
            o = TrackOptions(engine=engine)
            solve_batch(p, L[:1], options=o)  # stage one, cached
            c0 = time.process_time()
            t, rs = best_of(lambda: solve_batch(p, L, options=o), 1)
            cpu = time.process_time() - c0
            rows.append((name, engine, n, 1e3 * t / n, 1e3 * cpu / n, sum(r.complete for r in rs), rs[0].timing))
    return rows


def fksgp_cell(measured, n_real, quoted: str) -> str:
    """fkSGP's CPU ms when measured ("*" when its real postures differ from the homotopy's), else the quote."""
    if measured is None:
        return quoted
    ms, its = measured
    return f"{ms:.1f}" + ("" if its == n_real else "*")


def print_homotopy(args) -> None:
    print("\n# Complete FK by parameter homotopy (all paths, classified, real modes certified) vs multi-start")
    print("# engines: c = compiled tracker (default), numpy = the vectorised reference tracker")
    print(
        f"{'case':32s} {'paths':>9s} {'complete':>8s} {'cert':>5s} {'c ms':>6s} {'c cpu':>6s} {'numpy ms':>8s} "
        f"{'np cpu':>6s} {'stage1 c/np':>11s} {'same':>5s} {'multi cpu':>9s} {'multi/c':>7s} {'multi/np':>8s} "
        f"{'np/c':>5s} {'fkSGP ms':>8s}  classes"
    )
    n_poses, repeat = (3, 3) if args.quick else (5, 5)
    rows = homotopy_times(n_poses, repeat, not args.homotopy_only)
    fk = fksgp_times(args.fksgp, homotopy_cases(n_poses), repeat) if args.fksgp else {}
    for label, key, pe, same, ms, mcpu, n_real in rows:
        (n2, nmax, counts), ok, cert, med, cpu, first = pe["c"]
        _, ok2, cert2, med2, cpu2, first2 = pe["numpy"]
        cls = " ".join(f"{k}={v}" for k, v in counts.items() if v)
        print(
            f"{label:32s} {n2:4d}/{nmax:<4d} {str(ok and ok2):>8s} {str(cert and cert2):>5s} {med:6.1f} {cpu:6.1f} "
            f"{med2:8.1f} {cpu2:6.1f} {first:5.0f}/{first2:<5.0f} {str(same):>5s} {mcpu:9.1f} {mcpu / cpu:7.1f} "
            f"{mcpu / cpu2:8.1f} {cpu2 / cpu:5.1f} {fksgp_cell(fk.get(label), n_real, FKSGP_MS[key]):>8s}  {cls}"
        )
    print("(ms: median per length set, wall and process CPU time, with the platform's stage one cached; stage1: its")
    print(" one-time wall cost (ms); same: both engines gave the same path classes and real modes; ratios: CPU time,")
    print(" measured in this run (CPU because the machine may be shared: wall time then includes waiting); fkSGP:")
    print(
        " "
        + (
            "CPU ms measured in this run (--fksgp), * = its real postures differ from the homotopy's"
            if fk
            else "quoted, not measured here"
        )
        + "; complete/cert: for both engines)"
    )
    if fk:
        print("real postures per length set, homotopy vs fkSGP (realOnly; an exception name where it raised):")
        for label, _, _, _, _, _, n_real in rows:
            print(f"  {label:32s} homotopy {n_real}  fkSGP {fk[label][1]}")
    print("\n# Batched homotopy: many length sets of one platform in one call")
    for name, engine, n, per, cpu, n_ok, timing in homotopy_batch(20 if args.quick else 100):
        tm = ", ".join(f"{k} {v:.2f} s" for k, v in timing.items())
        print(
            f"{name:22s} {engine:5s} {n:4d} sets: {per:6.2f} ms wall, {cpu:6.2f} ms CPU per set, {n_ok}/{n} complete ({tm})"
        )


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="smaller batches")
    ap.add_argument("--homotopy", action="store_true", help="only the complete-FK (homotopy vs multi-start) section")
    ap.add_argument(
        "--homotopy-only", action="store_true", help="only the homotopy timings, without the multi-start comparison"
    )
    ap.add_argument(
        "--fksgp",
        metavar="DIR",
        help="a checkout of github.com/martyushev/fkSGP: time its Python solver on the same cases",
    )
    args = ap.parse_args(argv)
    n = 20_000 if args.quick else 100_000
    if args.homotopy or args.homotopy_only:
        print_homotopy(args)
        return 0

    print(f"\n# Newton FK, batch of {n} poses (best of 3)")
    print(
        f"{'platform':22s} {'solves/s':>10s} {'no check':>10s} {'tracking':>10s} {'1-call/s':>9s} {'iters':>6s} {'trk it':>6s} {'conv':>6s}"
    )
    rows = newton_rates(n)
    for name, _, chk, raw, trk, one, it, it2, conv in rows:
        print(f"{name:22s} {chk:10.3g} {raw:10.3g} {trk:10.3g} {one:9.3g} {it:6.2f} {it2:6.2f} {conv:6.3f}")
    r0 = rows[0]
    print(
        f"ratio batch/single-call (utn-dynamic): {r0[2] / r0[5]:.0f}x; singularity check costs {100 * (1 - r0[2] / r0[3]):.0f}% of the rate"
    )

    print("\n# MathematicalProgram FK, one solve from a guess 2 cm / 0.1 rad off (gonzalez-dutra-2009)")
    prog_rows = program_times(20 if args.quick else 100)
    for rot, solver, med, wall in prog_rows:
        print(f"{rot:16s} {solver:6s} solver {med:7.3f} ms   wall {wall:7.3f} ms")
    snopt_ms = prog_rows[0][3]
    print(f"ratio SNOPT solve / Newton batch solve (gonzalez-dutra): {snopt_ms * 1e-3 * rows[1][2]:.0f}x")

    print("\n# All assembly modes (Newton multi-start; 'full' adds the SNOPT confirmation)")
    print(
        f"{'geometry':28s} {'modes':>5s} {'max':>4s} {'complete':>8s} {'certified':>9s} {'newton s':>9s} {'full s':>7s} {'starts':>7s}"
    )
    for label, k, kmax, comp, cert, tf, tfull, starts in assembly_times():
        print(f"{label:28s} {k:5d} {kmax:4d} {str(comp):>8s} {cert:9d} {tf:9.3f} {tfull:7.3f} {starts:7d}")
    print_homotopy(args)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
