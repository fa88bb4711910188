"""A CSV reference starts a run like the closed-form one it samples."""

from __future__ import annotations

import numpy as np

from stewart_drake.core.geometry import load_platform
from stewart_drake.core.trajectory import SEED, load_trajectory_csv
from stewart_drake.drake.simulation import Scenario, simulate


def test_sampled_seed_tracks_like_the_closed_form(tmp_path):
    """The seed trajectory sampled every 10 ms: the piecewise-linear reference is within a·Δt²/8 ≈ 5 µm of
    the sine (a = 0.4 m/s²), so the float twin's legs follow both within 0.1 mm (the loop's response to
    the 10 ms kinks). The run starts at the first segment's velocity: a pose held before t = 0 would read
    as an acceleration of v/h at the start and throw the plate (≈ 200 mm leg errors)."""
    t = np.arange(0.0, 1.0 + 1e-9, 0.01)
    path = tmp_path / "seed.csv"
    np.savetxt(path, np.column_stack([t, SEED.pose(t)]), delimiter=",", header="t,px,py,pz,ax,ay,az", comments="")
    csv_ref = load_trajectory_csv(path)
    before = csv_ref.pose(np.array([-0.01]))[0]
    assert np.allclose(before, 2 * SEED.pose(0.0) - SEED.pose(0.01))  # continued along the first segment
    p = load_platform("utn-dynamic")
    a = simulate(Scenario(p, csv_ref, "float", duration=0.3))
    b = simulate(Scenario(p, SEED, "float", duration=0.3))
    assert np.abs(a.lengths - b.lengths).max() < 1e-4
