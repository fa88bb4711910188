"""The search: the family reproduces the paper's geometry, the evaluation agrees with independent computations,
the same seed gives the same Pareto set on 1 and 2 Dask workers, and a search resumes from its folder."""

from __future__ import annotations

import json
import re
from importlib import resources

import numpy as np
import pytest
import scipy.linalg

from stewart_drake.core.geometry import load_platform_yaml
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.design.modes import spatial_inertia
from stewart_drake.design.stiffness import stiffness_matrix
from stewart_drake.errors import JournalError
from stewart_drake.synthesis.batch import evaluate_designs
from stewart_drake.synthesis.evaluate import evaluate_design, leg_range
from stewart_drake.synthesis.families import design_platform
from stewart_drake.synthesis.outputs import design_yaml
from stewart_drake.synthesis.proof import prove_requirements_box
from stewart_drake.synthesis.requirements import load_requirements
from stewart_drake.synthesis.search import CACHE, run_search
from stewart_drake.synthesis.synthesize import synthesize
from stewart_drake.system.journal import JournalWriter

SEED_001 = resources.files("stewart_drake") / "examples" / "seed_001_requirements.yaml"


@pytest.fixture(scope="module")
def req():
    return load_requirements(SEED_001)


def paper_x(gd):
    return np.array([0.624850, 0.392956, np.radians(6.9590), np.radians(17.2124), gd.home_height])


def test_radial_family_is_the_papers_pairing(gd, req):
    p = design_platform(req, paper_x(gd), gd.stroke)
    np.testing.assert_allclose(p.base_anchors, gd.base_anchors, atol=1e-12)
    np.testing.assert_allclose(p.top_anchors, gd.top_anchors, atol=1e-12)


def test_leg_range_bounds_a_dense_sample(gd, req):
    """The position is exact and the angles are sampled: a dense random sample of the box stays within the
    range up to the angle grid's curvature gap (well under the 2 mm stroke margin)."""
    lo, hi, _ = leg_range(req, paper_x(gd))
    rng = np.random.default_rng(0)
    u = rng.random((50_000, 6))
    u[:64] = np.stack(np.meshgrid(*[[0.0, 1.0]] * 6, indexing="ij"), -1).reshape(-1, 6)  # the vertices too
    poses = gd.home_pose() + req.box_lo + u * (req.box_hi - req.box_lo)
    L = leg_lengths(gd, poses)
    assert L.min() >= lo - 1e-3 and L.max() <= hi + 1e-3
    assert L.min() - lo < 1e-3 and hi - L.max() < 1e-3  # and the range is attained (not loose)


def test_frequency_matches_scipy_eigh(gd, req):
    """The evaluation's lowest frequency is the minimum over the box's poses of the generalised eigenproblem
    K φ = ω² M φ solved by scipy (an independent solver) with the toolkit's K and M."""
    row = evaluate_design(req, paper_x(gd))
    p = design_platform(req, paper_x(gd), [row["L_min"], row["L_max"]])
    corners = np.stack(np.meshgrid(*[[a, b] for a, b in zip(req.box_lo, req.box_hi, strict=True)], indexing="ij"), -1)
    poses = np.concatenate([corners.reshape(-1, 6), [(req.box_lo + req.box_hi) / 2]]) + p.home_pose()
    f = []
    for q in poses:
        K = stiffness_matrix(p, q, req.stiffness)
        w2 = scipy.linalg.eigh(0.5 * (K + K.T), spatial_inertia(p, q), eigvals_only=True)[0]
        f.append(np.sqrt(w2) / (2 * np.pi))
    assert row["frequency"] == pytest.approx(min(f), rel=1e-9)


def small(req):
    return {"budget": 36, "seed": 7, "pop_size": 12}


def test_same_pareto_set_on_one_and_two_workers(req):
    one = run_search(req, workers=1, **small(req))
    two = run_search(req, workers=2, **small(req))
    assert [r["x"] for r in one.rows] == [r["x"] for r in two.rows]
    assert [one.rows[i]["x"] for i in one.front] == [two.rows[i]["x"] for i in two.front]
    assert [one.rows[i]["f"] for i in one.front] == [two.rows[i]["f"] for i in two.front]
    assert len(one.front) > 0


def test_resume_after_interruption_and_with_a_larger_budget(req, tmp_path):
    full = run_search(req, **small(req))
    out = tmp_path / "search"
    first = run_search(req, out=out, **small(req))
    assert first.evaluated == 36 and [r["x"] for r in first.rows] == [r["x"] for r in full.rows]
    # an interruption: the cache loses its last 10 lines and half a line
    lines = (out / CACHE).read_text().splitlines()
    (out / CACHE).write_text("\n".join(lines[:-10]) + "\n" + lines[-10][:40])
    again = run_search(req, out=out, **small(req))
    assert again.evaluated == 10 and again.cached == 26
    assert [r["f"] for r in again.rows] == [r["f"] for r in full.rows]
    longer = run_search(req, out=out, budget=48, seed=7, pop_size=12)
    assert longer.evaluated == 12 and [r["x"] for r in longer.rows[:36]] == [r["x"] for r in full.rows]
    head = json.loads((out / CACHE).read_text().splitlines()[0])
    with pytest.raises(Exception, match="holds a search with other requirements or seed"):
        run_search(req, out=out, budget=12, seed=8, pop_size=12)
    assert head["key"] == first.key


