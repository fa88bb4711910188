"""The calibration model: residuals vanish on the true machine, the central-difference Jacobian equals the
closed-form derivatives of the leg lengths, shared joints stay shared, tilts are the Euler angles."""

from __future__ import annotations

import numpy as np
import pytest

from stewart_drake.calibration.model import Layout, exp_so3, make_problem, pose_blocks, pose_residuals, tilts
from stewart_drake.calibration.simulate import default_targets, draw_machine
from stewart_drake.core.geometry import Platform, load_preset
from stewart_drake.core.kinematics import leg_unit_vectors
from stewart_drake.core.rotations import rotation_matrix
from stewart_drake.core.sampling import random_poses
from tests.calibration.conftest import ERRORS, NOISE, clean_data


@pytest.mark.parametrize("name", ["utn-dynamic", "gonzalez-dutra-2009"])
@pytest.mark.parametrize("kind", ["pose", "points", "inclinometer"])
def test_residuals_vanish_on_the_true_machine(name, kind):
    """Noise-free data of a drawn machine: its own θ gives residuals at the rounding floor (< 1e-3 σ), the
    nominal's gives hundreds of σ (1 mm errors over µm noise)."""
    nominal = load_preset(name)
    truth, _ = draw_machine(nominal, ERRORS, np.random.default_rng(5))
    q = random_poses(nominal, 12, seed=2)
    targets = default_targets(nominal, 3) if kind == "points" else None
    data = clean_data(truth, q, kind, targets)
    layout = Layout(nominal, kind, 3 if kind == "points" else 0)
    problem = make_problem(layout, data, NOISE, platform=truth)  # reference poses: the truth's FK = the poses
    assert np.abs(pose_residuals(problem, layout.theta(truth, targets))).max() < 1e-3
    assert np.abs(pose_residuals(problem, layout.theta(nominal, targets))).max() > 20


def test_jacobian_equals_the_closed_form_leg_derivatives():
    """Pose data: d(L_i − r_i − o_i)/db_j = −u_i, /dt_j = R_BTᵀ u_i (leg i on joint j), /do_i = −1. The
    central-difference blocks, un-whitened, agree to 1e-7 (truncation h² ~ 1e-12 over lengths ~1)."""
    p = load_preset("gonzalez-dutra-2009")
    q = random_poses(p, 5, seed=3)
    layout = Layout(p, "pose")
    problem = make_problem(layout, clean_data(p, q, "pose"), NOISE)
    Jg, Jn = pose_blocks(problem, layout.theta(p))
    assert not Jn.any()
    raw = np.linalg.inv(problem.whiten) @ Jg  # undo the whitening: d e_leg / dθ
    u = leg_unit_vectors(p, q)  # (n, 6, 3)
    R = rotation_matrix(q[:, 3:])
    expect = np.zeros_like(raw)
    for i in range(6):
        expect[:, i, 3 * i : 3 * i + 3] = -u[:, i]
        expect[:, i, 18 + 3 * i : 18 + 3 * i + 3] = np.einsum("nji,nj->ni", R, u[:, i])
        expect[:, i, 36 + i] = -1.0
    assert np.abs(raw - expect).max() < 1e-7


def _six_three() -> Platform:
    """A 6-3 platform (three base joints, each shared by two legs; six plate joints)."""
    ang_b = np.radians([0, 120, 240])
    base = np.stack([0.5 * np.cos(ang_b), 0.5 * np.sin(ang_b), np.zeros(3)], -1)[[0, 0, 1, 1, 2, 2]]
    ang_t = np.radians([-40, 40, 80, 160, 200, 280])
    top = np.stack([0.3 * np.cos(ang_t), 0.3 * np.sin(ang_t), np.zeros(6)], -1)
    return Platform(
        name="six-three", base_anchors=base, top_anchors=top, leg_top=np.arange(6), stroke=[0.5, 0.9], mass=5.0,
        com=np.zeros(3), inertia=np.eye(3) * 0.1,
    )  # fmt: skip


def test_shared_joints_stay_shared():
    """3-6 (utn): 6 base + 3 plate joints (33 parameters); 6-3: 3 base + 6 plate joints. A drawn or
    identified θ moves a shared joint as one point: its legs still coincide."""
    utn = Layout(load_preset("utn-dynamic"), "pose")
    assert (utn.n_base, utn.n_top, utn.size) == (6, 3, 33)
    p63 = _six_three()
    lay = Layout(p63, "pose")
    assert (lay.n_base, lay.n_top, lay.size) == (3, 6, 33)
    moved = lay.platform(lay.theta(p63) + np.random.default_rng(0).normal(0, 1e-3, lay.size))
    b = moved.base_anchors
    assert np.array_equal(b[0], b[1]) and np.array_equal(b[2], b[3]) and np.array_equal(b[4], b[5])
    assert not np.allclose(b[0], p63.base_anchors[0])
    truth, _ = draw_machine(p63, ERRORS, np.random.default_rng(1))
    assert np.array_equal(truth.base_anchors[2], truth.base_anchors[3])


def test_tilts_are_the_roll_and_pitch_whatever_the_yaw():
    rng = np.random.default_rng(0)
    a, b, g = rng.uniform(-0.5, 0.5, (3, 20))
    Rx = np.array([[[1, 0, 0], [0, np.cos(t), -np.sin(t)], [0, np.sin(t), np.cos(t)]] for t in a])
    Ry = np.array([[[np.cos(t), 0, np.sin(t)], [0, 1, 0], [-np.sin(t), 0, np.cos(t)]] for t in b])
    Rz = np.array([[[np.cos(t), -np.sin(t), 0], [np.sin(t), np.cos(t), 0], [0, 0, 1]] for t in g])
    assert np.abs(tilts(Rz @ Ry @ Rx) - np.stack([a, b], -1)).max() < 1e-12


def test_exp_so3_is_rodrigues():
    """exp of a rotation vector: orthonormal, fixes the axis, turns by its norm (small ones too)."""
    for w in (np.array([0.3, -0.2, 0.5]), np.array([1e-10, 0, 0])):
        R = exp_so3(w)
        assert np.allclose(R @ R.T, np.eye(3), atol=1e-14) and np.allclose(R @ w, w, atol=1e-14)
        assert np.isclose(np.arccos((np.trace(R) - 1) / 2), np.linalg.norm(w), atol=1e-7)


@pytest.mark.parametrize("name", ["utn-dynamic", "gonzalez-dutra-2009"])
def test_layout_base_is_found_once_and_read_only(name):
    """The residuals read ``Layout.base`` at every evaluation: it is the platform's base joints, kept from the
    first read, and read-only so that no caller can change it for the others."""
    from stewart_drake.core.geometry import base_joints

    lay = Layout(load_preset(name), "pose")
    first, leg_joint = lay.base
    ref = base_joints(lay.nominal)
    assert np.array_equal(first, ref[0]) and np.array_equal(leg_joint, ref[1]) and lay.n_base == 6
    assert lay.base[0] is first and lay.base[1] is leg_joint
    with pytest.raises(ValueError):
        leg_joint[0] = 1
