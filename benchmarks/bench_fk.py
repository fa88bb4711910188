"""Forward-kinematics throughput: batched Newton, Drake MathematicalProgram, all assembly modes
(multi-start search and the complete parameter homotopy of ``stewart_drake.homotopy``).

Run by hand: ``.venv/bin/python benchmarks/bench_fk.py [--quick]``. Pins nothing; prints absolute
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

from stewart_drake.core.newton_fk import forward_kinematics  # noqa: E402
from stewart_drake.core.sampling import random_poses  # noqa: E402
from stewart_drake.core.geometry import load_preset  # noqa: E402
from stewart_drake.core.kinematics import leg_lengths  # noqa: E402


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
        rows.append((name, n, n / t_chk, n / t_raw, n / t_trk, 200 / t_one, r.iterations.mean(), r2.iterations.mean(), r.converged.mean()))
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
        rows.append((label, len(b), b.max_solutions, b.complete, sum(m.certified for m in b.modes), t_fast, t_full, b.starts))
    return rows


# fkSGP (Martyushev et al., elimination templates, Mech. Mach. Theory 2025), published per-case times in
# Python: ~11-15 ms on Dietmaier's general 6-6, ~5 ms on a planar 6-6; it does not handle the 3-fold
# symmetric 6-6 (roots at infinity) nor 3-6 platforms. Quoted from its paper, not measured here.
FKSGP_MS = {"dietmaier-1998": "11-15", "planar": "~5", "gonzalez-dutra-2009": "fails", "utn-dynamic": "fails", "utn-kinematic": "fails"}


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


def homotopy_times(n_poses: int, repeat: int, with_multistart: bool) -> list[tuple]:
    """Per length set: homotopy median time (stage one cached), its one-time stage-one cost, the
    multi-start search's time (polish off) on the same sets, and the outcome."""
    from stewart_drake.core.assembly_modes import assembly_modes
    from stewart_drake.homotopy import solve
    from stewart_drake.homotopy.solve import _PLATFORM_STARTS

    rows = []
    for label, key, p, Ls in homotopy_cases(n_poses):
        _PLATFORM_STARTS.clear()
        t0 = time.perf_counter()
        solve(p, Ls[0])
        t_first = time.perf_counter() - t0
        ts, cs, ok, cert, paths = [], [], True, True, None
        for L in Ls:
            for _ in range(repeat):
                t0, c0 = time.perf_counter(), time.process_time()
                r = solve(p, L)
                ts.append(time.perf_counter() - t0)
                cs.append(time.process_time() - c0)
            ok &= r.complete
            cert &= all(m.certified for m in r.modes)
            paths = (r.n_paths, r.max_solutions, r.counts())
        t_ms, c_ms = [], []
        if with_multistart:
            for L in Ls:
                t0, c0 = time.perf_counter(), time.process_time()
                assembly_modes(p, L, polish=None)
                t_ms.append(time.perf_counter() - t0)
                c_ms.append(time.process_time() - c0)
        med = float(np.median(ts))
        nan = float("nan")
        rows.append((label, key, paths, ok, cert, 1e3 * med, 1e3 * float(np.median(cs)), 1e3 * (t_first - med),
                     1e3 * float(np.median(t_ms)) if t_ms else nan, 1e3 * float(np.median(c_ms)) if c_ms else nan))
    return rows


def homotopy_batch(n: int) -> list[tuple]:
    """Batched mode: n length sets of one platform in one call, per-set time."""
    from stewart_drake.core.reference_platforms import dietmaier_platform, planar_platform
    from stewart_drake.homotopy import solve_batch

    rows = []
    rng = np.random.default_rng(1)
    platforms = {"dietmaier-1998": dietmaier_platform()[0], "planar 6-6 seed 0": planar_platform(0)[0]}
    platforms.update({name: load_preset(name) for name in ("gonzalez-dutra-2009", "utn-dynamic")})
    for name, p in platforms.items():
        q = p.home_pose() + np.c_[rng.uniform(-0.05, 0.05, (n, 3)), rng.uniform(-0.2, 0.2, (n, 3))]
        L = leg_lengths(p, q)
        solve_batch(p, L[:1])  # stage one, cached
        c0 = time.process_time()
        t, rs = best_of(lambda: solve_batch(p, L), 1)
        cpu = time.process_time() - c0
        rows.append((name, n, 1e3 * t / n, 1e3 * cpu / n, sum(r.complete for r in rs), rs[0].timing))
    return rows


