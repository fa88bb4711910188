"""The proof of a pose box: its bounds enclose the IK's leg lengths, the Taylor constant holds, rounding is covered
(checked in ball arithmetic), and the three outcomes (proven, violated with a witness, unresolved)."""

from __future__ import annotations

from importlib import resources

import flint
import numpy as np
import pytest

from stewart_drake.core.kinematics import leg_lengths, leg_vectors
from stewart_drake.core.rotations import rotation_matrix
from stewart_drake.core.sanity import plate_anchor_heights
from stewart_drake.synthesis.families import design_platform
from stewart_drake.synthesis.proof import (
    COVER_PAD,
    FP_SLACK,
    VERTICES,
    Cells,
    cell_bounds,
    prove_box,
    prove_requirements_box,
    rotation_derivatives,
)
from stewart_drake.synthesis.requirements import load_requirements
from stewart_drake.workspace.limits import Limits, limit_margins, raw_margins

# A fifth of the paper's one-axis extents (seed 001): inside the gonzalez-dutra-2009 geometry's reach.
FIFTH_LO = np.array([-0.0782, -0.0902, -0.0501, *np.radians([-8.36, -6.58, -9.46])])
FIFTH_HI = np.array([0.0782, 0.0902, 0.0451, *np.radians([7.22, 6.58, 9.46])])


@pytest.mark.parametrize("convention", ["utn", "zyx"])
def test_rotation_derivatives_match_the_toolkit(convention):
    rng = np.random.default_rng(0)
    a = rng.uniform(-1, 1, (20, 3))
    R, dR = rotation_derivatives(a, convention)
    np.testing.assert_allclose(R, rotation_matrix(a, convention), atol=1e-15)
    h = 1e-6
    for j in range(3):
        e = np.eye(3)[j] * h
        fd = (rotation_matrix(a + e, convention) - rotation_matrix(a - e, convention)) / (2 * h)
        np.testing.assert_allclose(dR[:, j], fd, atol=1e-9)  # central difference error ~ h²


def random_cells(rng, home, n, h_max):
    c = home + rng.uniform(-1, 1, (n, 6)) * np.r_[0.05, 0.05, 0.04, 0.15, 0.15, 0.15]
    h = rng.uniform(0.2, 1.0, (n, 6)) * h_max
    return Cells(c, h)


def test_bounds_enclose_the_ik_on_sampled_poses(gd):
    """Every sampled pose of a cell has its IK leg lengths and anchor heights inside the cell's bounds, and the
    bounds are attained within a second-order gap (not vacuous)."""
    rng = np.random.default_rng(1)
    cells = random_cells(rng, gd.home_pose(), 40, np.r_[0.03, 0.03, 0.03, 0.06, 0.06, 0.06])
    b = cell_bounds(gd, cells)
    u = rng.uniform(-1, 1, (40, 3000, 6))
    u[:, :64] = VERTICES.T  # the vertices too
    poses = cells.c[:, None] + u * cells.h[:, None]
    L = leg_lengths(gd, poses)
    z = plate_anchor_heights(gd, poses)
    assert np.all(L <= b.upper[:, None]) and np.all(L >= b.lower[:, None])
    assert np.all(z >= b.z_lower[:, None])
    # tight: the gap to the sampled extremes is within the Taylor remainder plus the lower bound's curvature
    r2 = 0.5 * 0.4 * np.sum(cells.h[:, 3:], 1) ** 2
    assert np.all(b.upper - L.max(1) <= r2[:, None] + 2e-3)


