"""``stewart-drake fk`` (Newton) says whether its answer is on the initial pose's branch
(``core.realtime_fk.branch_check``)."""

import json

import numpy as np

from stewart_drake.cli import main
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.newton_fk import forward_kinematics, leg_geometry, newton_core
from stewart_drake.core.realtime_fk import branch_check
from stewart_drake.core.rotations import rotation_matrix
from stewart_drake.core.sampling import random_poses


def test_fk_reports_the_branch_of_the_initial_pose(capsys):
    """From home to a pose 10 mm / 5 deg away: certified on home's branch, with a positive uniqueness
    radius around home (mm); the text output says so."""
    p = load_preset("utn-kinematic")
    q = np.array([10.0, -5.0, 120.0, 3.0, -2.0, 5.0])
    L = leg_lengths(p, np.r_[q[:3] * 1e-3, np.radians(q[3:])]) * 1e3
    assert main(["fk", "--lengths", *(repr(float(v)) for v in L), "--json"]) == 0
    (s,) = json.loads(capsys.readouterr().out)["solutions"]
    assert s["branch_certified"] is True and s["uniqueness_radius_initial"] > 0
    assert main(["fk", "--lengths", *(repr(float(v)) for v in L)]) == 0
    assert "on the initial pose's branch (certified)" in capsys.readouterr().out


def test_branch_check_refuses_a_newton_answer_on_another_branch():
    """Large steps between random workspace poses of utn-kinematic: where Newton's answer is not the
    continuation of the initial pose's branch (400 numpy Newton steps along the straight length path,
    an independent follow), the branch check does not certify it; where it is, it does (most pairs)."""
    p = load_preset("utn-kinematic")
    q = random_poses(p, 400, seed=2, region="workspace")
    q0 = random_poses(p, 400, seed=3, region="workspace")
    L = leg_lengths(p, q)
    r = forward_kinematics(p, L, q0, check_singularity=False)
    P, R = q0[:, :3].copy(), rotation_matrix(q0[:, 3:])
    _, _, L0 = leg_geometry(p, P, R)
    for s in np.linspace(0, 1, 401)[1:]:
        P, R, _, _, st = newton_core(p, P, R, L0 + s * (L - L0))
    ok = r.converged & (st == 0)
    jumped = ok & (np.abs(r.iterate[:, :3] - P).max(axis=1) > 1e-9)
    assert jumped.sum() >= 1
    for k in np.flatnonzero(jumped):
        assert not branch_check(p, q0[k], L[k], r.iterate[k, :3], r.rotation[k])[0]
    followed = [
        branch_check(p, q0[k], L[k], r.iterate[k, :3], r.rotation[k])[0] for k in np.flatnonzero(ok & ~jumped)[:40]
    ]
    assert np.mean(followed) > 0.5
