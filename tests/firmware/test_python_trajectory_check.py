"""``firmware check`` of a module generated from a Python ``Trajectory``: the gains were designed over that
motion's poses, which no name looks up; ``generate`` writes them beside the C (``sd_design_poses.json``, tied to
the module by its hash in the fingerprint) and ``check`` designs the same gains from them."""

from __future__ import annotations

import json

import numpy as np
import pytest

import stewart_drake as sd
from stewart_drake.errors import FirmwareError, UsageError
from stewart_drake.firmware.fingerprint import DESIGN_POSES

CHECK = dict(poses=500, duration=0.05)  # 500 IK poses and 50 closed-loop ticks: a cheap comparison


def lifted(dz: float) -> sd.Trajectory:
    """The seed motion moved up by ``dz`` m (a user's motion: no name ``check`` could look up)."""
    seed = sd.Trajectory.seed()
    return sd.Trajectory("lifted", lambda t: seed.pose(t) + np.array([0, 0, dz, 0, 0, 0]), seed.duration)


@pytest.fixture(scope="module")
def platform():
    return sd.load_platform("utn-dynamic")


@pytest.fixture
def generated(platform, tmp_path):
    out = tmp_path / "fw"
    g = sd.firmware.generate(platform, out, trajectory=lifted(0.02), compile=False)
    return g, out / "sd_firmware.c"


def test_check_designs_the_gains_from_the_recorded_poses(platform, generated, tmp_path):
    g, source = generated
    # the motion's gains are not the home pose's: a check that designed over home would compare other gains
    home = sd.firmware.generate(platform, tmp_path / "home", compile=False)
    assert g.summary["gains"] != home.summary["gains"]
    assert (source.parent / DESIGN_POSES).is_file()
    r = sd.firmware.check(source, **CHECK)
    assert r.identical and r.tick is not None and r.tick["ticks"] > 0


def test_the_same_trajectory_given_replaces_the_file(generated):
    _, source = generated
    (source.parent / DESIGN_POSES).unlink()
    assert sd.firmware.check(source, trajectory=lifted(0.02), **CHECK).identical


def test_another_trajectory_given_is_refused(generated):
    _, source = generated
    with pytest.raises(
        UsageError, match=r"trajectory='lifted' here, other design poses than 'lifted' in .*sd_firmware\.[ch]"
    ):
        sd.firmware.check(source, trajectory=lifted(0.03), **CHECK)


def test_a_missing_or_edited_poses_file_is_one_line_naming_it(generated):
    _, source = generated
    path = source.parent / DESIGN_POSES
    data = json.loads(path.read_text())
    data["poses"][3][2] += 1e-9
    path.write_text(json.dumps(data))
    with pytest.raises(FirmwareError, match=r"sd_design_poses\.json: not the poses it was generated with; .*'lifted'"):
        sd.firmware.check(source, **CHECK)
    path.unlink()
    with pytest.raises(FirmwareError, match=r"sd_design_poses\.json: No such file or directory; .*trajectory="):
        sd.firmware.check(source, **CHECK)
