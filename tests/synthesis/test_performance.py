"""The proof of the actuator and dexterity requirements (``synthesis.performance``): its per-cell bounds dominate the
toolkit's own evaluation (``envelope_sizing``, ``stiffness_matrix`` + ``lowest_frequency``, ``condition_number``) at
random poses, shrink to the centre's value with the cell, and the three outcomes (proven, violated with a witness
the toolkit confirms, unresolved)."""

from __future__ import annotations

from importlib import resources

import numpy as np
import pytest

from stewart_drake.core.rotations import rotation_matrix
from stewart_drake.synthesis.families import design_platform
from stewart_drake.synthesis.performance import (
    NAMES,
    performance_bounds,
    prove_performance,
    prove_requirements_performance,
    sampled_performance,
)
from stewart_drake.synthesis.proof import ROUND, START_CELLS, CellBudget, Cells
from stewart_drake.synthesis.requirements import load_requirements


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


TEMPLATE = resources.files("stewart_drake") / "templates" / "requirements.yaml"
# the design `optimize --budget 48` (seed 0) chooses on the requirements template: radii, half-angles, home height
TEMPLATE_X = [0.8914985975591974, 0.21701921906811264, 0.32361990590914863, 0.041326076705205037, 1.2579510023564282]


def test_the_default_budget_proves_the_templates_design():
    """The template's (the docs' example) chosen design needs more cells than the first budget: force's bound
    reaches its 4 kN limit only on fine cells. The default budget grows past ``START_CELLS`` while the volume left
    shrinks and proves every requirement, each bound on the right side of its limit."""
    req = load_requirements(TEMPLATE)
    design = design_platform(req, TEMPLATE_X, [1.2896629093960421, 1.646287872338915])
    proof = prove_requirements_performance(design, req)
    assert proof.ok and proof.stopped is None, {k: r["status"] for k, r in proof.results.items()}
    assert proof.cells_examined > START_CELLS  # what the first budget alone left unresolved
    r = proof.results
    assert r["force"]["bound"] <= req.max_force and r["speed"]["bound"] <= req.max_speed
    assert r["frequency"]["bound"] >= req.min_frequency_hz and r["condition"]["bound"] <= req.max_condition


def _cells(n, share):
    """``n`` cells covering ``share`` of the box [-1, 1]⁶ together (half-widths (share / n)^(1/6))."""
    return Cells(np.zeros((n, 6)), np.full((n, 6), (share / n) ** (1 / 6)))


def test_the_cell_budget_doubles_while_the_volume_left_shrinks_and_stops_when_it_stalls():
    """The first budget is ``START_CELLS``; past it, a level whose cells cover less than ``SHRINK`` of the volume left
    ``ROUND`` levels before (the whole box at first) doubles it, one that does not stops the proof ("stalled"), and
    the cap stops it too ("cap")."""
    lo, hi = -np.ones(6), np.ones(6)
    b = CellBudget(4 * START_CELLS, lo, hi)
    for _ in range(ROUND):  # levels within the first budget that prove nothing: allowed
        assert b.allows(0, _cells(1000, 1.0)) and b.limit == START_CELLS
    assert b.allows(START_CELLS, _cells(START_CELLS, 0.5)) and b.limit == 2 * START_CELLS and b.stopped is None
    for _ in range(ROUND - 1):
        assert b.allows(0, _cells(1000, 0.5))
    # ROUND levels after the volume was 0.5 it is still 0.5: a full round of halvings proved nothing
    assert not b.allows(2 * START_CELLS, _cells(START_CELLS + 1, 0.5)) and b.stopped == "stalled"
    capped = CellBudget(START_CELLS + 10, lo, hi)
    assert not capped.allows(START_CELLS, _cells(11, 1e-3)) and capped.stopped == "cap"
    small = CellBudget(60, lo, hi)  # a cap under the first budget is the budget
    assert small.allows(0, _cells(60, 1.0)) and not small.allows(60, _cells(1, 1e-3)) and small.stopped == "cap"
