"""The compiled real-time FK (core.realtime_fk, core/fk_kernel.c): the same Newton as the numpy
reference, its branch certificate checked against independent computations (the complete homotopy's
other modes, a fine numpy continuation), and the numpy fallback without a compiler."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from stewart_drake.core import realtime_fk
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import anchor_radius, leg_lengths
from stewart_drake.core.newton_fk import forward_kinematics, leg_geometry, newton_core
from stewart_drake.core.realtime_fk import RealtimeFK, certificate, pose_distance
from stewart_drake.core.rotations import angles_from_matrix, rotation_matrix
from stewart_drake.core.sampling import random_poses
from stewart_drake.errors import FkInputError
from tests._own_platform import own_radial


@pytest.fixture(scope="module")
def own_platform(tmp_path_factory):
    return own_radial(tmp_path_factory.mktemp("rtfk"))


def platforms(own):
    return [load_preset(n) for n in ("utn-dynamic", "gonzalez-dutra-2009", "utn-kinematic")] + [own]


def continuation(p, q0, L_target, steps=400):
    """The branch of q0 followed by the numpy Newton along L(s) = L(q0) + s (L* − L(q0)) in ``steps`` steps."""
    P, R = q0[:, :3].copy(), rotation_matrix(q0[:, 3:])
    _, _, L0 = leg_geometry(p, P, R)
    for s in np.linspace(0, 1, steps + 1)[1:]:
        P, R, _, _, st = newton_core(p, P, R, L0 + s * (L_target - L0))
    return np.c_[P, angles_from_matrix(R)], st


def test_compiled_newton_equals_numpy_newton(own_platform):
    """From 1 mm / 1 mrad off, the compiled Newton (per call and batched) and the numpy Newton give the
    same pose to 1e-12 (m and rad): both converge to the same root to tol = 1e-13 m in the legs, and the
    pose error is tol / σ_min ≲ 1e-12 at these workspace poses. Where certified, that root is the pose the
    lengths came from; near a singularity of utn-kinematic both Newtons land on another mode 2 mm away,
    and the compiled one says so (not certified)."""
    for p in platforms(own_platform):
        q = random_poses(p, 300, seed=1, region="workspace")
        L = leg_lengths(p, q)
        q0 = q + 1e-3
        fk = RealtimeFK(p, engine="c")
        r = fk.solve_batch(L, q0)
        ref = forward_kinematics(p, L, q0, check_singularity=False)
        assert r.engine == "c" and np.all(r.status == ref.status) and np.all(ref.converged)
        assert np.abs(r.poses - ref.poses).max() <= 1e-12
        assert np.abs(r.poses - q)[r.certified].max() <= 1e-9
        assert r.certified.mean() > 0.8
        for k in range(0, 300, 37):
            pose, cert, radius = fk.solve(L[k], q0[k])
            assert np.array_equal(pose, r.poses[k]) and cert == r.certified[k] and radius == r.radius[k]


def test_compiled_certificate_equals_numpy_certificate(own_platform):
    """The C kernel's bounds (η from Newton's LU solve, numpy's from X·F) and the vectorised numpy ones
    agree within the relative margin the bounds carry for rounding (MARGIN = 1e-9; the two roundings of
    J⁻¹F differ by ≈ κ ε ≲ 1e-11 at these condition numbers), and so do the certified flags."""
    for p in platforms(own_platform):
        q = random_poses(p, 300, seed=5, region="workspace")
        q0 = q + np.r_[2e-3, -1e-3, 1e-3, 2e-3, 1e-3, -2e-3]
        L = leg_lengths(p, q)
        c = RealtimeFK(p, engine="c").solve_batch(L, q0)
        n = RealtimeFK(p, engine="numpy").solve_batch(L, q0)
        assert n.engine == "numpy"
        tol = realtime_fk.MARGIN
        assert np.allclose(c.radius, n.radius, rtol=tol, atol=0) and np.allclose(c.eta, n.eta, rtol=tol, atol=0)
        assert np.array_equal(c.certified, n.certified) and c.certified.mean() > 0.5


def test_uniqueness_radius_is_below_the_distance_to_every_other_mode():
    """The certified uniqueness radius around a pose is a lower bound on the distance to every other
    real assembly mode of its lengths, found independently by the complete homotopy (an Euler-free
    distance: sqrt(|Δp|² + (a θ)²), as ``homotopy.branches``)."""
    from stewart_drake.homotopy import solve

    checked = 0
    for name in ("gonzalez-dutra-2009", "utn-dynamic"):
        p = load_preset(name)
        a = anchor_radius(p)
        for q in random_poses(p, 3, seed=4, region="workspace"):
            L = leg_lengths(p, q)
            modes = solve(p, L).modes
            P = np.array([m.position for m in modes])
            R = np.array([m.rotation for m in modes])
            rho, _ = certificate(p, P, R, np.broadcast_to(L, (len(modes), 6)))
            for i in range(len(modes)):
                d = pose_distance(a, P[i : i + 1], R[i : i + 1], np.delete(P, i, 0), np.delete(R, i, 0))
                assert rho[i] < d.min()
                checked += rho[i] > 0
    assert checked >= 6


def test_a_jump_to_another_mode_is_not_certified():
    """Large steps (one random workspace pose to another): where Newton lands on a pose that is not the
    continuation of the previous pose's branch, the result is never certified; with sub-steps, every
    certified result is that continuation (400 numpy Newton steps along the same length path)."""
    p = load_preset("utn-kinematic")
    q = random_poses(p, 400, seed=2, region="workspace")
    q0 = random_poses(p, 400, seed=3, region="workspace")
    L = leg_lengths(p, q)
    cont, st = continuation(p, q0, L)
    r = RealtimeFK(p).solve_batch(L, q0)
    ok = (r.status == 0) & (st == 0)
    jumped = ok & (np.abs(r.poses - cont).max(axis=1) > 1e-9)
    assert jumped.sum() >= 1 and not np.any(r.certified & jumped)
    s = RealtimeFK(p, max_substeps=64).solve_batch(L, q0)
    assert s.certified.sum() > 100 and np.all(s.substeps[s.certified] >= 1)
    assert np.abs(s.poses[s.certified & (st == 0)] - cont[s.certified & (st == 0)]).max() <= 1e-9


def test_track_certifies_a_trajectory_sampled_at_one_kilohertz(own_platform):
    """Following a 2 s motion sampled at 1 kHz, each pose from the last: every step certified on the
    branch, and the poses are the ones the lengths came from (round trip through IK, 1e-10 m)."""
    for p in (load_preset("utn-dynamic"), own_platform):
        t = np.linspace(0, 2, 2001)[:, None]
        amp = np.r_[0.02, 0.015, 0.01, 0.05, 0.04, 0.1]
        q = p.home_pose() + amp * np.sin(2 * np.pi * 0.5 * t + np.arange(6))
        r = RealtimeFK(p).track(leg_lengths(p, q), q[0])
        assert r.certified.all() and np.abs(r.poses - q).max() <= 1e-10
        n = RealtimeFK(p, engine="numpy").track(leg_lengths(p, q[:50]), q[0])
        assert np.abs(n.poses - r.poses[:50]).max() <= 1e-12 and n.certified.all()


def test_bad_input_is_named():
    p = load_preset("utn-dynamic")
    with pytest.raises(FkInputError, match="engine must be"):
        RealtimeFK(p, engine="fortran")
    with pytest.raises(FkInputError, match="do not match"):
        RealtimeFK(p).solve_batch(np.full((3, 6), 0.5), np.zeros((2, 6)))
    with pytest.raises(FkInputError, match="leg 2 length"):
        RealtimeFK(p).solve_batch([0.5, -1, 0.5, 0.5, 0.5, 0.5], p.home_pose())


def test_numpy_fallback_without_a_compiler(tmp_path):
    """No compiler ($STEWART_DRAKE_CC a missing program) and an empty cache: the numpy path runs, with the
    one-line note on stderr, and gives the compiled answer."""
    code = (
        "import numpy as np\n"
        "from stewart_drake.core.geometry import load_preset\n"
        "from stewart_drake.core.kinematics import leg_lengths\n"
        "from stewart_drake.core.realtime_fk import RealtimeFK\n"
        "p = load_preset('utn-dynamic'); q = p.home_pose() + [0.01, 0, 0.01, 0.05, 0, 0.1]\n"
        "fk = RealtimeFK(p); pose, cert, rho = fk.solve(leg_lengths(p, q), p.home_pose())\n"
        "import json; print(json.dumps([fk.engine, bool(cert), pose.tolist()]))\n"
    )
    env = {**os.environ, "STEWART_DRAKE_CC": "/nonexistent/cc", "STEWART_DRAKE_CACHE": str(tmp_path)}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True)
    assert out.stderr.strip() == realtime_fk.NO_COMPILER_NOTE
    engine, cert, pose = json.loads(out.stdout)
    p = load_preset("utn-dynamic")
    q = p.home_pose() + [0.01, 0, 0.01, 0.05, 0, 0.1]
    c_pose, c_cert, _ = RealtimeFK(p, engine="c").solve(leg_lengths(p, q), p.home_pose())
    assert engine == "numpy" and cert == c_cert
    assert np.abs(np.array(pose) - c_pose).max() <= 1e-12
