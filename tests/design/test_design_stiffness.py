"""Stiffness and natural frequencies: zero-load stiffness against Aᵀ diag(k) A built from
the anchors, loaded stiffness against finite differences of the static wrench, the inertia against inverse
dynamics (the modes against Drake: ``tests/drake/test_design_stiffness_drake.py``)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from stewart_drake.cli import main
from stewart_drake.core.geometry import load_platform
from stewart_drake.design.modes import spatial_inertia
from stewart_drake.design.payload import with_payload
from stewart_drake.design.stiffness import deflection, principal_stiffness, stiffness_matrix
from stewart_drake.errors import PayloadError, StiffnessError

G = 9.81
Q_OFF = np.array([0.05, -0.03, 0.72, 0.1, -0.05, 0.2])  # an asymmetric pose: no repeated frequencies
K_LEGS = np.array([1.0e5, 1.2e5, 0.9e5, 1.0e5, 1.1e5, 1.05e5])


def _R(angles):
    """utn R = Ry(b) Rx(a) Rz(g) by scipy."""
    a = np.asarray(angles, float)
    return Rotation.from_euler("YXZ", [a[1], a[0], a[2]]).as_matrix()


def _geometry(p, pose, R=None):
    R = _R(pose[3:]) if R is None else R
    r = (p.top_anchors_per_leg - p.rotation_centre) @ R.T
    l = pose[:3] + r - p.base_anchors
    L = np.linalg.norm(l, axis=1)
    return r, l / L[:, None], L, R


@pytest.fixture(scope="module")
def loaded():
    return with_payload(load_platform("utn-dynamic"), 8.0, [0.03, -0.02, 0.06])


def test_zero_load_stiffness_is_At_k_A(loaded):
    r, u, _, _ = _geometry(loaded, Q_OFF)
    A = np.hstack([u, np.cross(r, u)])
    expected = A.T @ np.diag(K_LEGS) @ A
    for K in (
        stiffness_matrix(loaded, Q_OFF, K_LEGS, gravity=0.0),
        stiffness_matrix(loaded, Q_OFF, K_LEGS, loaded=False),
    ):
        assert np.abs(K - expected).max() <= 1e-9 * np.abs(expected).max()


def _total_wrench(p, q0, dx, k):
    """Wrench on the plate displaced by δx = [δp; δθ] from equilibrium at q0, legs as springs at their q0
    lengths, with the static forces solved here from the anchors (independent of the toolkit)."""
    r0, u0, L0, R0 = _geometry(p, q0)
    r_cm0 = R0 @ (p.com - p.rotation_centre)
    fg = np.array([0, 0, -p.mass * G])
    F0 = np.linalg.solve(np.hstack([u0, np.cross(r0, u0)]).T, -np.r_[fg, np.cross(r_cm0, fg)])
    R = Rotation.from_rotvec(dx[3:]).as_matrix() @ R0
    r, u, L, _ = _geometry(p, np.r_[q0[:3] + dx[:3], 0, 0, 0], R)
    F = F0 - k * (L - L0)
    r_cm = R @ (p.com - p.rotation_centre)
    return np.r_[F @ u + fg, F @ np.cross(r, u) + np.cross(r_cm, fg)]


def test_loaded_stiffness_matches_finite_differences(loaded):
    K = stiffness_matrix(loaded, Q_OFF, K_LEGS)
    h = 1e-6
    K_fd = -np.stack(
        [
            (_total_wrench(loaded, Q_OFF, h * e, K_LEGS) - _total_wrench(loaded, Q_OFF, -h * e, K_LEGS)) / (2 * h)
            for e in np.eye(6)
        ],
        -1,
    )
    # central differences: truncation ~ h² |w'''| and rounding ~ 1e-16 k L / h, both < 1e-8 of |K| here
    assert np.abs(K - K_fd).max() <= 1e-8 * np.abs(K).max()
    K0 = stiffness_matrix(loaded, Q_OFF, K_LEGS, loaded=False)
    assert np.abs(K - K0).max() > 1e-4 * np.abs(K).max()  # the load matters at this resolution


@pytest.mark.parametrize("legs", [False, True])
def test_loaded_stiffness_symmetric_at_equilibrium(loaded, legs):
    """A conservative system's stiffness at an equilibrium is a Hessian: symmetric. The geometric term
    alone is not, so this checks the load terms against each other."""
    K = stiffness_matrix(loaded, Q_OFF, K_LEGS, legs=legs)
    tol = (1e-12 if not legs else 1e-9) * np.abs(K).max()  # legs: their weight term by central differences
    assert np.abs(K - K.T).max() <= tol


def test_home_pose_is_isotropic_in_xy():
    """The 3-fold symmetric platform at home: equal x and y stiffness, principal directions along z."""
    p = load_platform("utn-dynamic")
    K = stiffness_matrix(p, p.home_pose(), 1e5)
    pr = principal_stiffness(K)
    assert abs(pr.translational[0] - pr.translational[1]) <= 1e-9 * pr.translational[0]
    assert abs(abs(pr.translational_dirs[2, 2]) - 1) < 1e-12


def test_deflection_solves_the_nonlinear_statics_to_first_order(loaded):
    """δx = K⁻¹ w for a small extra load equals the displaced equilibrium (Newton on the exact wrench)."""
    K = stiffness_matrix(loaded, Q_OFF, K_LEGS)
    w = np.array([0.3, -0.2, -1.0, 0.02, 0.01, -0.03])
    d = deflection(K, w)
    x = np.zeros(6)
    for _ in range(5):
        res = _total_wrench(loaded, Q_OFF, x, K_LEGS) + w
        x = x + np.linalg.solve(K, res)
    # second-order effects ~ |d|² relative
    assert np.abs(x - d).max() <= 1e-3 * np.abs(d).max()


# ----------------------------------------------------------------------------------------------
# Natural frequencies.


def test_spatial_inertia_matches_inverse_dynamics(loaded):
    """M_C by formula equals the one read off the toolkit's inverse dynamics (unit accelerations)."""
    from stewart_drake.core.kinematics import inverse_jacobian
    from stewart_drake.design.envelope import cartesian_leg_forces

    A = inverse_jacobian(loaded, Q_OFF)
    F = cartesian_leg_forces(loaded, np.broadcast_to(Q_OFF, (6, 6)), np.zeros((6, 6)), np.eye(6), gravity=0.0)
    M = spatial_inertia(loaded, Q_OFF)
    assert np.abs(A.T @ F.T - M).max() <= 1e-12 * np.abs(M).max()