def _journal(req, tmp_path):
    """A finished small search's folder and its journal's lines."""
    out = tmp_path / "search"
    run_search(req, out=out, **small(req))
    return out, (out / CACHE).read_text().splitlines()


def test_an_edited_journal_row_is_refused_naming_its_line(req, tmp_path):
    """A hand-edited objective put a fake design alone on the Pareto front after a resume."""
    out, lines = _journal(req, tmp_path)
    k = 5  # the 6th line: a design row
    lines[k] = lines[k].replace('"f": [', '"f": [-1e6, ', 1)
    (out / CACHE).write_text("\n".join(lines) + "\n")
    with pytest.raises(JournalError, match=rf"^{re.escape(str(out / CACHE))}:6: does not verify"):
        run_search(req, out=out, **small(req))


def test_a_journal_line_removed_from_the_middle_is_refused(req, tmp_path):
    out, lines = _journal(req, tmp_path)
    (out / CACHE).write_text("\n".join(lines[:3] + lines[4:]) + "\n")
    with pytest.raises(JournalError, match=rf"^{re.escape(str(out / CACHE))}:4: does not verify"):
        run_search(req, out=out, **small(req))


@pytest.mark.parametrize(
    ("edit", "problem"),
    [
        (lambda r: r.update(f=[-1.0e6] * len(r["f"])), "its objectives or constraints are not those of its metrics"),
        (lambda r: r["x"].__setitem__(0, 5.0), "variable base_radius = 5.0 is outside its bounds"),
    ],
)
def test_a_rewritten_chain_is_still_checked_against_the_requirements(req, tmp_path, edit, problem):
    """Whoever rewrites the chain (its key is not secret) still meets the row checks: bounds and f, g from the
    metrics."""
    out, lines = _journal(req, tmp_path)
    rows = [json.loads(line)["row"] for line in lines[1:]]
    edit(rows[2])
    (out / CACHE).write_text(lines[0] + "\n")
    w = JournalWriter(out / CACHE, json.loads(lines[0])["key"])
    w.append_texts([json.dumps(r) for r in rows])
    w.close()
    with pytest.raises(JournalError, match=rf"^{re.escape(str(out / CACHE))}:4: {re.escape(problem)}"):
        run_search(req, out=out, **small(req))


def test_batch_evaluation_equals_the_per_platform_functions(req):
    """The search's batched evaluation (designs × poses at once) against ``evaluate_design``, which calls the
    project's per-platform envelope sizing, stiffness, frequency and condition functions: every metric,
    objective and constraint within 1e-9 relative (rounding differs only by the order of operations)."""
    rng = np.random.default_rng(5)
    X = req.lower + rng.random((30, len(req.lower))) * (req.upper - req.lower)
    batch = evaluate_designs(req, X)
    compared = 0
    for x, b in zip(X, batch, strict=True):
        ref = evaluate_design(req, x)
        if ref["error"] is not None:  # singular or below the base: infeasible either way
            assert b["error"] is not None or max(b["g"]) > 0
            continue
        compared += 1
        keys = (
            "peak_force",
            "peak_speed",
            "L_min",
            "L_max",
            "base_radius",
            "frequency",
            "condition",
            "max_joint_angle",
            "min_leg_distance",
        )
        for key in keys:
            assert b[key] == pytest.approx(ref[key], rel=1e-9, abs=1e-9), key
        np.testing.assert_allclose(b["g"], ref["g"], rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(b["f"], ref["f"], rtol=1e-9)
    assert compared >= 20


UTN = """
length_unit: mm
angle_unit: deg
family: utn-3-6
variables: {b: [300, 500], d: [60, 150], a: [150, 300], home_height: [250, 450]}
workspace: {px: [-20, 20], py: [-20, 20], pz: [-10, 10], a: [-5, 5], b: [-5, 5], g: [-8, 8]}
payload: {mass: 5, com: [0, 0, 20], inertia: [30000, 30000, 50000, 0, 0, 0]}
motion: {velocity: {linear: 100, angular: 20}, acceleration: {linear: 1000, angular: 100}}
actuator: {max_force: 300, stroke: [250, 600], stiffness: 1.0e5}
objectives: [peak_force, base_radius]
"""


def test_utn_family_batch_and_design_file(tmp_path):
    """The utn-3-6 family (three plate joints, two legs each) with a fixed stroke, in millimetres: the batch
    equals the per-platform path, and the chosen design's file is a UTN platform file that loads and proves."""
    (tmp_path / "u.yaml").write_text(UTN)
    req = load_requirements(tmp_path / "u.yaml")
    assert req.variables == ("b", "d", "a", "home_height") and req.stroke.tolist() == [0.25, 0.6]
    X = req.lower + np.random.default_rng(8).random((12, 4)) * (req.upper - req.lower)
    for x, b in zip(X, evaluate_designs(req, X), strict=True):
        ref = evaluate_design(req, x)
        if ref["error"] is None:
            np.testing.assert_allclose(b["g"], ref["g"], rtol=1e-9, atol=1e-9)
    res = synthesize(req, budget=24, seed=1, pop_size=12)
    assert res.platform.top_anchors.shape == (3, 3) and res.platform.stroke.tolist() == [0.25, 0.6]
    text = design_yaml(res, "u.yaml")
    (tmp_path / "d.yaml").write_text(text)
    p = load_platform_yaml(tmp_path / "d.yaml")
    np.testing.assert_allclose(p.base_anchors, res.platform.base_anchors, atol=1e-12)
    assert prove_requirements_box(p, req.box_lo, req.box_hi).status == res.proof.status == "proven"