def test_taylor_constant_holds():
    """|R(c+δ)t − R(c)t − Σ δ_j ∂R/∂θ_j t| <= ½ |t| ‖δ‖₁² for random c, δ, t (the derived constant)."""
    rng = np.random.default_rng(2)
    c = rng.uniform(-1, 1, (5000, 3))
    d = rng.uniform(-0.3, 0.3, (5000, 3))
    t = rng.normal(size=(5000, 3))
    for convention in ("utn", "zyx"):
        R, dR = rotation_derivatives(c, convention)
        lin = np.einsum("nij,nj->ni", R, t) + np.einsum("nkij,nj,nk->ni", dR, t, d)
        err = np.linalg.norm(np.einsum("nij,nj->ni", rotation_matrix(c + d, convention), t) - lin, axis=1)
        bound = 0.5 * np.linalg.norm(t, axis=1) * np.sum(np.abs(d), 1) ** 2
        assert np.all(err <= bound)
        assert np.max(err / bound) > 0.2  # and not wildly loose


def test_rounding_is_covered_in_ball_arithmetic(gd):
    """The upper bound recomputed in python-flint's arb balls (rigorous, 200 bits) lies within 1e-12 m of the
    float one, far inside the 1e-9 m widening."""
    flint.ctx.prec = 200
    rng = np.random.default_rng(3)
    cells = random_cells(rng, gd.home_pose(), 3, np.r_[0.02, 0.02, 0.02, 0.05, 0.05, 0.05])
    b = cell_bounds(gd, cells)
    t = gd.top_anchors_per_leg - gd.rotation_centre
    for n in range(3):
        c = [flint.arb(float(v)) for v in cells.c[n]]
        h = [flint.arb(float(v)) for v in cells.h[n] + COVER_PAD * (1 + np.abs(cells.c[n]))]  # as cell_bounds
        sa, ca, sb, cb, sg, cg = c[3].sin(), c[3].cos(), c[4].sin(), c[4].cos(), c[5].sin(), c[5].cos()
        R = flint.arb_mat([[cb * cg + sa * sb * sg, sa * sb * cg - cb * sg, ca * sb], [ca * sg, ca * cg, -sa],
                           [sa * cb * sg - sb * cg, sb * sg + sa * cb * cg, ca * cb]])  # fmt: skip
        Sx = flint.arb_mat([[0, 0, 0], [0, 0, -1], [0, 1, 0]])
        Sy = flint.arb_mat([[0, 0, 1], [0, 0, 0], [-1, 0, 0]])
        Sz = flint.arb_mat([[0, -1, 0], [1, 0, 0], [0, 0, 0]])
        Ry = flint.arb_mat([[cb, 0, sb], [0, 1, 0], [-sb, 0, cb]])
        Rx = flint.arb_mat([[1, 0, 0], [0, ca, -sa], [0, sa, ca]])
        Rz = flint.arb_mat([[cg, -sg, 0], [sg, cg, 0], [0, 0, 1]])
        dR = [Ry * Rx * Sx * Rz, Sy * R, R * Sz]
        for leg in range(6):
            tl = flint.arb_mat([[float(v)] for v in t[leg]])
            q = R * tl
            J = [dR[k] * tl for k in range(3)]
            tn = sum(flint.arb(float(v)) ** 2 for v in t[leg]).sqrt()
            r2 = flint.arb(0.5) * tn * (h[3] + h[4] + h[5]) ** 2
            best = flint.arb(0)
            for s in VERTICES.T:
                v = [c[i] + q[i, 0] - float(gd.base_anchors[leg, i]) + s[i] * h[i] for i in range(3)]
                v = [v[i] + sum(int(s[3 + k]) * h[3 + k] * J[k][i, 0] for k in range(3)) for i in range(3)]
                norm = (v[0] ** 2 + v[1] ** 2 + v[2] ** 2).sqrt()
                best = norm if norm > best else best.union(norm) if norm.overlaps(best) else best
            exact_upper = best + r2
            assert abs(float(exact_upper.mid()) - (b.upper[n, leg] - FP_SLACK)) < 1e-12
            assert float(exact_upper.rad()) < 1e-40


