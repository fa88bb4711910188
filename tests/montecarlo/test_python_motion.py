"""``sd.montecarlo`` takes a Python ``Trajectory`` wherever it takes a motion: run in this process or pickled to
Dask workers with the study, and recorded in the study's key by its poses."""

from __future__ import annotations

import numpy as np
import pytest

import stewart_drake as sd
from stewart_drake.cli import main
from stewart_drake.errors import StudyError

# two short runs (50 ticks) with drawn anchors: cheap, and runs that differ from each other
STUDY = dict(runs=2, vary="anchor=±0.5mm", duration=0.05, engine="python")


def _rows(result) -> list[dict]:
    return [{k: v for k, v in r.items() if k != "wall_s"} for r in result.rows]


def lifted(dz: float) -> sd.Trajectory:
    """The seed motion moved up by ``dz`` m, built in the user's code (a closure: pickled by value)."""
    seed = sd.Trajectory.seed()
    q0, q1, q2 = (np.zeros(6) for _ in range(3))
    q0[2] = dz

    def exact(t):
        q, qd, qdd = seed.derivatives(t)
        return q + q0, qd + q1, qdd + q2

    return sd.Trajectory("lifted", lambda t: seed.pose(t) + q0, seed.duration, exact)


@pytest.fixture(scope="module")
def platform():
    return sd.load_platform("utn-dynamic")


def test_a_trajectory_object_is_the_motion_the_runs_follow(platform, tmp_path):
    by_name = sd.montecarlo(platform, "seed", out=tmp_path / "a", workers=0, **STUDY)
    by_object = sd.montecarlo(platform, sd.Trajectory.seed(), out=tmp_path / "b", workers=0, **STUDY)
    assert _rows(by_object) == _rows(by_name)  # the same motion: the same runs, bit for bit
    other = sd.montecarlo(platform, lifted(2e-3), out=tmp_path / "c", workers=0, **STUDY)
    assert _rows(other) != _rows(by_name)  # another motion: other runs (the object is followed, not its name)
    assert other.summary["settings"]["motion"]["name"] == "lifted"
    assert by_object.summary["key"] != other.summary["key"]  # the key follows the poses


def test_a_users_trajectory_reaches_the_dask_workers(platform, tmp_path):
    here = sd.montecarlo(platform, lifted(2e-3), out=tmp_path / "w0", workers=0, **STUDY)
    dask = sd.montecarlo(platform, lifted(2e-3), out=tmp_path / "w1", workers=1, **STUDY)
    assert _rows(dask) == _rows(here)


def test_a_python_motion_study_is_not_replayed_from_its_hash(platform, tmp_path, capsys):
    sd.montecarlo(platform, lifted(2e-3), out=tmp_path / "mc", workers=0, **STUDY)
    assert main(["montecarlo", "--replay", "0", "--out", str(tmp_path / "mc"), "--no-animation"]) == 2
    err = capsys.readouterr().err
    assert StudyError.MOTION_NOT_STORED.format(name="lifted") in err and err.count("\n") == 1
