"""What the data cannot identify is computed and named: inclinometer data on a 6-6 cannot fix the base
frame's position and yaw nor the plate frame's position; poses that are all pure translations lose each
leg's joint pair; targets leave the plate frame free; full poses identify everything."""

from __future__ import annotations

import numpy as np
import pytest

from stewart_drake.calibration.identifiability import analyse, free_parameters, stacked
from stewart_drake.calibration.model import Layout, make_problem, pose_blocks, reduced_blocks
from stewart_drake.calibration.simulate import default_targets
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.sampling import random_poses
from tests.calibration.conftest import NOISE, clean_data


def _analyse(name, kind, poses, targets=None):
    p = load_preset(name)
    layout = Layout(p, kind, 0 if targets is None else len(targets))
    problem = make_problem(layout, clean_data(p, poses, kind, targets), NOISE)
    theta = layout.theta(p, targets)
    return analyse(layout, stacked(reduced_blocks(*pose_blocks(problem, theta)), NOISE.length), theta)


def test_inclinometer_on_a_6_6_names_the_frame_freedoms():
    p = load_preset("gonzalez-dutra-2009")
    ident = _analyse("gonzalez-dutra-2009", "inclinometer", random_poses(p, 30, seed=1))
    assert ident.frame_freedoms == [
        "base frame translation along x",
        "base frame translation along y",
        "base frame translation along z",
        "base frame rotation about z",
        "plate frame translation along x",
        "plate frame translation along y",
        "plate frame translation along z",
    ]
    # exactly those 7 are lost; the convention holds base joint 1, one more base coordinate and plate joint 1
    assert len(ident.fixed) == 7 and ident.free.sum() == 35
    assert [ident.names[i] for i in ident.fixed] == [
        "base joint 1 x", "base joint 1 y", "base joint 1 z", "base joint 2 x",
        "plate joint 1 x", "plate joint 1 y", "plate joint 1 z",
    ]  # fmt: skip
    assert np.isfinite(ident.condition) and ident.noise_amplification > 0


@pytest.mark.parametrize("name, lost", [("gonzalez-dutra-2009", 18), ("utn-dynamic", 9)])
def test_pure_translations_lose_each_legs_joint_pair(name, lost):
    """Every pose at one orientation: L_i depends on b_i − R t_i only, so each base joint and its plate
    joint move together unseen: 3 per leg on a 6-6 (18), 3 per plate joint on a 3-6 (9: two base joints
    and their shared plate joint move together)."""
    p = load_preset(name)
    q = random_poses(p, 30, seed=2)
    q[:, 3:] = [0.02, -0.01, 0.03]
    ident = _analyse(name, "pose", q)
    assert len(ident.fixed) == lost and ident.frame_freedoms == []
    first = ident.combinations[0]
    assert first.startswith("base joint 1 x") or "base joint 1 x" in first
    assert "plate joint 1 x" in first


def test_targets_leave_the_plate_frame_free():
    p = load_preset("utn-dynamic")
    ident = _analyse("utn-dynamic", "points", random_poses(p, 20, seed=3), default_targets(p, 3))
    assert ident.frame_freedoms == [
        f"plate frame {m} {w} {a}" for m, w in (("translation", "along"), ("rotation", "about")) for a in "xyz"
    ]
    assert len(ident.fixed) == 6


def test_full_poses_identify_every_parameter():
    p = load_preset("gonzalez-dutra-2009")
    ident = _analyse("gonzalez-dutra-2009", "pose", random_poses(p, 20, seed=4))
    assert ident.fixed == [] and ident.free.all() and ident.frame_freedoms == []
    assert ident.to_dict()["identifiable"] == 42


@pytest.mark.parametrize("kind", ["inclinometer", "pose"])
def test_free_parameters_is_analyse_s_convention(kind):
    """The light call (one SVD) holds the same parameters as the full analysis, chosen afresh or kept from a
    previous fit; inclinometer data loses 7 (a non-trivial convention), full poses none."""
    p = load_preset("gonzalez-dutra-2009")
    layout = Layout(p, kind)
    problem = make_problem(layout, clean_data(p, random_poses(p, 30, seed=1), kind), NOISE)
    theta = layout.theta(p)
    J = stacked(reduced_blocks(*pose_blocks(problem, theta)), NOISE.length)
    ident = analyse(layout, J, theta)
    fixed, free = free_parameters(J)
    assert fixed == ident.fixed and np.array_equal(free, ident.free)
    assert len(fixed) == (7 if kind == "inclinometer" else 0)
    kept = list(reversed(ident.fixed))  # a convention that still fixes every null direction is kept as given
    assert free_parameters(J, kept)[0] == kept == analyse(layout, J, theta, fixed=kept).fixed
