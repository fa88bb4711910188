"""Seeded random poses around a platform's home pose (for tests, analyses and benchmarks).

One rejection sampler with two regions (each keeps its own draw order, so a seed gives the same poses
it always gave):

- ``"box"``: home + uniform offsets, ±``translation`` on x, y, z (default 10 % of the stroke range) and
  ±``rotation`` on each angle (default 15°); with ``within_stroke``, only poses with every leg in stroke.
- ``"workspace"``: x, y within ±``translation`` of home (default 30 % of the stroke range), z in
  [max(h − translation, h/2), h + translation] for the home height h, each angle within ±``rotation``
  (default 20°); kept only when every leg is within stroke and every plate anchor lies above the base
  plane (z > 0): the poses the forward-kinematics solvers must handle.
"""

from __future__ import annotations

import numpy as np

from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import CHUNK, leg_lengths, plate_anchors, stroke_within
from stewart_drake.errors import SamplingError

REGIONS = ("box", "workspace")
MAX_ROUNDS = 100  # draws before giving up: a region with (almost) no acceptable pose fails, not spins


def random_poses(
    platform: Platform,
    n: int,
    seed: int = 0,
    translation: float | None = None,
    rotation: float | None = None,
    within_stroke: bool = True,
    *,
    region: str = "box",
    convention: str = "utn",
) -> np.ndarray:
    """``(n, 6)`` seeded poses (m, rad, ``convention``) around home in ``region`` (see the module
    docstring; ``translation`` m and ``rotation`` rad default per region). ``within_stroke`` applies to
    "box" only ("workspace" always requires it). Raises ValueError when ``MAX_ROUNDS`` draws do not
    give ``n`` acceptable poses."""
    if region not in REGIONS:
        raise SamplingError(SamplingError.REGION.format(value=region, valid=", ".join(REGIONS)))
    rng = np.random.default_rng(seed)
    span = platform.L_max - platform.L_min
    home = platform.home_pose()
    out, have = [], 0
    for _ in range(MAX_ROUNDS):
        if region == "box":
            t = 0.1 * span if translation is None else translation
            r = np.radians(15) if rotation is None else rotation
            q = home + np.concatenate([rng.uniform(-t, t, (2 * n, 3)), rng.uniform(-r, r, (2 * n, 3))], axis=1)
        else:
            t = 0.3 * span if translation is None else translation
            r = np.radians(20.0) if rotation is None else rotation
            h = platform.home_height
            m = max(4 * (n - have), 64)
            q = np.empty((m, 6))
            q[:, :2] = rng.uniform(-t, t, (m, 2))
            q[:, 2] = rng.uniform(max(h - t, 0.5 * h), h + t, m)
            q[:, 3:] = rng.uniform(-r, r, (m, 3))
        # a round's draws are all made (the next round's depend on them); they are tested in the blocks
        # ``leg_lengths`` takes (the same numbers) until ``n`` are accepted, since the poses after the n-th
        # accepted one are dropped
        for s in range(0, max(len(q), 1), CHUNK):  # one empty block when n = 0: an empty sample, as always
            blk = q[s : s + CHUNK]
            if region == "box":
                ok = stroke_within(platform, leg_lengths(platform, blk, convention)) if within_stroke else None
            else:
                ok = stroke_within(platform, leg_lengths(platform, blk, convention))
                ok &= np.all(plate_anchors(platform, blk, convention)[..., 2] > 0, axis=-1)
            out.append(blk if ok is None else blk[ok])
            have += len(out[-1])
            if have >= n:
                return np.concatenate(out)[:n]
    raise SamplingError(SamplingError.TOO_FEW.format(name=platform.name, n=n, region=region))