def test_proven_violated_unresolved(gd):
    proven = prove_requirements_box(gd, FIFTH_LO, FIFTH_HI)
    assert proven.status == "proven" and proven.stroke_margin_m > 0
    lo, hi = proven.length_bounds
    assert gd.L_min <= lo and hi <= gd.L_max
    # a quarter of the extents is not inside: the witness is out of stroke by the IK itself
    bad = prove_requirements_box(gd, 1.25 * FIFTH_LO, 1.25 * FIFTH_HI)
    assert bad.status == "violated"
    w = bad.witness
    pose = np.array(w["pose"])
    rel = pose - gd.home_pose()
    assert np.all(rel >= 1.25 * FIFTH_LO - 1e-12) and np.all(rel <= 1.25 * FIFTH_HI + 1e-12)
    L = leg_lengths(gd, pose)
    assert L[w["leg"] - 1] < gd.L_min or L[w["leg"] - 1] > gd.L_max
    few = prove_box(gd, gd.home_pose() + FIFTH_LO, gd.home_pose() + FIFTH_HI, max_cells=10)
    assert few.status == "unresolved" and few.unresolved_count > 0 and few.unresolved_cells


def test_random_poses_never_leave_a_proven_box(gd):
    """A sample of 20 000 uniform poses of the proven box (10⁶ in benchmarks/check_proof_samples.py: the sample
    is cut to keep this test under a second) stays within the stroke and above the base."""
    rng = np.random.default_rng(4)
    poses = gd.home_pose() + FIFTH_LO + rng.random((20_000, 6)) * (FIFTH_HI - FIFTH_LO)
    L = leg_lengths(gd, poses)
    assert np.all((L >= gd.L_min) & (L <= gd.L_max))
    assert np.all(plate_anchor_heights(gd, poses) > 0)


def test_cone_bounds_enclose_sampled_poses(gd):
    """Lower bounds of l·e_z and l·n (n the plate normal) hold at thousands of sampled poses per cell."""
    rng = np.random.default_rng(6)
    cells = random_cells(rng, gd.home_pose(), 30, np.r_[0.03, 0.03, 0.03, 0.08, 0.08, 0.08])
    b = cell_bounds(gd, cells, cones=True)
    poses = cells.c[:, None] + rng.uniform(-1, 1, (30, 3000, 6)) * cells.h[:, None]
    l = leg_vectors(gd, poses)
    n = rotation_matrix(poses[..., 3:])[..., :, 2]
    assert np.all(l[..., 2] >= b.axial_lower[:, None])
    assert np.all(np.einsum("cpli,cpi->cpl", l, n) >= b.normal_lower[:, None])


def test_joint_cone_proven_and_violated(gd):
    """The toolkit's joint angles decide: a cone 5° above the largest angle of 20 000 sampled poses is proven;
    one 2° above it is violated, with a witness pose that workspace.limits confirms: the sample missed the
    worst pose (the sample's 51.3° against the witness's 53.4°), the proof did not."""
    home = gd.home_pose()
    rng = np.random.default_rng(7)
    poses = home + FIFTH_LO + rng.random((20_000, 6)) * (FIFTH_HI - FIFTH_LO)
    m = limit_margins(gd, poses, Limits(stroke=False, base_cone=np.pi, top_cone=np.pi))
    worst = np.pi - min(m["base_joint"][0].min(), m["top_joint"][0].min())  # the largest joint angle sampled
    ok = prove_requirements_box(gd, FIFTH_LO, FIFTH_HI, joint_cone=worst + np.radians(5))
    assert ok.status == "proven"
    bad = prove_requirements_box(gd, FIFTH_LO, FIFTH_HI, joint_cone=worst + np.radians(2))
    assert bad.status == "violated" and "joint beyond its cone" in bad.witness["what"]
    cone = worst + np.radians(2)
    w = limit_margins(gd, np.array(bad.witness["pose"]), Limits(stroke=False, base_cone=cone, top_cone=cone))
    assert min(w["base_joint"][0], w["top_joint"][0]) < 0


