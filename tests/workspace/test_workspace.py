"""Workspace analysis (seed 001): the paper's limiting legs and mobility count, the numerics checked against
independent computations, the optional limits binding and not, and the sweep's chunking/back ends."""

import json
import math
import re
import tracemalloc

import numpy as np
import pytest

from stewart_drake import workspace as ws
from stewart_drake.cli import main
from stewart_drake.core.kinematics import check_stroke, condition_number, leg_lengths
from stewart_drake.core.rotations import rotation_matrix
from stewart_drake.workspace.slabs import grid_spec, inside_block

W = ws.WorkspaceError

DEG = math.pi / 180


# ---------------------------------------------------------------------------------------------
# The paper's tables: which legs limit each rotation; the Grübler count (the paper's extents, rotation limits
# and leg lengths against its printed numbers: tests/report/test_workspace_paper.py).


def test_rotation_limits_name_the_paper_legs(rot):
    # Tables 1-3: the legs printed at 0.95/0.949 are the ones at L_max.
    assert rot[("x", 1)].at_limit == (3, 4) and rot[("x", -1)].at_limit == (1, 6)
    assert rot[("y", 1)].at_limit == (5,) and rot[("z", 1)].at_limit == (1, 3, 5)
    assert all(r.side == "max" for r in rot.values())
    # the lengths reported are at the limit: the limiting leg sits on L_max to the bisection tolerance
    for r in rot.values():
        assert r.lengths[r.leg - 1] == pytest.approx(0.95, abs=1e-8)


def test_gruebler_paper_count():
    assert ws.gruebler_mobility(14, [3] * 12 + [1] * 6, passive_dofs=6) == 6  # seed 001 eq. (1)
    assert ws.stewart_mobility("UPS")["m"] == 6
    assert ws.stewart_mobility("UPU")["m"] == 0  # a strict U-P-U leg has 5 freedoms
    assert ws.gruebler_mobility(4, [1, 1, 1, 1], space_dof=3) == 1  # planar four-bar
    with pytest.raises(W, match=re.escape(W.LEG_TYPE.format(kind="RSS", valid=", ".join(ws.STEWART_JOINTS)))):
        ws.stewart_mobility("RSS")
    with pytest.raises(W, match=re.escape(W.SPACE_DOF.format(value=4))):
        ws.gruebler_mobility(4, [1], space_dof=4)


# ---------------------------------------------------------------------------------------------
# Numerics against independent computations.


@pytest.mark.parametrize("orientation", [(0, 0, 0), (10 * DEG, -5 * DEG, 20 * DEG)])
def test_grid_classification_equals_leg_lengths(gd, orientation):
    """The grid kernel (translation added to l_i(0)) agrees node by node with kinematics.leg_lengths."""
    rng = np.random.default_rng(1)
    xs, ys, zs = (
        np.sort(rng.uniform(lo, hi, n)) for (lo, hi), n in zip(ws.default_bounds(gd, orientation), (17, 19, 23))
    )
    spec = grid_spec(gd, orientation, "utn", ws.Limits(), (xs, ys, zs))
    inside, _ = inside_block(spec, xs, ys, zs)
    X, Y, Z = np.meshgrid(xs, ys, zs, indexing="ij")
    q = np.stack([X, Y, Z] + [np.full(X.shape, a) for a in orientation], -1)
    expect = check_stroke(gd, leg_lengths(gd, q)).within
    assert inside.any() and not inside.all()
    np.testing.assert_array_equal(inside, expect)


def test_z_extents_closed_form(gd, ws10):
    """At zero orientation the top and bottom of the workspace are on the axis with all six legs at
    L_max / L_min (anchors on circles, z = 0): z = sqrt(L² - ρ²), ρ the legs' common horizontal span."""
    rho = np.linalg.norm(gd.top_anchors_per_leg[:, :2] - gd.base_anchors[:, :2], axis=1)
    assert np.ptp(rho) < 1e-12
    assert ws10.extents[2, 1] == pytest.approx(math.sqrt(gd.L_max**2 - rho[0] ** 2), abs=1e-7)
    assert ws10.extents[2, 0] == pytest.approx(math.sqrt(gd.L_min**2 - rho[0] ** 2), abs=1e-7)


