"""The simulation's tracking verdict (``drake/simulation``): saturation counted by its longest stretch."""

import numpy as np
import pytest

from stewart_drake.core.geometry import load_platform


def test_saturation_verdict_counts_the_longest_stretch():
    """``longest_saturation`` from the cumulative per-leg counters: leg 2 saturated on ticks 3..62 (60
    ticks = 0.060 s at 1 ms) fails; leg 5 saturated on 40 ticks in two stretches of 20 passes."""
    from stewart_drake.control import STATUS
    from stewart_drake.control.simulation_log import (
        MAX_SATURATION_S,
        SimulationLog,
        longest_saturation,
        tracking_verdict,
    )

    n, T = 100, 1e-3
    sat = np.zeros((n, 6), bool)
    sat[2:62, 1] = True
    sat[10:30, 4] = sat[50:70, 4] = True
    status = np.zeros((n, len(STATUS)))
    status[:, 0] = np.arange(1, n + 1)
    status[:, 4:10] = np.cumsum(sat, axis=0)
    z = np.zeros((n, 6))
    log = SimulationLog("fixed", "p", "seed", T, np.arange(n) * T, z, z, z, z, z, status, np.arange(n) * T, z)
    assert longest_saturation(log) == pytest.approx([0, 0.060, 0, 0, 0.020, 0])
    v = tracking_verdict(load_platform("utn-dynamic"), z, z, log)
    assert v["failures"] == [
        f"leg 2 saturated for 0.060 s in one stretch (longer than {MAX_SATURATION_S:g} s): its actuator cannot follow the reference"
    ]