def test_clearance_bounds_and_outcomes(gd):
    """The lower bound of the distance between two legs (a separating direction between their hulls over a
    cell) holds at sampled poses (workspace.limits' segment distances); a diameter half the sampled minimum is
    proven, one above the sampled minimum is violated with a witness pair that workspace.limits confirms."""
    rng = np.random.default_rng(9)
    cells = random_cells(rng, gd.home_pose(), 20, np.r_[0.03, 0.03, 0.03, 0.06, 0.06, 0.06])
    b = cell_bounds(gd, cells, clearance=True)
    poses = cells.c[:, None] + rng.uniform(-1, 1, (20, 2000, 6)) * cells.h[:, None]
    d = raw_margins(
        gd, leg_vectors(gd, poses), rotation_matrix(poses[..., 3:]), Limits(stroke=False, leg_diameter=1e-300)
    )
    assert np.all(d["collision"] >= b.clearance_lower[:, None])
    home = gd.home_pose()
    sample = home + FIFTH_LO + rng.random((20_000, 6)) * (FIFTH_HI - FIFTH_LO)
    dmin = limit_margins(gd, sample, Limits(stroke=False, leg_diameter=1e-300))["collision"][0].min()
    assert prove_requirements_box(gd, FIFTH_LO, FIFTH_HI, leg_diameter=0.5 * dmin).status == "proven"
    bad = prove_requirements_box(gd, FIFTH_LO, FIFTH_HI, leg_diameter=1.05 * dmin)
    assert bad.status == "violated" and "closer than the leg diameter" in bad.witness["what"]
    m = limit_margins(gd, np.array(bad.witness["pose"]), Limits(stroke=False, leg_diameter=1.05 * dmin))
    assert m["collision"][0] < 0


# A design optimize chose on seed 001 with 80 mm legs (budget 240): its closest approach between legs over the box is
# 86.9 mm (sampled and locally minimised), at a box vertex, near the base anchors of legs 4 and 5.
CLEAR_X = np.array([0.388285, 0.183480, 0.112583, 0.272872, 0.707668])


def test_clearance_bound_tends_to_the_distance_and_resolves_a_realistic_diameter():
    """The clearance bound converges to the sampled distance as the cell shrinks (the direction between the centre
    pieces' exact closest points has no floor: the old sampled directions left ~11 mm at 2.5 mm cells), holds at
    every sampled pose of those cells, and so an 80 mm leg diameter (7 mm under the closest approach) is proven
    within 20 000 cells, and a diameter 1 % above the closest approach is violated with a witness."""
    req = load_requirements(resources.files("stewart_drake") / "examples" / "seed_001_requirements.yaml")
    p = design_platform(req, CLEAR_X, [0.64, 0.89])
    home = p.home_pose()
    corner = home + np.r_[req.box_lo[:4], req.box_hi[4:]]  # the vertex of the closest approach
    rng = np.random.default_rng(11)
    gaps = []
    for hw in (0.01, 0.005, 0.0025):
        c = corner + np.r_[hw, hw, hw, hw, -hw, -hw]
        b = cell_bounds(p, Cells(c[None], np.full((1, 6), hw)), clearance=True)
        poses = c + rng.uniform(-1, 1, (4000, 6)) * hw
        d = limit_margins(p, poses, Limits(stroke=False, leg_diameter=1e-300))["collision"][0]
        assert d.min() >= b.clearance_lower.min()
        gaps.append(d.min() - b.clearance_lower.min())
    assert gaps[2] < 0.5 * gaps[0] and gaps[2] < 2e-3  # first order in the cell, 1.6 mm at 2.5 mm / 2.5 mrad
    closest = limit_margins(p, corner[None], Limits(stroke=False, leg_diameter=1e-300))["collision"][0][0]
    assert prove_requirements_box(p, req.box_lo, req.box_hi, leg_diameter=0.08, max_cells=20_000).status == "proven"
    bad = prove_requirements_box(p, req.box_lo, req.box_hi, leg_diameter=1.01 * closest, max_cells=20_000)
    assert bad.status == "violated" and "closer than the leg diameter" in bad.witness["what"]
