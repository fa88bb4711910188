"""The viewer's certified uniqueness radius (``drake.viewer.uniqueness_radius``)."""

import numpy as np

from stewart_drake.core.assembly_modes import assembly_modes
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import anchor_radius
from stewart_drake.core.rotations import rotation_matrix
from stewart_drake.drake.viewer import labels, readout


def test_no_mode_found_lies_within_the_certified_radius():
    """At a tilted pose of utn-dynamic, every other assembly mode the viewer's search finds lies farther
    than the certified radius (sqrt(|Δp|² + (a θ)²)), and the page shows the radius."""
    p = load_preset("utn-dynamic")
    pose = p.home_pose() + [0.02, -0.01, 0.01, 0.1, -0.05, 0.2]
    r = readout(p, pose)
    modes = assembly_modes(p, r.lengths, n_starts=256, max_rounds=2, patience=1, polish=None).poses()
    R0 = rotation_matrix(pose[3:])
    R = rotation_matrix(modes[:, 3:])
    theta = np.arccos(np.clip((np.einsum("kij,ij->k", R, R0) - 1) / 2, -1, 1))
    d = np.sqrt(np.sum((modes[:, :3] - pose[:3]) ** 2, axis=1) + (anchor_radius(p) * theta) ** 2)
    others = d[d > 1e-9]
    assert len(others) >= 2 and r.uniqueness_radius > 0 and np.all(others > r.uniqueness_radius)
    shown = " ".join(line.strip() for line in labels(r))  # the panel wraps long lines at words
    assert f"no other assembly mode within {r.uniqueness_radius * 1e3:.1f} mm (certified)" in shown
