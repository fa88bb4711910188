"""The scores against what they must give on constructed cases: a perfect cue, a delayed cue, a reversed cue,
and the stroke use read from the exact leg lengths."""

import numpy as np
import pytest

from stewart_drake.control.cueing.classical import ClassicalParams, classical
from stewart_drake.control.cueing.drive import GRAVITY, Drive
from stewart_drake.control.cueing.generators import car_drive
from stewart_drake.control.cueing.platform_motion import platform_drive
from stewart_drake.control.cueing.scores import CHANNELS, score
from stewart_drake.control.cueing.vestibular import FORCE_THRESHOLD, perceive
from stewart_drake.core.geometry import load_platform
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.errors import CueingError


@pytest.fixture(scope="module")
def setting():
    platform = load_platform("gonzalez-dutra-2009")
    home = platform.home_pose()
    d = car_drive("slalom")
    q = classical(d, ClassicalParams(), home)
    return platform, home, d, q


def test_a_drive_scored_against_itself_is_perfect(setting):
    platform, home, d, q = setting
    s = score(d, d, q, platform)
    for c in CHANNELS:
        assert s["channels"][c]["rmse"] == 0.0
        assert s["channels"][c]["delay_s"] == 0.0
        assert s["channels"][c]["false_cue_share"] == 0.0
    assert s["channels"]["fy"]["pearson"] == pytest.approx(1.0, abs=1e-12)


def test_a_delayed_cue_shows_its_delay_and_a_reversed_one_its_false_cues(setting):
    platform, home, d, q = setting
    shift = 23  # samples, 0.23 s
    f = np.roll(d.specific_force, shift, axis=0)
    f[:shift] = d.specific_force[0]
    late = Drive("late", d.t, f, np.roll(d.angular_velocity, shift, axis=0))
    assert score(d, late, q, platform)["channels"]["fy"]["delay_s"] == pytest.approx(shift * d.dt, abs=1e-12)
    reversed_ = Drive("rev", d.t, 2 * np.array([0, 0, GRAVITY]) - d.specific_force, -d.angular_velocity)
    s = score(d, reversed_, q, platform)
    assert s["channels"]["fy"]["pearson"] == pytest.approx(-1.0, abs=1e-9)
    pv = perceive(d).specific_force[:, 1]
    assert s["channels"]["fy"]["false_cue_share"] == pytest.approx(np.mean(np.abs(pv) > FORCE_THRESHOLD[1]))


def test_a_still_channel_correlates_with_nothing(setting):
    # the slalom has no pitch rate and a still platform no motion: their perceived series are constant up to the
    # filters' rounding, which must not read as a correlation or a delay
    platform, home, d, q = setting
    still = np.tile(home, (len(d), 1))
    s = score(d, platform_drive(still, d.t, home), still, platform)
    for c in CHANNELS:
        assert s["channels"][c]["pearson"] == 0.0 and s["channels"][c]["delay_s"] == 0.0


def test_workspace_figures_come_from_the_exact_leg_lengths(setting):
    platform, home, d, q = setting
    s = score(d, platform_drive(q, d.t, home), q, platform)
    L = leg_lengths(platform, q)
    used = (L.max(axis=0) - L.min(axis=0)).max() / (platform.L_max - platform.L_min)
    assert s["stroke_use_pct"] == pytest.approx(100 * used)
    assert s["leg_speed_max"] == pytest.approx(
        np.abs(np.diff(L, axis=0)).max() / d.dt, rel=0.05
    )  # central vs one-sided


def test_drives_of_other_times_are_refused(setting):
    platform, home, d, q = setting
    other = car_drive("slalom", rate=50.0)
    with pytest.raises(CueingError, match="must share t"):
        score(d, other, q, platform)
