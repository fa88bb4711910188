"""``control.tuning``: the grid over a box, and a gain set evaluated on the stored plants is the loop built
afresh with those gains."""

from dataclasses import replace

import numpy as np
import pytest

from stewart_drake.control.frequency import LoopModel, margins
from stewart_drake.control.gains import ControllerConfig
from stewart_drake.control.tuning import GridLoops, LoopSpec, grid_poses, replace_gains
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths


def test_grid_is_centre_faces_corners_in_stroke():
    p = load_preset("utn-dynamic")
    home = p.home_pose()
    d = np.r_[[0.01] * 3, [0.02] * 3]  # small enough that every pose keeps its legs in the stroke
    g = grid_poses(p, home - d, home + d)
    assert len(g) == 1 + 12 + 64 and np.array_equal(g[0], home)
    assert len(np.unique(g, axis=0)) == len(g)
    # a box flat in the angles: 1 centre + 6 faces (3 of them repeat the centre) + 8 corners, each once
    flat = grid_poses(p, home - np.r_[d[:3], 0, 0, 0], home + np.r_[d[:3], 0, 0, 0])
    assert len(flat) == 1 + 6 + 8
    # a box reaching past the stroke loses the poses whose legs leave it, and keeps the others
    big = grid_poses(p, home - 20 * d, home + 20 * d)
    L = leg_lengths(p, big)
    assert 0 < len(big) < 77 and np.all((L >= p.L_min) & (L <= p.L_max))


@pytest.mark.parametrize("scale", [0.5, 2.0])
def test_evaluation_on_stored_plants_is_the_loop_built_afresh(scale):
    p = load_preset("utn-dynamic")
    cfg = ControllerConfig.for_platform(p)
    t = cfg.timing
    spec = LoopSpec(t.sample_period, t.output_delay, 2e-3, 1e-3, None)
    pose = p.home_pose() + np.r_[0.01, 0, 0, 0, 0.03, 0]
    loops = GridLoops(p, pose[None], spec, cfg.gains)
    g = replace(cfg.gains, kp=cfg.gains.kp * scale, kd=cfg.gains.kd * scale, kv=cfg.gains.kv * scale)
    fresh = LoopModel.build(p, pose, g, t.sample_period, t.output_delay, 2e-3, 1e-3, None)
    swapped = replace_gains(loops.models[0], g, spec)
    np.testing.assert_allclose(swapped.A, fresh.A, rtol=0, atol=1e-9 * np.abs(fresh.A).max())
    ev = loops.evaluate(g)
    assert ev.spectral_radius == pytest.approx(fresh.spectral_radius, rel=1e-9)
    L, _ = fresh.loops(loops.freqs)
    gm = min(margins(loops.freqs, L[:, i])["gain_margin_db"] for i in range(6))
    pm = min(margins(loops.freqs, L[:, i])["phase_margin_deg"] for i in range(6))
    # the same frequencies, the same formulas on independently built responses: equal to rounding
    assert ev.gain_margin_db == pytest.approx(gm, abs=1e-9) and ev.phase_margin_deg == pytest.approx(pm, abs=1e-9)
