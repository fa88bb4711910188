"""A study's plots leave the caller's matplotlib backend alone: ``sd.montecarlo`` called in a notebook must not
switch its inline backend to Agg (the figures drawn after it would silently vanish)."""

from __future__ import annotations

import matplotlib
import numpy as np

from stewart_drake.montecarlo.summary import write_plots


def test_write_plots_keeps_the_backend(tmp_path):
    before = matplotlib.get_backend()
    matplotlib.use("svg")  # any backend other than the Agg that the plots are saved with
    try:
        rng = np.random.default_rng(0)
        rows = [
            {
                "gain_scale": float(g),
                "max_leg_error_m": float(1e-3 * g),
                "max_position_error_m": float(2e-3 * g),
                "max_angle_error_rad": float(1e-2 * g),
            }
            for g in rng.uniform(0.8, 1.2, 8)
        ]
        summary = {"sensitivity": {"max_leg_error_m": [{"parameter": "gain_scale", "spearman": 1.0}]}}
        paths = write_plots(rows, summary, tmp_path)
        assert matplotlib.get_backend() == "svg"
        assert [p.name for p in paths] == ["distributions.png", "sensitivity.png"]
        assert all(p.read_bytes().startswith(b"\x89PNG") for p in paths)
    finally:
        matplotlib.use(before)