def test_x_extent_against_column_bisection(gd, ws10):
    """x_max independently: bisect on x for 'some column near y = 0 has a reachable z-interval'."""
    ys = np.linspace(-0.02, 0.02, 4001)

    def reachable(x):
        return ws.stroke_column_lengths(gd, x, ys).max() > 0

    lo, hi = 0.3, 0.5
    assert reachable(lo) and not reachable(hi)
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if reachable(mid) else (lo, mid)
    # the y sampling (1e-5 m) can only under-estimate the extreme, by far less than 1e-5 m
    assert ws10.extents[0, 1] == pytest.approx(lo, abs=1e-5)
    assert ws10.extent_error <= ws10.resolution


def test_volume_converges_under_refinement(gd):
    """Three grids: each estimate lies within its bound of the semi-analytic column volume, the bound
    halves with the step (cells on the boundary scale like the surface / h²), the error shrinks."""
    v_col = ws.stroke_volume_columns(gd, 0.002)
    assert ws.stroke_volume_columns(gd, 0.004) == pytest.approx(v_col, rel=1e-3)  # the reference itself converged
    runs = [ws.constant_orientation_workspace(gd, resolution=h, refine=False) for h in (0.02, 0.01, 0.005)]
    for w in runs:
        lo, hi = w.volume_bounds
        assert lo <= v_col <= hi and abs(w.volume - v_col) <= w.volume_error
    ratios = [a.volume_error / b.volume_error for a, b in zip(runs, runs[1:])]
    assert all(1.8 < r < 2.2 for r in ratios), ratios
    errs = [abs(w.volume - v_col) for w in runs]
    # the node count errs on both sides of the boundary and mostly cancels: the actual error is far
    # below the one-sided cell bound (here ~1/200 of it); require 1/50
    assert errs[-1] < errs[0] and errs[-1] < runs[-1].volume_error / 50


def test_volume_tilted_orientation(gd):
    o = (5 * DEG, 0.0, 15 * DEG)
    w = ws.constant_orientation_workspace(gd, o, resolution=0.01, refine=False)
    v_col = ws.stroke_volume_columns(gd, 0.003, o)
    assert abs(w.volume - v_col) <= w.volume_error and abs(w.volume - v_col) < 1e-3 * v_col * 10


def test_inside_outside_just_across_limits(gd, ws10, rot):
    """Poses 1e-7 inside / outside a limit are classified correctly (the margins are smooth, slope ~1)."""
    z_top = ws10.extents[2, 1]
    q = np.array([[0, 0, z_top - 1e-7, 0, 0, 0], [0, 0, z_top + 1e-7, 0, 0, 0]])
    np.testing.assert_array_equal(ws.classify(gd, q), [True, False])
    np.testing.assert_array_equal(check_stroke(gd, leg_lengths(gd, q)).within, [True, False])
    a = rot[("x", -1)].angle
    q = np.tile(gd.home_pose(), (2, 1))
    q[:, 3] = [a + 1e-7, a - 1e-7]
    np.testing.assert_array_equal(ws.classify(gd, q), [True, False])


def test_rotation_about_a_centre(gd):
    """About a centre 0.2 m above the plate, the pivot stays fixed and the lengths are those of that
    rigid motion (computed here from the anchors), and the limits differ from the origin's."""
    c = np.array([0.0, 0.0, 0.2])
    res = ws.orientation_limits(gd, centre=c)
    p_C = gd.home_pose()[:3] + c
    for r in res:
        k = ws.AXES.index(r.axis)
        R = rotation_matrix(np.eye(3)[k] * r.angle)
        anchors = p_C + (gd.top_anchors_per_leg - c) @ R.T
        np.testing.assert_allclose(r.lengths, np.linalg.norm(anchors - gd.base_anchors, axis=1), atol=1e-12)
        assert np.isclose(r.lengths, gd.L_max, atol=1e-8).any() or np.isclose(r.lengths, gd.L_min, atol=1e-8).any()
    about_origin = ws.orientation_limits(gd)
    assert abs(res[0].angle - about_origin[0].angle) > 1 * DEG  # about X: a higher pivot swings the plate
    assert res[4].angle == pytest.approx(about_origin[4].angle, abs=1e-9)  # about Z: the axis is the same line


