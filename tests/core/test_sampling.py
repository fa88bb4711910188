"""The seeded pose sampler (``core/sampling``) and its stroke test (``kinematics.stroke_within``)."""

import numpy as np
import pytest

from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import CHUNK, check_stroke, leg_lengths, plate_anchors, stroke_within
from stewart_drake.core.sampling import MAX_ROUNDS, random_poses


def _random_poses_whole_rounds(platform, n, seed=0, translation=None, rotation=None, within_stroke=True, region="box"):
    """The sampler as it was: every pose of a round tested at once with ``check_stroke``, then the first ``n``."""
    rng = np.random.default_rng(seed)
    span = platform.L_max - platform.L_min
    home = platform.home_pose()
    out, have = [], 0
    for _ in range(MAX_ROUNDS):
        if region == "box":
            t = 0.1 * span if translation is None else translation
            r = np.radians(15) if rotation is None else rotation
            q = home + np.c_[rng.uniform(-t, t, (2 * n, 3)), rng.uniform(-r, r, (2 * n, 3))]
            ok = check_stroke(platform, leg_lengths(platform, q)).within if within_stroke else np.ones(len(q), bool)
        else:
            t = 0.3 * span if translation is None else translation
            r = np.radians(20.0) if rotation is None else rotation
            h = platform.home_height
            m = max(4 * (n - have), 64)
            q = np.empty((m, 6))
            q[:, :2] = rng.uniform(-t, t, (m, 2))
            q[:, 2] = rng.uniform(max(h - t, 0.5 * h), h + t, m)
            q[:, 3:] = rng.uniform(-r, r, (m, 3))
            ok = check_stroke(platform, leg_lengths(platform, q)).within
            ok &= np.all(plate_anchors(platform, q)[..., 2] > 0, axis=-1)
        out.append(q[ok])
        have += int(ok.sum())
        if have >= n:
            return np.concatenate(out)[:n]
    raise AssertionError("too few")


@pytest.mark.parametrize(
    "name, n, kw",
    [
        ("utn-kinematic", 0, {}),
        ("utn-kinematic", 7, {}),
        ("utn-kinematic", CHUNK + 5, dict(translation=0.1, rotation=np.radians(25))),  # the fixed-point study's
        ("utn-kinematic", 300, dict(within_stroke=False)),
        ("gonzalez-dutra-2009", 9000, dict(region="workspace")),  # 4n draws over three blocks, done in the first
        ("utn-kinematic", 3000, dict(translation=0.3)),  # most poses out of stroke: three rounds
        # rounds of two blocks, then of one, until the last accepted pose
        ("gonzalez-dutra-2009", 4500, dict(region="workspace", translation=0.5)),
        ("utn-dynamic", 3, dict(region="workspace", seed=4)),
    ],
)
def test_sampler_gives_the_poses_it_always_gave(name, n, kw):
    """Testing a round's draws block by block and stopping at the n-th accepted pose gives the very poses (bits)
    of testing the whole round: small and empty samples, a round over several ``leg_lengths`` blocks, the
    workspace region over more than one round."""
    p = load_preset(name)
    got = random_poses(p, n, **kw)
    want = _random_poses_whole_rounds(p, n, **kw)
    assert got.shape == (n, 6)
    np.testing.assert_array_equal(got, want)


def test_stroke_within_is_check_stroke_within():
    """The sampler's stroke test answers as ``check_stroke(...).within``: lengths at, just inside and just outside
    both ends of the stroke, far outside, infinite and NaN (no leg compares out: within, as there)."""
    p = load_preset("utn-kinematic")
    lo, hi = p.L_min, p.L_max
    values = np.array(
        [lo, hi, np.nextafter(lo, 0), np.nextafter(lo, 1), np.nextafter(hi, 0), np.nextafter(hi, 2), 0.0, 5.0]
        + [np.inf, -np.inf, np.nan, 0.5 * (lo + hi)]
    )
    rng = np.random.default_rng(0)
    L = values[rng.integers(0, len(values), (4000, 6))]
    L[:50] = 0.5 * (lo + hi)  # some sets wholly within
    L[50, 2] = np.nan  # a NaN among in-stroke legs
    want = check_stroke(p, L).within
    np.testing.assert_array_equal(stroke_within(p, L), want)
    assert want[:51].all() and not want.all()
    np.testing.assert_array_equal(stroke_within(p, L.reshape(2, 2000, 6)), want.reshape(2, 2000))
