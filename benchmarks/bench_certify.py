"""The firmware certificate: its cost on each preset's workspace box, and its bound against the worst
error of many random + adversarial poses through the bit-exact emulation.

1. ``firmware certify`` (default budget, 200,000 cells) on each preset's workspace box at the default
   format (16-bit words, 1 mm LSB, tfr16): wall and CPU seconds (one core: BLAS threads pinned to 1), the
   peak resident memory, the verdict and the proven bound per leg.
2. With ``--poses N`` (the issue's figure: 10^7), N uniform pose words of the box plus its 64 corners,
   then ``--adversarial`` rounds of a local search around the worst poses (6 x 1024 perturbations each),
   through the emulation; per leg the worst |L_firmware - L_float|, the proven bound, their ratio (the
   done-when: 1 <= bound / worst <= 2), and whether every sampled word lies in its proven range.

Run by hand:  .venv/bin/python benchmarks/bench_certify.py [--poses 10000000] [--adversarial 200]
(10^7 poses take about 7 minutes per preset on one idle core.)
"""

from __future__ import annotations

import argparse
import os
import resource
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from stewart_drake.core.geometry import PRESETS, load_preset  # noqa: E402
from stewart_drake.firmware.certify.box import workspace_box  # noqa: E402
from stewart_drake.firmware.certify.certificate import certify  # noqa: E402
from stewart_drake.firmware.certify.recipe import Model, word_names  # noqa: E402
from stewart_drake.firmware.certify.sampling import sample_box  # noqa: E402
from stewart_drake.fixedpoint.generic import QFormat  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--poses", type=int, default=0, help="random poses per preset for the comparison (0: skip)")
    ap.add_argument("--adversarial", type=int, default=200, help="local-search rounds after the random poses")
    ap.add_argument("--lsb", type=float, default=1e-3, help="length LSB (m), default 1e-3")
    ap.add_argument("--preset", action="append", choices=PRESETS, help="only these presets (default: all)")
    a = ap.parse_args()
    fmt = QFormat(16, a.lsb, "tfr16")
    for name in a.preset or PRESETS:
        p = load_preset(name)
        box = workspace_box(p)
        t0, c0 = time.perf_counter(), time.process_time()
        cert = certify(p, fmt, box)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
        bound = np.array([np.nan if e is None else e for e in cert.error_bound_mm])
        print(
            f"{name}: certify {wall:.1f} s wall, {cpu:.1f} s CPU, peak RSS {rss:.0f} MB, {cert.cells} cells, "
            f"saturation {'POSSIBLE' if cert.saturation_possible else 'impossible'}, bound/leg {np.round(bound, 4)} mm"
        )
        if a.poses:
            model = Model.build(p, fmt)
            t0 = time.perf_counter()
            s = sample_box(model, *box.words(fmt), a.poses, seed=0, adversarial=a.adversarial)
            worst = s.worst_err * fmt.length_lsb * 1e3
            proven = {w.name: w for w in cert.words}
            inside = all(
                proven[n].min <= s.word_min[k] and s.word_max[k] <= proven[n].max for k, n in enumerate(word_names())
            )
            print(
                f"  {a.poses} random + {a.adversarial * 6144} adversarial poses ({time.perf_counter() - t0:.0f} s): "
                f"worst/leg {np.round(worst, 4)} mm; bound/worst {np.round(bound / worst, 3)} "
                f"(max bound / max worst {bound.max() / worst.max():.3f}); every sampled word in its range: {inside}"
            )


if __name__ == "__main__":
    main()
