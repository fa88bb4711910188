"""Complete FK resolves singular end points instead of dropping them (issue 24, item 5b)."""

import numpy as np
import pytest

from stewart_drake.cli import main
from stewart_drake.core.geometry import load_platform
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.newton_fk import jacobian_analysis
from stewart_drake.homotopy import solve

POSE = np.array([0.0, 0.0, 0.7, 0.0, 0.0, np.pi / 2])  # utn-dynamic, inside the stroke, on a singularity


def test_the_singular_pose_is_found_not_dropped():
    """The IK of 0 0 0.7 m, 0 0 90°: 4 paths end at singular roots. Before, they were dropped and the result
    said "complete" with no real mode; now the pose is found (leg residual at rounding level), flagged
    singular (its Jacobian is rank-deficient: an independent check with the kinematics' own analysis)."""
    p = load_platform("utn-dynamic")
    L = leg_lengths(p, POSE)
    r = solve(p, L)
    assert r.classes.count("singular") == 4
    found = [m for m in r.modes if np.allclose(m.position, POSE[:3], atol=1e-7)]
    assert len(found) == 1 and found[0].singular and not found[0].certified
    R = found[0].rotation
    assert np.degrees(np.arctan2(R[1, 0], R[0, 0])) == pytest.approx(90.0, abs=1e-5)
    assert found[0].residual < 1e-12
    assert jacobian_analysis(p, POSE).sigma_min < 1e-6 * jacobian_analysis(p, p.home_pose()).sigma_min
    assert r.complete and "resolved by Gauss–Newton" in r.guarantee


def test_fk_all_shows_the_singular_pose_and_exits_1(capsys):
    L = leg_lengths(load_platform("utn-dynamic"), POSE)
    rc = main(
        ["fk", "--platform", "utn-dynamic", "--length-unit", "m", "--lengths", *(repr(float(x)) for x in L), "--all"]
    )
    out, err = capsys.readouterr()
    assert rc == 1 and "SINGULAR" in out and "lie on a singularity" in err and "cannot be assembled" not in err
    assert "0.70000" in out and "90.00000" in out
