"""The linear leg loop (``sd.loop_response``) against the nonlinear Drake loop at 10 frequencies, on two presets
and the 210 kg machine, with the float law and the fixed-point firmware at a fine format: the finest set-point
LSB whose 16-bit word still holds the stroke's end, and a 1 µm sensor; plant step 0.25 ms.

    python benchmarks/bench_loop_response.py [--quick]

Prints, per machine and law, the margins and each frequency's measured and linear response (magnitude, phase),
their difference and its tolerance (``drake.loop_response``); exits 1 if any point disagrees.
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np

import stewart_drake as sd

MACHINES = ("utn-dynamic", "utn-kinematic", "examples/newcomer-210kg.yaml")
FREQUENCIES = (1.0, 2.0, 3.0, 5.0, 8.0, 12.0, 20.0, 30.0, 50.0, 80.0)
RESOLUTION = 1e-6


def fine_lsb(machine) -> float:
    """The smallest whole number of sensor counts per LSB whose 16-bit word holds the stroke's end."""
    L_max = float(machine.loaded_platform.stroke[1])
    return math.ceil(L_max / 32767 / RESOLUTION) * RESOLUTION


def main() -> int:
    freqs = FREQUENCIES[::3] if "--quick" in sys.argv else FREQUENCIES
    bad = 0
    for name in MACHINES:
        m = sd.load_machine(name)
        for law in ("float", "fixed"):
            over = {"controller.law": law, "sensors.resolution": RESOLUTION, "run.plant_step": 2.5e-4}
            if law == "fixed":
                over["firmware.length_lsb"] = fine_lsb(m)
            t0 = time.perf_counter()
            r = sd.loop_response(m, measure=list(freqs), **over)
            gm = min(d["gain_margin_db"] for d in r.margins)
            pm = min(d["phase_margin_deg"] for d in r.margins)
            lsb = f", LSB {over['firmware.length_lsb'] * 1e6:g} µm" if law == "fixed" else ""
            print(
                f"{name} {law}{lsb}: GM {gm:.2f} dB, PM {pm:.1f}°, bandwidth {r.bandwidth_hz:.3g} Hz, "
                f"sensitivity peak {r.sensitivity_peak:.3g}, {time.perf_counter() - t0:.0f} s"
            )
            for p in r.measured:
                h, g = p.response[p.leg], p.linear[p.leg]
                d, tol = abs(h - g), p.tolerance[p.leg]
                bad += d > tol
                print(
                    f"  {p.freq:5g} Hz A {p.amplitude * 1e6:7.1f} µm  measured {abs(h):.4f} ∠{np.degrees(np.angle(h)):7.2f}°"
                    f"  linear {abs(g):.4f} ∠{np.degrees(np.angle(g)):7.2f}°  |Δ| {d:.4f} ≤ {tol:.4f} "
                    + ("ok" if d <= tol else "DISAGREES")
                )
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
