"""The workspace guard: over every shipped drive, on the presets and the 210 kg machine's platform, no guarded
sample is outside the stroke or over the leg speed and acceleration limits (re-checked with the exact IK); the
guard scales the whole excursion (never a leg alone), without steps, and leaves a motion inside untouched."""

import numpy as np
import pytest
from scipy.optimize import brentq

from stewart_drake.control.cueing.classical import HAND_SET, classical
from stewart_drake.control.cueing.generators import DRIVES
from stewart_drake.control.cueing.guard import WorkspaceGuard
from stewart_drake.core.geometry import load_platform
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.errors import CueingError
from stewart_drake.workspace.limits import Limits, limit_margins
from tests._own_platform import NEWCOMER_PLATFORM


@pytest.fixture(scope="module")
def platforms(tmp_path_factory):
    path = tmp_path_factory.mktemp("own") / "newcomer.yaml"
    path.write_text(NEWCOMER_PLATFORM)
    return {name: load_platform(name) for name in ("utn-kinematic", "utn-dynamic", "gonzalez-dutra-2009")} | {
        "newcomer-210kg": load_platform(str(path))
    }


@pytest.fixture(scope="module")
def drives():
    return {name: make() for name, make in DRIVES.items()}


def _hard_check(guard, q, t):
    # against the platform's own stroke and speed limit (the guard keeps margins inside them)
    p = guard.platform
    return guard.check(q, t, stroke=p.stroke, max_speed=guard.max_speed / 0.9, max_accel=guard.max_accel / 0.9)


@pytest.mark.parametrize("name", ["utn-kinematic", "utn-dynamic", "gonzalez-dutra-2009", "newcomer-210kg"])
def test_no_guarded_sample_leaves_the_workspace_over_every_shipped_drive(platforms, drives, name):
    guard = WorkspaceGuard.for_platform(platforms[name])
    tried = 0
    for d in drives.values():
        q = classical(d, HAND_SET, guard.home)
        raw = guard.check(q, d.t)
        tried += not raw.ok
        g = guard.guard(q, d.t)
        assert guard.check(g, d.t).ok, d.name  # the guard's own limits, with their margins
        assert _hard_check(guard, g, d.t).ok, d.name
    assert tried >= 3  # the hand set leaves the workspace on several drives: the guard had work to do


def test_guard_scales_the_whole_excursion_smoothly(platforms, drives):
    guard = WorkspaceGuard.for_platform(platforms["gonzalez-dutra-2009"])
    d = drives["ship-ss6"]
    q = classical(d, HAND_SET, guard.home)
    g = guard.guard(q, d.t)
    e, eg = q - guard.home, g - guard.home
    c = np.sum(e * eg, axis=1) / np.maximum(np.sum(e * e, axis=1), 1e-300)
    np.testing.assert_allclose(eg, c[:, None] * e, atol=1e-12)  # one scale for all six coordinates
    assert c.min() < 0.9 and c.max() <= 1.0
    moving = np.sum(e * e, axis=1) > 1e-10  # where the excursion is ~0 the scale is not observable
    steps = np.abs(np.diff(c))[moving[1:] & moving[:-1]]
    assert steps.max() <= guard.scale_rate * d.dt * (1 + 1e-9)


def test_joint_cones_are_kept_where_limits_give_them(platforms, drives):
    # 38° cones about the base and plate normals (the legs lean 30.7° at home): the hand set's ship-ss6 poses cross
    # them; guarded, no sample does
    # (limit_margins, the workspace module's own check, reads the joint angles independently of the guard)
    platform = platforms["gonzalez-dutra-2009"]
    limits = Limits(stroke=False, base_cone=np.radians(38), top_cone=np.radians(38))
    guard = WorkspaceGuard.for_platform(platform, limits=limits)
    d = drives["ship-ss6"]
    q = classical(d, HAND_SET, guard.home)
    worst = lambda poses: min(m.min() for m, _ in limit_margins(platform, poses, limits).values())  # noqa: E731
    assert worst(q) < 0
    g = guard.guard(q, d.t)
    assert worst(g) >= 0
    assert _hard_check(guard, g, d.t).ok


def test_small_motion_is_left_as_it_is(platforms):
    guard = WorkspaceGuard.for_platform(platforms["utn-dynamic"])
    t = np.arange(0, 5, 0.01)
    q = np.tile(guard.home, (len(t), 1))
    q[:, 0] += 0.002 * np.sin(t)
    np.testing.assert_array_equal(guard.guard(q, t), q)


def test_admissible_scale_is_the_stroke_boundary(platforms):
    # independently: the scale where the first leg reaches a stroke end, by Brent's method on the exact IK
    guard = WorkspaceGuard.for_platform(platforms["newcomer-210kg"])
    rng = np.random.default_rng(5)
    e = rng.normal(size=(20, 6)) * [0.3, 0.3, 0.3, 0.4, 0.4, 0.4]
    s = guard.admissible_scale(e)
    lo, hi = guard.stroke

    def excess(x, k):
        L = leg_lengths(guard.platform, guard.home + x * e[k])
        return max(np.max(L - hi), np.max(lo - L))

    for k in range(len(e)):
        if s[k] < 1:
            assert s[k] == pytest.approx(brentq(excess, 0, 1, args=(k,)), abs=1e-8)


def test_bad_guard_settings_are_named(platforms):
    with pytest.raises(CueingError, match=r"margin must be in \[0, 0.5\), got 0.7"):
        WorkspaceGuard.for_platform(platforms["utn-dynamic"], margin=0.7)
    with pytest.raises(CueingError, match="max_speed must be a positive number, got 0"):
        WorkspaceGuard.for_platform(platforms["utn-dynamic"], max_speed=0)