def test_rotation_limit_not_reached_within_max_angle(gd):
    res = ws.orientation_limits(gd, max_angle=10 * DEG)
    assert not any(r.reached for r in res) and all(r.limit is None for r in res)
    np.testing.assert_allclose([r.angle for r in res], np.array([1, -1] * 3) * 10 * DEG, atol=1e-15)


def test_segment_distance_against_sampling():
    rng = np.random.default_rng(7)
    P1, Q1, P2, Q2 = rng.normal(size=(4, 60, 3))
    Q2[:10] = P2[:10] + 2.0 * (Q1[:10] - P1[:10])  # parallel pairs
    d = ws.segment_distances(P1, Q1, P2, Q2)
    n = 401
    s = np.linspace(0, 1, n)[:, None]
    for k in range(len(d)):
        A, B = P1[k] + s * (Q1[k] - P1[k]), P2[k] + s * (Q2[k] - P2[k])
        brute = np.linalg.norm(A[:, None] - B[None], axis=-1).min()
        # the nearest samples are at most half a sample step from the true closest points
        slack = (np.linalg.norm(Q1[k] - P1[k]) + np.linalg.norm(Q2[k] - P2[k])) / (2 * (n - 1))
        assert d[k] <= brute + 1e-12 and brute - d[k] <= slack, k
    # crossing segments touch
    assert ws.segment_distances([0, 0, 0], [1, 1, 0], [1, 0, 0], [0, 1, 0]) == pytest.approx(0.0, abs=1e-15)


# ---------------------------------------------------------------------------------------------
# The optional limits: each with a case where it binds and one where it does not.


def test_joint_limit_binds_and_not(gd, ws10, rot):
    # at home every leg leans arccos(z / L) from the base and plate normals
    lean = math.acos(gd.home_height / 0.75)
    m = ws.limit_margins(gd, gd.home_pose(), ws.Limits(base_cone=40 * DEG, top_cone=40 * DEG))
    assert m["base_joint"][0] == pytest.approx(40 * DEG - lean, abs=1e-12)
    assert m["top_joint"][0] == pytest.approx(40 * DEG - lean, abs=1e-12)
    tight = ws.Limits(base_cone=40 * DEG, top_cone=40 * DEG)
    w = ws.constant_orientation_workspace(gd, resolution=0.01, limits=tight)
    assert set(w.binding) == {"base_joint", "top_joint"} and w.volume < 0.5 * ws10.volume
    r = {(x.axis, x.sign): x for x in ws.orientation_limits(gd, limits=tight)}
    assert r[("x", 1)].limit == "top_joint" and r[("z", 1)].limit == "base_joint"
    assert abs(r[("x", 1)].angle) < abs(rot[("x", 1)].angle)
    loose = ws.Limits(base_cone=80 * DEG, top_cone=80 * DEG)
    w = ws.constant_orientation_workspace(gd, resolution=0.01, limits=loose)
    assert w.binding == [] and w.volume == ws10.volume
    r = ws.orientation_limits(gd, limits=loose)
    assert all(x.limit == "stroke" for x in r) and r[0].angle == pytest.approx(rot[("x", 1)].angle, abs=1e-9)


def test_collision_limit_binds_and_not(gd, ws10, rot):
    thin = ws.constant_orientation_workspace(gd, resolution=0.01, limits=ws.Limits(leg_diameter=0.10))
    assert thin.binding == [] and thin.volume == ws10.volume
    thick = ws.constant_orientation_workspace(gd, resolution=0.01, limits=ws.Limits(leg_diameter=0.145))
    assert thick.binding == ["collision"] and thick.volume < ws10.volume
    assert thick.removed_m3["collision"] == pytest.approx(ws10.volume - thick.volume)
    # rotating about Z brings legs to within 149.7 mm of each other before the stroke ends (47.4°)
    r = {(x.axis, x.sign): x for x in ws.orientation_limits(gd, limits=ws.Limits(leg_diameter=0.1505))}
    assert r[("z", 1)].limit == "collision" and r[("z", 1)].pair is not None
    assert abs(r[("z", 1)].angle) < abs(rot[("z", 1)].angle)
    assert r[("x", 1)].limit == "stroke"


