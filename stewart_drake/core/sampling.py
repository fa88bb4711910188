"""Seeded random poses around a platform's home pose (for tests, analyses and benchmarks)."""

from __future__ import annotations

import numpy as np

from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import check_stroke, leg_lengths


def random_poses(platform: Platform, n: int, seed: int = 0, translation: float | None = None,
                 rotation: float = np.radians(15), within_stroke: bool = True) -> np.ndarray:
    """``(n, 6)`` poses: home + uniform offsets, ±``translation`` metres (default 10 % of the stroke
    range) and ±``rotation`` radians; with ``within_stroke`` only poses with every leg in stroke."""
    rng = np.random.default_rng(seed)
    if translation is None:
        translation = 0.1 * (platform.L_max - platform.L_min)
    out = np.empty((0, 6))
    while len(out) < n:
        q = platform.home_pose() + np.c_[rng.uniform(-translation, translation, (2 * n, 3)), rng.uniform(-rotation, rotation, (2 * n, 3))]
        if within_stroke:
            q = q[check_stroke(platform, leg_lengths(platform, q)).within]
        out = np.vstack([out, q])
    return out[:n]
