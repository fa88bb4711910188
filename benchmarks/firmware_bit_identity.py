"""Bit-identity at scale (run by hand; minutes): the compiled tp17.C vs the Python port on 10^6 firmware
poses; the generated sd_ik of every preset, built with gcc and with zig cc, vs the emulation on 10^6
workspace poses and 10^6 uniformly random words (the saturating paths); and full closed-loop runs (seed
and rotating trajectories on each preset, the trajectory's whole duration) with the C engine vs the
Python engine, every logged array compared exactly.

    .venv/bin/python benchmarks/firmware_bit_identity.py [--poses 1000000]

The tests run the same comparisons on smaller samples.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import time

os.environ.setdefault("MPLBACKEND", "Agg")

import numpy as np  # noqa: E402

from stewart_drake.control import ControllerConfig  # noqa: E402
from stewart_drake.core.geometry import PRESETS, load_preset  # noqa: E402
from stewart_drake.core.trajectory import fit_trajectory, get_trajectory  # noqa: E402
from stewart_drake.drake.simulation import Scenario, build_simulation  # noqa: E402
from stewart_drake.firmware.check import workspace_poses  # noqa: E402
from stewart_drake.firmware.generate import generate  # noqa: E402
from stewart_drake.firmware.host import tp17_leg_lengths_c  # noqa: E402
from stewart_drake.firmware.module import compile_generated  # noqa: E402
from stewart_drake.fixedpoint import tp17_leg_lengths  # noqa: E402
from stewart_drake.fixedpoint.generic import leg_length_words, pose_words  # noqa: E402
from stewart_drake.system.c_build import compiler_by_name  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--poses", type=int, default=1_000_000)
    n = ap.parse_args(argv).poses
    rng = np.random.default_rng(2026)
    ang = np.where(rng.random((n, 1)) < 0.9, rng.uniform(-0.3, 0.3, (n, 3)), rng.uniform(-1, 1, (n, 3)))
    q = np.c_[rng.uniform(-300, 300, (n, 2)), rng.uniform(0, 600, n), ang]
    t = time.perf_counter()
    bad = int(np.any(tp17_leg_lengths_c(q) != tp17_leg_lengths(q), axis=1).sum())
    print(f"tp17.C compiled vs the Python port, {n} poses: {bad} differ ({time.perf_counter() - t:.0f} s)", flush=True)
    ok = bad == 0
    for name in PRESETS:
        p = load_preset(name)
        cfg = ControllerConfig.for_platform(p)
        g = generate(p, cfg)
        f = cfg.ik_format.frac_bits
        sets = {
            "workspace poses": pose_words(workspace_poses(p, n, seed=7), cfg.ik_format),
            "random words": rng.integers(-(1 << f), 1 << f, (n, 6)),
        }
        want = {k: leg_length_words(p, w, cfg.ik_format, cfg.convention) for k, w in sets.items()}
        for cc in ("gcc", "zig"):
            m = compile_generated(g, compiler=compiler_by_name(cc))
            for k, w in sets.items():
                bad = int(np.any(m.ik(w)[0] != want[k], axis=1).sum())
                ok &= bad == 0
                print(f"{name}: generated sd_ik ({cc}) vs emulation, {n} {k}: {bad} differ", flush=True)
    for name in PRESETS:
        p = load_preset(name)
        for tr in ("seed", "rotating"):
            traj = get_trajectory(tr)
            if name != "utn-dynamic":
                traj = fit_trajectory(traj, p)
            d = traj.duration or 4.0
            logs = {e: build_simulation(Scenario(p, traj, "fixed", engine=e)).run(d) for e in ("python", "c")}
            arrays = [
                f.name for f in dataclasses.fields(logs["c"]) if isinstance(getattr(logs["c"], f.name), np.ndarray)
            ]
            same = all(np.array_equal(getattr(logs["python"], a), getattr(logs["c"], a)) for a in arrays)
            ok &= same
            print(
                f"closed loop {name}, {tr}, {d:g} s ({len(logs['c'].tick_times())} ticks): C vs Python logs bit-identical: {same}",
                flush=True,
            )
    return 0 if ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
