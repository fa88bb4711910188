"""The proof of the actuator and dexterity requirements (``synthesis.performance``): its per-cell bounds dominate the
toolkit's own evaluation (``envelope_sizing``, ``stiffness_matrix`` + ``lowest_frequency``, ``condition_number``) at
random poses, shrink to the centre's value with the cell, and the three outcomes (proven, violated with a witness
the toolkit confirms, unresolved)."""

from __future__ import annotations

import numpy as np
import pytest

from stewart_drake.core.rotations import rotation_matrix
from stewart_drake.synthesis.performance import (
    NAMES,
    performance_bounds,
    prove_performance,
    prove_requirements_performance,
    sampled_performance,
)
from stewart_drake.synthesis.proof import Cells


def _args(req):
    return req.v_max, req.a_max, req.stiffness, req.convention


def test_cell_bounds_dominate_the_toolkit_on_sampled_poses(req, design):
    """On 40 random cells (half-widths up to 1 cm and 1.7°), 250 random poses each (vertices included) evaluated by
    the toolkit's per-platform functions: every force, speed and condition number is at most the cell's bound, every
    lowest frequency at least its bound (10⁴ poses in all)."""
    rng = np.random.default_rng(3)
    home = design.home_pose()
    c = home + rng.uniform(-1, 1, (40, 6)) * np.r_[req.box_hi[:3], req.box_hi[3:]] * 0.8
    h = rng.uniform(0.1, 1.0, (40, 6)) * np.r_[0.01, 0.01, 0.01, 0.03, 0.03, 0.03]
    b = performance_bounds(design, Cells(c, h), *_args(req))
    u = rng.uniform(-1, 1, (40, 250, 6))
    u[:, :64] = np.array(np.meshgrid(*[[-1.0, 1.0]] * 6, indexing="ij")).reshape(6, -1).T
    poses = (c[:, None] + u * h[:, None]).reshape(-1, 6)
    s = {k: v.reshape(40, 250) for k, v in sampled_performance(design, poses, *_args(req)).items()}
    for k in ("force", "speed", "condition"):
        assert np.all(s[k].max(1) <= getattr(b, k)), k
    assert np.all(s["frequency"].min(1) >= b.frequency)
    assert np.all(np.isfinite(b.force)) and np.all(b.frequency > 0)  # not vacuous on cells of this size


def test_bounds_shrink_to_the_centre_value(req, design):
    """As the cell shrinks, every bound tends to the toolkit's value at its centre (first order in the width): at
    1e-6 m / 1e-6 rad half-widths within 1e-3 relative (the geometric-stiffness term of the frequency bound stays:
    it is bounded, not differenced, at ~1e-3 of k σ_min²)."""
    home = design.home_pose()
    s = sampled_performance(design, home[None], *_args(req))
    b = performance_bounds(design, Cells(home[None], np.full((1, 6), 1e-6)), *_args(req))
    for k in NAMES:
        np.testing.assert_allclose(getattr(b, k), s[k], rtol=1e-3)
        np.testing.assert_allclose(getattr(b, "centre_" + k), s[k], rtol=1e-9)  # the centre: the same formulas


def test_proof_over_the_box_dominates_random_poses(req, design):
    """The seed-001 requirements proven on the design over its whole box; 10⁴ random poses of the box (the
    toolkit's functions) never exceed a proven bound. The bounds are within a factor 5 of the sampled worst (force
    ~4, frequency ~2.6, condition ~2.5, speed ~1.05 with the default refinement)."""
    proof = prove_requirements_performance(design, req)
    assert proof.ok, proof.results
    home = design.home_pose()
    rng = np.random.default_rng(4)
    poses = home + req.box_lo + rng.random((10_000, 6)) * (req.box_hi - req.box_lo)
    s = sampled_performance(design, poses, *_args(req))
    r = proof.results
    for k in ("force", "speed", "condition"):
        assert s[k].max() <= r[k]["bound"] <= r[k]["required"]
        assert r[k]["bound"] <= 5 * s[k].max()
    assert r["frequency"]["required"] <= r["frequency"]["bound"] <= s["frequency"].min()
    assert r["frequency"]["bound"] >= s["frequency"].min() / 5


def test_tight_requirements_are_violated_with_a_witness_the_toolkit_confirms(req, design):
    """A force limit at 95 % and a frequency floor 5 % above what the box's centre pose achieves: both violated,
    each with a witness pose inside the box at which the toolkit's own evaluation breaks the limit (exit 1 follows)."""
    home = design.home_pose()
    at_home = sampled_performance(design, home[None], *_args(req))
    limits = {"force": 0.95 * at_home["force"][0], "frequency": 1.05 * at_home["frequency"][0], "speed": 10.0}
    lo, hi = home + req.box_lo, home + req.box_hi
    proof = prove_performance(design, lo, hi, limits, *_args(req), tighten_cells=0)
    assert proof.results["speed"]["status"] == "proven"
    for k, worse in (("force", np.greater), ("frequency", np.less)):
        r = proof.results[k]
        assert r["status"] == "violated"
        pose = np.array(r["witness"]["pose"])
        assert np.all(pose >= lo) and np.all(pose <= hi)
        value = sampled_performance(design, pose[None], *_args(req))[k][0]
        assert worse(value, limits[k]) and value == pytest.approx(r["witness"]["value"], rel=1e-12)
    assert not proof.ok


def test_too_few_cells_is_unresolved(req, design):
    """A limit just above the sampled worst needs fine cells: with 100 cells the requirement is unresolved, with
    the cells left listed."""
    home = design.home_pose()
    lo, hi = home + req.box_lo, home + req.box_hi
    worst = sampled_performance(design, np.r_[lo[None], hi[None], home[None]], *_args(req))["force"].max()
    proof = prove_performance(design, lo, hi, {"force": 1.3 * worst}, *_args(req), max_cells=100, tighten_cells=0)
    r = proof.results["force"]
    assert r["status"] == "unresolved" and r["unresolved_count"] > 0 and len(r["unresolved_cells"]) > 0
    assert r["bound"] is None


def test_derived_constants_hold():
    """The two constants the bounds rest on, on random draws: ‖R(θ+δ) − R(θ)‖₂ <= ‖δ‖₁ for both conventions (and not
    loose: the ratio reaches 0.9), and |a/|a| − b/|b|| <= |a − b| / min(|a|, |b|) (normalising is 1-Lipschitz
    outside the unit ball)."""
    rng = np.random.default_rng(5)
    th = rng.uniform(-1, 1, (20_000, 3))
    d = rng.uniform(-0.3, 0.3, (20_000, 3)) * rng.random((20_000, 1))
    for convention in ("utn", "zyx"):
        diff = np.linalg.norm(rotation_matrix(th + d, convention) - rotation_matrix(th, convention), 2, axis=(1, 2))
        ratio = diff / np.sum(np.abs(d), 1)
        assert np.all(ratio <= 1 + 1e-12) and ratio.max() > 0.9
    a, b = rng.normal(size=(2, 20_000, 3)) * rng.uniform(0.1, 2, (2, 20_000, 1))
    na, nb = np.linalg.norm(a, axis=1), np.linalg.norm(b, axis=1)
    lhs = np.linalg.norm(a / na[:, None] - b / nb[:, None], axis=1)
    assert np.all(lhs <= np.linalg.norm(a - b, axis=1) / np.minimum(na, nb) * (1 + 1e-12))
