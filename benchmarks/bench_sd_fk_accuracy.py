"""``sd_fk``'s accuracy (the generated firmware's fixed-point FK) sampled over each preset's workspace: the figures
docs/realtime-kinematics.md quotes, and the measurement ``tests/firmware/test_sd_fk_accuracy.py`` repeats on a
smaller sample to check them.

The sample: ``random_poses(platform, n, seed, region="workspace")`` (uniform in the preset's workspace box, kept
where the IK is within stroke), the sensors' counts of their exact leg lengths, ``sd_fk`` of the default format
(16-bit words, 1 mm LSB) from the pose's words offset by ``-1, 0 or +1`` (``numpy.random.default_rng(seed)``) times
the start offset: ``tick`` (±3 length LSB, ±30 angle words: a tick of fast motion) or ``far`` (±30 LSB, ±100
words). Per preset and start: the worst and 99th-percentile position error |p_fk − p| (largest axis, mm) and
angle error (mrad), the share of estimates that explain the sensors as well as the IK can (``converged``: every
leg's residual within the largest IK error plus one LSB, as the test defines it) and the number that do not at a
Jacobian condition number (pose words) below 1000.

Run by hand:  .venv/bin/python benchmarks/bench_sd_fk_accuracy.py --n 100000 --seed 0
(10^5 poses per preset and start take about a minute on one core.)
"""

from __future__ import annotations

import argparse
import json
import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from stewart_drake.control.gains import ControllerConfig  # noqa: E402
from stewart_drake.core.geometry import PRESETS, Platform, load_preset  # noqa: E402
from stewart_drake.core.kinematics import leg_lengths  # noqa: E402
from stewart_drake.core.sampling import random_poses  # noqa: E402
from stewart_drake.firmware.fk_gen import pose_jacobian, word_scales  # noqa: E402
from stewart_drake.firmware.generate import generate  # noqa: E402
from stewart_drake.firmware.module import compile_generated  # noqa: E402
from stewart_drake.fixedpoint.generic import pose_words  # noqa: E402

STARTS = {"tick": np.r_[3, 3, 3, 30, 30, 30], "far": np.r_[30, 30, 30, 100, 100, 100]}
KAPPA = 1000.0


def run_fk(m, measured: np.ndarray, start: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(estimates (n, 6) words, saturation counts (n,))`` of ``sd_fk`` from ``start`` words."""
    out = np.empty_like(start)
    nsat = np.empty(len(start), dtype=np.int64)
    counts, word = m.ffi.new("sd_count[6]"), m.ffi.new("sd_word[6]")
    for k in range(len(start)):
        counts[0:6] = measured[k].tolist()
        word[0:6] = start[k].tolist()
        nsat[k] = m.lib.sd_fk(counts, word)
        out[k] = list(word)
    return out, nsat


def measure(platform: Platform, n: int, seed: int, start: str) -> dict:
    """The figures of one preset and start over ``n`` workspace poses drawn with ``seed`` (see the docstring)."""
    cfg = ControllerConfig.for_platform(platform)
    m = compile_generated(generate(platform, cfg))
    q = random_poses(platform, n, seed=seed, region="workspace")
    res, lsb, sc = cfg.timing.sensor_resolution, cfg.ik_format.length_lsb, word_scales(cfg)
    measured = np.round(leg_lengths(platform, q) / res).astype(np.int32)
    step = np.random.default_rng(seed).integers(-1, 2, (len(q), 6)) * STARTS[start]
    out, nsat = run_fk(m, measured, (pose_words(q, cfg.ik_format) + step).astype(np.int16))
    q_w = out * sc
    L_fx, _ = m.ik(out)
    r = np.abs(measured * res - L_fx * lsb)
    eps = np.abs(leg_lengths(platform, q_w) - L_fx * lsb)
    converged = r.max(axis=1) <= eps.max() + lsb
    s = np.linalg.svd(pose_jacobian(platform, q, "utn") * sc, compute_uv=False)
    kappa = s[:, 0] / s[:, -1]
    pos = np.abs(q_w - q)[:, :3].max(axis=1)
    ang = np.abs(q_w - q)[:, 3:].max(axis=1)
    return {
        "n": int(len(q)),
        "seed": seed,
        "start": start,
        "saturations": int(nsat.sum()),
        "pos_max_mm": float(pos.max() * 1e3),
        "pos_p99_mm": float(np.percentile(pos, 99) * 1e3),
        "ang_max_mrad": float(ang.max() * 1e3),
        "converged_share": float(converged.mean()),
        "not_converged_below_kappa": int((~converged & (kappa < KAPPA)).sum()),
        "kappa_max": float(kappa.max()),
        "pos_errors_mm": pos * 1e3,  # (n,) the position errors themselves (not printed)
    }


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=100_000, help="workspace poses per preset and start")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--presets", nargs="*", default=list(PRESETS))
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args()
    rows = []
    for name in a.presets:
        for start in STARTS:
            t0 = time.process_time()
            row = {"preset": name, **measure(load_preset(name), a.n, a.seed, start)}
            del row["pos_errors_mm"]
            row["cpu_s"] = round(time.process_time() - t0, 1)
            rows.append(row)
            if not a.json:
                print(
                    f"{name:>20} {start:>4} n={row['n']} seed={a.seed}: position max {row['pos_max_mm']:.2f} mm, "
                    f"p99 {row['pos_p99_mm']:.2f} mm; angle max {row['ang_max_mrad']:.2f} mrad; converged "
                    f"{100 * row['converged_share']:.3f} %, not converged at kappa < {KAPPA:g}: "
                    f"{row['not_converged_below_kappa']}; saturations {row['saturations']} ({row['cpu_s']} CPU s)",
                    flush=True,
                )
    if a.json:
        print(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
