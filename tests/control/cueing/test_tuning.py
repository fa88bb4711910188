"""Tuning: the tuned washout beats its start on the perceived error with no sample past a limit, the same seed
gives the same parameters, and parameters files round-trip and name the line of a bad value."""

import re

import pytest

from stewart_drake.control.cueing.classical import HAND_SET, ClassicalParams, classical
from stewart_drake.control.cueing.generators import car_drive
from stewart_drake.control.cueing.guard import WorkspaceGuard
from stewart_drake.control.cueing.tuning import load_params, save_params, tune_classical, tuning_cost
from stewart_drake.core.geometry import load_platform
from stewart_drake.errors import CueingError, YamlError


@pytest.fixture(scope="module")
def tuned():
    platform = load_platform("gonzalez-dutra-2009")
    guard = WorkspaceGuard.for_platform(platform)
    drives = [car_drive("lane-change", rate=25.0), car_drive("braking", rate=25.0)]
    return platform, guard, drives, tune_classical(drives, platform, guard, start=HAND_SET, budget=128, seed=1)


def test_tuned_beats_its_start_within_the_limits(tuned):
    platform, guard, drives, params = tuned
    assert tuning_cost(drives, guard, params) < 0.9 * tuning_cost(drives, guard, HAND_SET)
    for d in drives:
        q = guard.guard(classical(d, params, guard.home), d.t)
        assert guard.check(q, d.t, stroke=platform.stroke).ok
    assert params.tilt_rate == HAND_SET.tilt_rate  # not tuned: the perception threshold's rate


def test_same_seed_same_parameters(tuned):
    platform, guard, drives, params = tuned
    assert tune_classical(drives, platform, guard, start=HAND_SET, budget=128, seed=1) == params


def test_parameters_file_round_trip_and_errors(tmp_path, tuned):
    params = tuned[3]
    assert load_params(save_params(params, tmp_path / "tuned.yaml")) == params
    bad = tmp_path / "bad.yaml"
    bad.write_text("scale_xy: 0.5\nhp_xy: -2\n")
    with pytest.raises(CueingError, match=re.escape(f"{bad}:2: hp_xy: -2 must be a positive number")):
        load_params(bad)
    bad.write_text("scale_xy: 0.5\nhp_xx: 2\n")
    with pytest.raises(YamlError, match="hp_xx"):
        load_params(bad)
    assert load_params(tmp_path / "tuned.yaml") != ClassicalParams()
