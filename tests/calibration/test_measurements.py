"""Measurement files: a written file reads back equal; every bad file is one line naming file, line and
column (NaN, a unit mistaken, a reading outside the stroke, a missing column, the wrong kind)."""

from __future__ import annotations

import re

import numpy as np
import pytest

from stewart_drake.calibration.measurements import measurements_csv, read_measurements
from stewart_drake.calibration.model import NOISE_FLOOR
from stewart_drake.calibration.noise import parse_noise
from stewart_drake.calibration.plan import plan_measurements, stw_program
from stewart_drake.calibration.simulate import simulate_measurements
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.sampling import random_poses
from stewart_drake.errors import CalibrationError
from stewart_drake.script import compile_program
from tests.calibration.conftest import ERRORS, NOISE

P = load_preset("utn-dynamic")


@pytest.mark.parametrize("kind", ["pose", "points", "inclinometer"])
def test_written_measurements_read_back_equal(tmp_path, kind):
    data, _ = simulate_measurements(P, ERRORS, random_poses(P, 8, seed=1), kind, NOISE, seed=2)
    f = tmp_path / "m.csv"
    f.write_text(measurements_csv(data))
    back = read_measurements(f, P)  # the kind from the header
    assert back.kind == kind and np.array_equal(back.readings, data.readings)
    for a, b in ((back.poses, data.poses), (back.targets, data.targets), (back.tilts, data.tilts)):
        assert (a is None and b is None) or np.array_equal(a, b)
    assert back.lines.tolist() == list(range(2, 10)) and len(back.sha256) == 64


def _file(tmp_path, text):
    f = tmp_path / "m.csv"
    f.write_text(text)
    return f


HEAD = "l1,l2,l3,l4,l5,l6,px,py,pz,a,b,g\n"
ROW = "0.75,0.75,0.75,0.75,0.75,0.75,0,0,0.7,0,0,0\n"


@pytest.mark.parametrize(
    "text, kwargs, message",
    [
        (HEAD + ROW + ROW.replace("0.7,", "nan,"), {}, "m.csv:3: column pz: values must be finite, got 'nan'"),
        (
            HEAD + ROW.replace("0.75", "750"),
            {},
            "m.csv:2: leg 1 reads 750 m, so its length 750 m lies outside the stroke",
        ),
        (HEAD + ROW.replace("0.75", "750"), {}, "(are the readings in mm? give --length-unit mm)"),
        (HEAD + ROW, {"length_unit": "mm"}, "(are the readings in m? give --length-unit m)"),
        (HEAD + ROW.replace("0.75,0.75,0.75,0.75,0.75,0.75", "0.75,0.75,0.75,0.75,0.75,1.2"), {}, "leg 6 reads 1.2 m"),
        (
            HEAD + ROW.replace(",0,0,0\n", ",0,0,30\n"),
            {},
            "m.csv:2: column g: 30 rad is beyond ±3.14159 rad (are the angles in degrees?",
        ),
        (HEAD.replace(",g", "") + ROW[:-3] + "\n", {}, "missing g"),
        (HEAD.replace("px", "pX") + ROW, {}, "unknown column 'pX'"),
        (ROW + ROW, {}, "m.csv:1: a measurement file starts with a header row"),
        (
            HEAD + ROW,
            {"kind": "inclinometer"},
            "--type inclinometer given, but the header names the columns of a pose file",
        ),
        (
            HEAD.replace("\n", ",w\n") + ROW.replace("\n", ",0\n"),
            {},
            "m.csv:2: column w: a weight must be > 0, got '0'",
        ),
        (HEAD, {}, "m.csv: no measurement rows"),
        (HEAD + ROW + "0.75,0.75\n", {}, "m.csv:3: expected 12 values (one per header column), got 2"),
    ],
)
def test_bad_files_are_one_clear_line(tmp_path, text, kwargs, message):
    with pytest.raises(CalibrationError, match=re.escape(message)) as e:
        read_measurements(_file(tmp_path, text), P, **kwargs)
    assert "\n" not in str(e.value)


def test_noise_spec():
    n = parse_noise("length=2um position=0.01mm angle=0.05mrad")
    assert (n.length, n.position, n.angle) == (2e-6, 1e-5, 5e-5)
    for bad, msg in (("length=2", None), ("size=1um", "unknown key 'size'"), ("length=-1um", "expected a number >= 0"),
                     ("angle=1mm", "expected a number >= 0 with a unit (rad mrad urad µrad deg)")):  # fmt: skip
        if msg is None:
            assert parse_noise(bad).length == 2.0
            continue
        with pytest.raises(CalibrationError, match=re.escape(msg)):
            parse_noise(bad)
    # σ = 0 is noise-free synthetic data: accepted as stated; the fit weighs it at the floor
    assert parse_noise("position=0").position == 0.0 and parse_noise("position=0").floored().position == NOISE_FLOOR


def test_the_plan_program_visits_the_planned_poses():
    """plan.stw runs through the motion language and its waypoints are the planned poses, in order."""
    plan = plan_measurements(P, 6, "pose", noise=NOISE, seed=0, candidates=200)
    _, motion = compile_program(stw_program(plan.poses, P.name), "plan.stw", P)
    traj = motion.trajectory(50.0)
    ends = [traj.pose(t) for t in np.cumsum([s.duration for s in traj.segments]) - 1e-9]
    moves = [q for q, s in zip(ends, traj.segments) if s.kind == "move"]
    assert np.abs(np.array(moves) - plan.poses).max() < 1e-6