def test_dexterity_limit_and_map(gd, ws10):
    u, v, kappa = ws.dexterity_map(gd, resolution=0.02)
    i, j = np.argwhere(np.isfinite(kappa))[5]
    q = np.r_[u[i], v[j], gd.home_height, 0, 0, 0]
    assert kappa[i, j] == pytest.approx(condition_number(gd, q), rel=1e-12)
    assert np.isnan(kappa[0, 0])  # the corner of the square is outside the workspace
    loose = ws.constant_orientation_workspace(gd, resolution=0.01, limits=ws.Limits(max_condition=100))
    assert loose.binding == [] and loose.volume == ws10.volume
    tight = ws.constant_orientation_workspace(gd, resolution=0.01, limits=ws.Limits(max_condition=3.0))
    assert tight.binding == ["dexterity"] and tight.volume < ws10.volume


# ---------------------------------------------------------------------------------------------
# The sweep: chunking, bounded memory, back ends, 6-D sweep.


def _same(a, b):
    assert a.inside_nodes == b.inside_nodes and a.volume_bounds == b.volume_bounds
    for k in ("top", "front", "side"):
        np.testing.assert_array_equal(getattr(a, k), getattr(b, k))
    assert sorted(map(tuple, a.boundary)) == sorted(map(tuple, b.boundary))
    np.testing.assert_allclose(a.extents, b.extents, atol=1e-9)


def test_chunking_does_not_change_the_result(gd, ws10):
    small = ws.constant_orientation_workspace(gd, resolution=0.01, chunk_nodes=1000)  # one plane per slab
    _same(small, ws10)
    lim = ws.Limits(base_cone=40 * DEG, top_cone=40 * DEG)
    a = ws.constant_orientation_workspace(gd, resolution=0.02, limits=lim, chunk_nodes=1000)
    b = ws.constant_orientation_workspace(gd, resolution=0.02, limits=lim, chunk_nodes=1 << 24)
    _same(a, b)
    assert a.removed_m3 == b.removed_m3


def test_memory_is_bounded_by_the_chunk(gd):
    def peak(chunk):
        tracemalloc.start()
        ws.constant_orientation_workspace(gd, resolution=0.008, chunk_nodes=chunk, refine=False)
        _, p = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        return p

    big, small = peak(1 << 24), peak(1 << 15)
    assert small < big / 4, (small, big)


def test_process_pool_gives_the_same_result(gd):
    a = ws.constant_orientation_workspace(gd, resolution=0.02, chunk_nodes=20000)
    b = ws.constant_orientation_workspace(gd, resolution=0.02, chunk_nodes=20000, workers=2)
    _same(a, b)


def test_count_reachable_matches_brute_force(gd):
    h = gd.home_pose()
    grids = [
        np.linspace(-0.2, 0.2, 5),
        np.linspace(-0.2, 0.2, 4),
        h[2] + np.linspace(-0.2, 0.2, 3),
        np.linspace(-30, 30, 3) * DEG,
        np.linspace(-30, 30, 4) * DEG,
        np.linspace(-40, 40, 5) * DEG,
    ]
    res = ws.count_reachable(gd, grids, chunk=97)
    mesh = np.stack(np.meshgrid(*grids, indexing="ij"), -1)
    inside = ws.classify(gd, mesh)
    assert res["total"] == inside.size and res["count"] == int(inside.sum()) and 0 < res["count"] < res["total"]
    for k in range(6):
        np.testing.assert_array_equal(res["marginals"][k], inside.sum(axis=tuple(j for j in range(6) if j != k)))