# ----------------------------------------------------------------------------------------------
# CLI.


def test_cli_stiffness_json(capsys):
    assert (
        main(
            [
                "stiffness",
                "--pose",
                "50",
                "-30",
                "720",
                "5",
                "-3",
                "10",
                "--payload",
                "8",
                "--payload-com",
                "30",
                "-20",
                "60",
                "--json",
            ]
        )
        == 0
    )
    out = json.loads(capsys.readouterr().out)
    p = with_payload(load_platform("utn-dynamic"), 8.0, [0.03, -0.02, 0.06])
    q = np.r_[0.05, -0.03, 0.72, np.radians([5, -3, 10])]
    K = stiffness_matrix(p, q, 1e5)  # legs.stiffness of the preset
    assert np.allclose(out["stiffness"], K, rtol=0, atol=1e-9 * np.abs(K).max())
    assert len(out["principal_stiffness"]["translational_n_per_m"]) == 3
    d = np.array(out["deflection"])
    assert d[2] < 0  # the payload pushes the plate down
    assert np.allclose(K @ d, out["payload_wrench"], atol=1e-9)


@pytest.mark.parametrize(
    "args, needle, rc",
    [
        (["--leg-stiffness", "-5"], StiffnessError.NOT_POSITIVE.format(option="--leg-stiffness", value=-5.0), 2),
        (["--leg-stiffness", "nan"], "--leg-stiffness", 2),
        (
            ["--payload", "2", "--payload-com", "0", "0", "-5"],
            PayloadError.BELOW_PLATE.format(option="--payload-com", z=-5.0, unit="mm"),
            2,
        ),
        (["--platform", "utn-kinematic"], StiffnessError.MISSING.format(option="legs.stiffness"), 2),
    ],
)
def test_cli_stiffness_errors(capsys, args, needle, rc):
    assert main(["stiffness", "--pose", "0", "0", "700", "0", "0", "0"] + args) == rc
    err = capsys.readouterr().err
    assert needle in err and err.count("\n") == 1


@pytest.mark.parametrize("command", ["stiffness", "modes"])
def test_cli_plate_below_the_base_exits_1(capsys, command):
    """The mirror image of a reachable pose under the base has legs within the stroke: only the sanity
    check that every command shares refuses it."""
    assert main([command, "--pose", "0", "0", "-700", "0", "0", "0", "--length-unit", "mm"]) == 1
    err = capsys.readouterr().err
    assert "the plate is below the base" in err and err.count("\n") == 1


def test_cli_stiffness_unreachable(capsys):
    assert main(["stiffness", "--pose", "0", "0", "300", "0", "0", "0"]) == 1
    assert "below the stroke minimum" in capsys.readouterr().err