def print_homotopy(args) -> None:
    print("\n# Complete FK by parameter homotopy (all paths, classified, real modes certified) vs multi-start")
    print(f"{'case':36s} {'paths':>9s} {'complete':>8s} {'cert':>5s} {'hom ms':>7s} {'hom cpu':>7s} {'stage1':>7s} "
          f"{'multi ms':>9s} {'multi cpu':>9s} {'ratio':>6s} {'fkSGP ms':>9s}  classes")
    rows = homotopy_times(3 if args.quick else 5, 3 if args.quick else 5, not args.homotopy_only)
    for label, key, (n2, nmax, counts), ok, cert, med, cpu, first, ms, mcpu in rows:
        cls = " ".join(f"{k}={v}" for k, v in counts.items() if v)
        print(f"{label:36s} {n2:4d}/{nmax:<4d} {str(ok):>8s} {str(cert):>5s} {med:7.1f} {cpu:7.1f} {first:7.1f} "
              f"{ms:9.1f} {mcpu:9.1f} {mcpu / cpu:6.1f} {FKSGP_MS[key]:>9s}  {cls}")
    print("(hom: median per length set, wall and process CPU time, with the platform's stage one cached; stage1: its")
    print(" one-time wall cost (ms); ratio: multi-start CPU / homotopy CPU, measured in this run (CPU time because the")
    print(" machine may be shared: wall time then includes waiting); fkSGP: published, not measured here)")
    print("\n# Batched homotopy: many length sets of one platform in one call")
    for name, n, per, cpu, n_ok, timing in homotopy_batch(20 if args.quick else 100):
        tm = ", ".join(f"{k} {v:.2f} s" for k, v in timing.items())
        print(f"{name:22s} {n:4d} sets: {per:6.2f} ms wall, {cpu:6.2f} ms CPU per set, {n_ok}/{n} complete ({tm})")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="smaller batches")
    ap.add_argument("--homotopy", action="store_true", help="only the complete-FK (homotopy vs multi-start) section")
    ap.add_argument("--homotopy-only", action="store_true", help="only the homotopy timings, without the multi-start comparison")
    args = ap.parse_args(argv)
    n = 20_000 if args.quick else 100_000
    if args.homotopy or args.homotopy_only:
        print_homotopy(args)
        return 0

    print(f"\n# Newton FK, batch of {n} poses (best of 3)")
    print(f"{'platform':22s} {'solves/s':>10s} {'no check':>10s} {'tracking':>10s} {'1-call/s':>9s} {'iters':>6s} {'trk it':>6s} {'conv':>6s}")
    rows = newton_rates(n)
    for name, _, chk, raw, trk, one, it, it2, conv in rows:
        print(f"{name:22s} {chk:10.3g} {raw:10.3g} {trk:10.3g} {one:9.3g} {it:6.2f} {it2:6.2f} {conv:6.3f}")
    r0 = rows[0]
    print(f"ratio batch/single-call (utn-dynamic): {r0[2] / r0[5]:.0f}x; singularity check costs {100 * (1 - r0[2] / r0[3]):.0f}% of the rate")

    print("\n# MathematicalProgram FK, one solve from a guess 2 cm / 0.1 rad off (gonzalez-dutra-2009)")
    prog_rows = program_times(20 if args.quick else 100)
    for rot, solver, med, wall in prog_rows:
        print(f"{rot:16s} {solver:6s} solver {med:7.3f} ms   wall {wall:7.3f} ms")
    snopt_ms = prog_rows[0][3]
    print(f"ratio SNOPT solve / Newton batch solve (gonzalez-dutra): {snopt_ms * 1e-3 * rows[1][2]:.0f}x")

    print("\n# All assembly modes (Newton multi-start; 'full' adds the SNOPT confirmation)")
    print(f"{'geometry':28s} {'modes':>5s} {'max':>4s} {'complete':>8s} {'certified':>9s} {'newton s':>9s} {'full s':>7s} {'starts':>7s}")
    for label, k, kmax, comp, cert, tf, tfull, starts in assembly_times():
        print(f"{label:28s} {k:5d} {kmax:4d} {str(comp):>8s} {cert:9d} {tf:9.3f} {tfull:7.3f} {starts:7d}")
    print_homotopy(args)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