def test_dask_local_cluster_same_result(gd, ws10):
    pytest.importorskip(
        "distributed", reason='the Dask back end needs dask.distributed (pip install "dask[distributed]")'
    )
    from stewart_drake.workspace.dask_sweep import (
        close_client,
        count_reachable_on_dask,
        local_client,
        map_platforms,
        workspace_on_dask,
    )

    client = local_client(n_workers=2)
    try:
        w = workspace_on_dask(gd, client=client, resolution=0.01, chunk_nodes=100_000)
        _same(w, ws10)
        grids = (
            [np.linspace(-0.1, 0.1, 3)] * 2
            + [gd.home_height + np.linspace(-0.1, 0.1, 3)]
            + [np.linspace(-0.3, 0.3, 3)] * 3
        )
        assert (
            count_reachable_on_dask(gd, grids, client=client, chunk=100)["count"]
            == ws.count_reachable(gd, grids)["count"]
        )
        vols = map_platforms(
            ws.stroke_volume_columns, [gd, gd.replace(stroke=np.array([0.5, 0.95]))], client, resolution=0.01
        )
        assert vols[0] == pytest.approx(ws.stroke_volume_columns(gd, 0.01)) and vols[1] > vols[0]
    finally:
        close_client(client)


# ---------------------------------------------------------------------------------------------
# Bad input: clear errors naming the thing and the value.


def test_errors(gd):
    with pytest.raises(W, match=re.escape(W.RESOLUTION.format(value=-0.01))):
        ws.constant_orientation_workspace(gd, resolution=-0.01)
    with pytest.raises(
        ws.WorkspaceError,
        match=r"resolution 1e-06 m would need .* grid nodes .*; the finest this machine can hold is ~.* mm; use a coarser resolution",
    ):
        ws.constant_orientation_workspace(gd, resolution=1e-6)
    with pytest.raises(W, match=re.escape(W.ORIENTATION.format(value=[0.0, 0.0]))):
        ws.constant_orientation_workspace(gd, orientation=(0.0, 0.0))
    with pytest.raises(W, match=re.escape(W.CONE.format(name="base_cone", value=-1.0))):
        ws.Limits(base_cone=-1.0)
    with pytest.raises(W, match=re.escape(W.LEG_DIAMETER.format(value=0.0))):
        ws.Limits(leg_diameter=0.0)
    start = W.START_OUTSIDE.format(pose=[0.0, 0.0, 0.3, 0.0, 0.0, 0.0], limit="stroke", margin=-0.06348, unit="m")
    with pytest.raises(W, match=re.escape(start)):
        ws.orientation_limits(gd, position=[0.0, 0.0, 0.3])
    with pytest.raises(ws.WorkspaceError, match="no reachable position .* 'base_joint'"):
        ws.constant_orientation_workspace(gd, resolution=0.02, limits=ws.Limits(base_cone=10 * DEG))
    with pytest.raises(W, match=re.escape(W.GRIDS.format(n=5))):
        ws.count_reachable(gd, [np.zeros(2)] * 5)
    with pytest.raises(W, match=re.escape(W.EXECUTOR.format(kind="object"))):
        ws.constant_orientation_workspace(gd, resolution=0.05, executor=object())


# ---------------------------------------------------------------------------------------------
# CLI.


def test_cli_limits_and_out(capsys, tmp_path):
    rc = main(
        [
            "workspace",
            "--resolution",
            "0.02",
            "--limits",
            "stroke,joints,collision",
            "--joint-cone",
            "40",
            "--leg-diameter",
            "0.145",
            "--orientation",
            "0",
            "0",
            "10",
            "--out",
            str(tmp_path / "o"),
        ]
    )
    out = capsys.readouterr().out
    assert rc == 0 and "base_joint limit binds" in out and "collision limit binds" in out
    for f in ("workspace.json", "boundary.csv", "top.png", "front.png", "side.png", "3d.png"):
        assert (tmp_path / "o" / f).stat().st_size > 100
    saved = json.loads((tmp_path / "o" / "workspace.json").read_text())
    assert saved["orientation_deg"] == [0.0, 0.0, 10.0] and "collision" in saved["binding_limits"]


def test_cli_bad_limit(capsys):
    assert main(["workspace", "--limits", "stroke,wind"]) == 2
    assert "unknown limit 'wind'" in capsys.readouterr().err
