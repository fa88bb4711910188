"""Complete forward kinematics by parameter homotopy (``stewart_drake.homotopy``), checked against the
multi-start search (``forward.assembly_modes``) and Drake's MathematicalProgram (``forward.ProgramFK``)."""

import importlib

import numpy as np
import pytest

from stewart_drake.core.assembly_modes import assembly_modes
from stewart_drake.core.geometry import load_platform_yaml, load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.reference_platforms import dietmaier_platform, planar_platform
from stewart_drake.core.rotations import rotation_matrix
from stewart_drake.drake.program_fk import ProgramFK
from stewart_drake.homotopy import architecture, ctrack, solve, solve_batch
from stewart_drake.homotopy.certify import certify, newton_real, real_forms
from stewart_drake.homotopy.solve import _classify
from stewart_drake.homotopy.start import load_start_system, monodromy_solve
from stewart_drake.homotopy.study import (
    evaluate,
    hessian_forms,
    leg_matrices,
    pose_from_study,
    study_from_pose,
    study_parameters,
)
from stewart_drake.homotopy.track import DONE, STALLED, TrackOptions, track

# Two solvers agree on a mode when positions and rotation matrices agree to this: both are
# Newton-polished to ~1e-15 m leg residual, and the modes are well separated (min distance ~1e-2).
SAME_MODE = 1e-8
solve_module = importlib.import_module("stewart_drake.homotopy.solve")  # the package's ``solve`` is the function


def _key(modes):
    return np.array([np.r_[m.position, m.rotation.ravel()] for m in modes]).reshape(-1, 12)


def _same_sets(hom_modes, ms_modes):
    A, B = _key(hom_modes), _key(ms_modes)
    if len(A) != len(B):
        return False
    d = np.abs(A[:, None] - B[None]).max(-1)
    return bool(np.all(d.min(1) < SAME_MODE) and np.all(d.min(0) < SAME_MODE))


def _check_against_multistart(platform, L, r):
    """complete, every real solution certified, the real set equal to the multi-start's."""
    assert r.complete, r.guarantee
    assert sum(r.counts().values()) == r.max_solutions
    assert all(m.certified for m in r.modes)
    assert all(m.residual < 1e-12 for m in r.modes)  # m; the legs of every mode have the given lengths
    ms = assembly_modes(platform, L, polish=None)
    assert _same_sets(r.modes, ms.modes), (len(r.modes), len(ms))


def test_study_system_is_the_leg_equations():
    """At a pose built by inverse kinematics the Study system vanishes; its Jacobian matches central
    differences (step 1e-6: error ~1e-12 for a quadratic); the quadratic forms give the same values."""
    p = load_preset("gonzalez-dutra-2009")
    q = p.home_pose() + [0.02, -0.01, 0.03, 0.1, -0.2, 0.15]
    L = leg_lengths(p, q)
    arch = architecture(p)
    a, b, s, k = study_parameters(p, L, arch)
    x = study_from_pose(q[None, :3], rotation_matrix(q[3:], "utn")[None], k, arch.kind)
    v = np.random.default_rng(0).normal(size=8)
    x = x / (x @ v)
    B = leg_matrices(a, b)
    F, J = evaluate(x, B[None], s[None], v)
    assert np.abs(F).max() < 1e-14
    h = 1e-6
    Jn = np.stack(
        [
            (
                evaluate(x + h * np.eye(8)[j], B[None], s[None], v)[0]
                - evaluate(x - h * np.eye(8)[j], B[None], s[None], v)[0]
            )[0]
            / (2 * h)
            for j in range(8)
        ],
        1,
    )
    np.testing.assert_allclose(Jn, J[0], atol=1e-9)
    xr = np.random.default_rng(1).normal(size=8)
    Fr, _ = evaluate(xr[None], B[None], s[None], v)
    Q = hessian_forms(B, s)
    np.testing.assert_allclose(np.einsum("j,ijk,k->i", xr, Q, xr), Fr[0, :7], rtol=1e-12, atol=1e-12)
    p_BC, R_BT = pose_from_study(x, k, arch.kind)
    np.testing.assert_allclose(p_BC[0], q[:3], atol=1e-14)
    np.testing.assert_allclose(R_BT[0], rotation_matrix(q[3:], "utn"), atol=1e-14)


@pytest.mark.parametrize("kind, count", [("6-6", 40), ("3-6", 16)])
def test_shipped_start_systems(kind, count):
    """The shipped start systems hold the class's root count of distinct solutions, residual at rounding."""
    S = load_start_system(kind)
    assert len(S.x) == count
    assert S.residual() < 1e-12
    d = np.linalg.norm(S.x[:, None] - S.x[None], axis=-1) + np.eye(count)
    assert d.min() > 1e-3


def test_monodromy_regenerates_a_start_system():
    """A fresh monodromy solve (another seed) of the 3-6 class finds 16 solutions; tracking the shipped
    start system's 16 solutions to the fresh parameters reaches exactly those 16 (two independent
    computations of the same solution set)."""
    fresh = monodromy_solve("3-6", seed=7)
    assert len(fresh.x) == 16 and fresh.residual() < 1e-12
    S = load_start_system("3-6")
    paths = track(S.x, S.B, fresh.B, S.s, fresh.s, S.v, np.exp(0.7j))

    # Different charts: compare as projective points (normalise e·e = 1 up to sign).
    def norm(x):
        y = x / np.sqrt(np.einsum("kj,kj->k", x[:, :4], x[:, :4]))[:, None]
        return y * np.sign(y[np.arange(len(y)), np.argmax(np.abs(y[:, :4]), 1)].real)[:, None]

    A, B = norm(paths.x), norm(fresh.x)
    d = np.linalg.norm(A[:, None] - B[None], axis=-1)
    assert np.all(d.min(1) < 1e-8) and np.all(d.min(0) < 1e-8)


def test_dietmaier_40_real_certified_and_confirmed_by_drake():
    """Dietmaier's platform: 40 paths, 40 real, complete, all certified; equal to the multi-start's 40;
    Drake's MathematicalProgram (IPOPT; SNOPT at the 1e-12 feasibility tolerance sometimes stops with a
    solver-specific error a few 1e-8 m short) started 1e-3 away from each of five of them returns to it
    within its own tolerance (an independent formulation and solver)."""
    p, L = dietmaier_platform()
    r = solve(p, L)
    assert r.kind == "6-6" and r.counts()["real"] == 40
    _check_against_multistart(p, L, r)
    prog = ProgramFK(p, "quaternion", "ipopt")
    for m in r.modes[::8]:
        sol = prog.solve(L, m.position + 1e-3, initial_rotation=m.rotation)
        assert sol.success and sol.residual < 1e-9
        np.testing.assert_allclose(sol.position, m.position, atol=1e-7)


@pytest.mark.parametrize("seed", range(20))
def test_random_planar_6_6_complete(seed):
    """Random planar 6-6 platforms (seeded): complete, certified, equal to the multi-start."""
    p, L = planar_platform(seed)
    r = solve(p, L)
    assert r.kind == "6-6"
    _check_against_multistart(p, L, r)


@pytest.mark.parametrize("name, kind, n_inf", [("gonzalez-dutra-2009", "6-6", 12), ("utn-dynamic", "3-6", 0)])
def test_presets_at_three_poses_batched(name, kind, n_inf):
    """Three poses in one batch: the 3-fold-symmetric 6-6 sends 12 of 40 paths to infinity, the 3-6
    uses the 16-path start system; complete, certified, equal to the multi-start; the batch equals
    the one-at-a-time solve."""
    p = load_preset(name)
    rng = np.random.default_rng(5)
    q = p.home_pose() + np.c_[rng.uniform(-0.05, 0.05, (3, 3)), rng.uniform(-0.2, 0.2, (3, 3))]
    L = leg_lengths(p, q)
    rs = solve_batch(p, L)
    for Lj, r, qj in zip(L, rs, q):
        assert r.kind == kind and r.max_solutions == {"6-6": 40, "3-6": 16}[kind]
        assert r.counts()["infinity"] == n_inf
        _check_against_multistart(p, Lj, r)
        assert np.min([np.abs(m.position - qj[:3]).max() for m in r.modes]) < 1e-12  # the IK pose is among them
    one = solve(p, L[1])
    assert _same_sets(one.modes, rs[1].modes)
    direct = solve(p, L[2], two_stage=False)  # straight from the shipped start system: same modes
    assert direct.stage == "direct" and direct.n_paths == direct.max_solutions and direct.complete
    assert direct.counts()["infinity"] == n_inf and _same_sets(direct.modes, rs[2].modes)


@pytest.mark.parametrize("engine", ["c", "numpy"])
def test_perturbed_path_is_reported_incomplete(engine):
    """Capping one path at 3 steps (in every attempt) makes it fail: the result is not complete and
    names that path; the other paths are still classified (both tracker implementations)."""
    p, L = dietmaier_platform()
    r = solve(p, L, path_max_steps={17: 3}, options=TrackOptions(engine=engine))
    assert r.engine == engine
    assert not r.complete
    assert r.failed_paths == [17] and r.classes[17] == "failed"
    assert "17" in r.guarantee and "failed" in r.guarantee
    assert r.counts()["real"] == 39


def test_certificate_radius_contains_the_solution():
    """Perturb a certified solution by 1e-10 (Dietmaier's modes are ill-conditioned: K up to ~1e5, so
    the test needs K·b < 1/4): it is still certified and the radius covers the distance to the original
    (the exact zero up to rounding); perturbed by 1e-1 it is not certified;
    the uniqueness radius separates the solution from every other mode."""
    p, L = dietmaier_platform()
    arch = architecture(p)
    a, b, s, k = study_parameters(p, L, arch)
    Q, c = real_forms(hessian_forms(leg_matrices(a, b), s))
    r = solve(p, L)
    X = study_from_pose(np.array([m.position for m in r.modes]), np.array([m.rotation for m in r.modes]), k, arch.kind)
    X = newton_real(X, Q, c)
    direction = np.random.default_rng(3).normal(size=8)
    direction /= np.linalg.norm(direction)
    near = certify(X + 1e-10 * direction, Q, c)
    assert near.certified.all()
    assert np.all(near.radius >= 1e-10 * (1 - 1e-6)) and np.all(near.radius < 1e-5)
    far = certify(X + 1e-1 * direction, Q, c)
    assert not far.certified.any()
    exact = certify(X, Q, c)
    D = np.linalg.norm(X[:, None] - X[None], axis=-1) + np.eye(len(X)) * 1e9
    assert np.all(exact.uniqueness < D.min(1) + exact.radius)


def test_explicit_yaml_3_6_is_classified(tmp_path):
    """An explicit-anchor YAML platform whose legs share plate anchors in pairs is solved as 3-6 (16
    paths), complete and certified."""
    f = tmp_path / "p.yaml"
    f.write_text(
        "name: explicit-3-6\nlength_unit: m\n"
        "base_anchors: [[0.5, 0.1, 0.0], [0.4, 0.35, 0.02], [-0.2, 0.5, 0.0], [-0.45, 0.2, -0.03], [-0.3, -0.4, 0.0], [0.25, -0.45, 0.01]]\n"
        "top_anchors: [[0.2, 0.05, 0.0], [-0.1, 0.2, 0.01], [-0.1, -0.2, -0.02]]\n"
        "leg_top: [0, 0, 1, 1, 2, 2]\nstroke: [0.4, 1.2]\nhome_height: 0.7\n"
    )
    p = load_platform_yaml(f)
    assert architecture(p).kind == "3-6"
    L = leg_lengths(p, p.home_pose() + [0.02, -0.01, 0.03, 0.1, 0.05, -0.1])
    r = solve(p, L)
    assert r.max_solutions == 16
    _check_against_multistart(p, L, r)


def test_branch_distance_matches_the_multistart_modes():
    """Branch safety along a short tilt of utn-dynamic: at each sample the distance to the nearest
    other mode equals the one computed from the multi-start's modes at the same lengths (second
    method); the sampled pose is always found among the certified modes."""
    from stewart_drake.core.newton_fk import anchor_scale
    from stewart_drake.homotopy.branches import branch_safety

    p = load_preset("utn-dynamic")
    t = np.linspace(0, 1, 4)
    q = p.home_pose() + np.outer(t, [0.03, -0.02, 0.05, 0.2, 0.1, 0.3])
    rep = branch_safety(p, t, q, "utn", samples=4)
    assert rep.complete.all() and rep.on_mode.all()
    r_a = anchor_scale(p)
    for k in range(4):
        am = assembly_modes(p, leg_lengths(p, q[k]), polish=None)
        R_q = rotation_matrix(q[k, 3:], "utn")
        d = [
            np.sqrt(
                np.sum((m.position - q[k, :3]) ** 2)
                + (r_a * np.arccos(np.clip((np.trace(m.rotation.T @ R_q) - 1) / 2, -1, 1))) ** 2
            )
            for m in am.modes
        ]
        d = np.sort(d)
        assert d[0] < 1e-9  # the pose itself
        assert rep.branch_distance[k] == pytest.approx(d[1], abs=1e-9)


def test_run_check_branches_cli(tmp_path, capsys):
    """``run --check-branches``: safe with the default margins on the circle example (exit 0, JSON
    summary), exit 1 with a one-line reason when the margin is above the measured distance, exit 2 on a
    negative margin or a branch option without --check-branches (nothing written)."""
    import json
    from pathlib import Path

    from stewart_drake.cli import main

    prog = str(Path(__file__).resolve().parents[2] / "examples" / "circle.stw")
    args = ["run", prog, "--platform", "utn-kinematic", "--check-branches", "--branch-samples", "5", "--json"]
    assert main(args + ["--out", str(tmp_path / "a")]) == 0
    b = json.loads(capsys.readouterr().out)["branches"]
    assert b["safe"] and b["all_complete"] and b["samples_checked"] == 5 and b["modes_min"] >= 2
    margin_mm = b["min_branch_distance_m"] * 1e3 * 1.01
    assert main(args + ["--out", str(tmp_path / "b"), "--branch-margin", str(margin_mm)]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "not branch-safe" in err[0] and "nearest other assembly mode" in err[0]
    assert main(args + ["--out", str(tmp_path / "c"), "--branch-margin", "-1"]) == 2
    assert "--branch-margin" in capsys.readouterr().err
    assert (
        main(["run", prog, "--platform", "utn-kinematic", "--out", str(tmp_path / "d"), "--branch-samples", "5"]) == 2
    )
    assert "--branch-samples needs --check-branches" in capsys.readouterr().err
    assert not (tmp_path / "d").exists()


def test_six_three_is_the_inverse_motion():
    """6-3 (base joints shared in pairs): the solver classifies it and solves it as the inverse 3-6
    motion: utn-dynamic's plate anchors become the base anchors (three joints, each shared by two legs)
    and vice versa; its modes must be the inverses (R → Rᵀ, p → −Rᵀ p) of the 3-6 platform's, all
    certified."""
    from types import SimpleNamespace

    from stewart_drake.core.geometry import Platform

    p = load_preset("utn-dynamic")
    q = p.home_pose() + [0.02, -0.01, 0.03, 0.1, 0.05, -0.1]
    L = leg_lengths(p, q)
    inv = Platform(
        name="utn-dynamic-inverse",
        base_anchors=p.top_anchors_per_leg - p.rotation_centre,
        top_anchors=p.base_anchors,
        leg_top=np.arange(6),
        stroke=p.stroke,
        mass=0.0,
        com=np.zeros(3),
        inertia=np.zeros((3, 3)),
        home_height=p.home_height,
    )
    assert architecture(inv).kind == "6-3"
    r63, r36 = solve(inv, L), solve(p, L)
    assert r63.complete and r63.max_solutions == 16 and all(m.certified for m in r63.modes)
    flipped = [SimpleNamespace(position=-m.rotation.T @ m.position, rotation=m.rotation.T) for m in r36.modes]
    assert _same_sets(r63.modes, flipped)
    assert max(m.residual for m in r63.modes) < 1e-12


def test_fk_all_cli_reports_paths_and_certificates(capsys):
    """``fk --all --json`` on the symmetric 6-6: path counts (12 at infinity) summing to max_solutions,
    complete with its guarantee, every solution certified with a radius; ``--method multi-start``
    finds the same poses. Lengths a thousand times too short: no real mode, proven (exit 1)."""
    import json

    from stewart_drake.cli import main

    p = load_preset("gonzalez-dutra-2009")
    L = leg_lengths(p, p.home_pose() + [0.02, -0.01, 0.01, 0.1, -0.05, 0.2])
    base = [
        "fk",
        "--platform",
        "gonzalez-dutra-2009",
        "--length-unit",
        "m",
        "--lengths",
        *(repr(float(v)) for v in L),
        "--all",
        "--json",
    ]
    assert main(base) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["method"] == "homotopy" and d["architecture"] == "6-6" and d["complete"]
    assert d["paths"]["infinity"] == 12 and sum(d["paths"].values()) == d["max_solutions"] == 40
    assert d["paths"]["real"] == len(d["solutions"]) and "probability one" in d["guarantee"]
    assert all(s["certified"] and 0 < s["certified_radius"] < 1e-6 < s["uniqueness_radius"] for s in d["solutions"])
    assert main(base + ["--method", "multi-start"]) == 0
    m = json.loads(capsys.readouterr().out)
    assert m["method"] == "multi-start"
    np.testing.assert_allclose(
        np.sort(np.array([s["pose"] for s in m["solutions"]]), 0),
        np.sort(np.array([s["pose"] for s in d["solutions"]]), 0),
        atol=1e-9,
    )
    short = [
        "fk",
        "--platform",
        "gonzalez-dutra-2009",
        "--length-unit",
        "mm",
        "--lengths",
        *(repr(float(v)) for v in L),
        "--all",
    ]
    assert main(short) == 1
    err = capsys.readouterr().err
    assert "no real assembly mode" in err and "cannot be assembled" in err


@pytest.mark.parametrize("name", ["dietmaier", "gonzalez-dutra-2009", "utn-dynamic"])
def test_compiled_tracker_matches_numpy(name):
    """The compiled tracker (track.c) and the numpy reference run the same algorithm: from the shipped
    start system to the platform (Dietmaier: 40 real; symmetric 6-6: 12 paths to infinity; 3-6), every
    path ends in the same state, and the paths that reached t = 1 end at the same point. Tolerance
    1e-9 relative: both end points are Newton-refined roots, so they differ by rounding (1e-16) times
    the root's condition number (below 1e5 here, Dietmaier's being the worst). The stalled paths
    approach a root at infinity, where the Jacobian is singular and the iterates are not determined
    to rounding: both must be classified at infinity."""
    if name == "dietmaier":
        p, L = dietmaier_platform()
    else:
        p = load_preset(name)
        L = leg_lengths(p, p.home_pose() + [0.01, 0.02, -0.01, 0.1, 0.05, -0.1])
    arch = architecture(p)
    a, b, s, _ = study_parameters(p, L, arch)
    B1 = leg_matrices(a, b)
    S = load_start_system(arch.kind)
    paths = {e: track(S.x, S.B, B1, S.s, s[None], S.v, np.exp(0.3j), TrackOptions(engine=e)) for e in ("c", "numpy")}
    c, ref = paths["c"], paths["numpy"]
    np.testing.assert_array_equal(c.state, ref.state)
    done = ref.state == DONE
    assert done.sum() == {"dietmaier": 40, "gonzalez-dutra-2009": 28, "utn-dynamic": 16}[name]
    rel = np.abs(c.x - ref.x).max(1) / np.abs(ref.x).max(1)
    assert rel[done].max() < 1e-9
    stalled = ref.state == STALLED
    for P in (c, ref):
        cls, _ = _classify(P, B1, np.broadcast_to(s, (len(S.x), 6)), S.v)
        assert np.all(cls[stalled] == "infinity")


def test_tracker_falls_back_to_numpy_without_a_compiler(monkeypatch, tmp_path):
    """Without a C compiler ($STEWART_DRAKE_CC naming a program that does not exist) and no compiled
    tracker in the (empty) build cache, "auto" tracks with numpy and gives the compiled tracker's
    result, and "c" says there is no compiler; an unknown engine name is refused."""
    from stewart_drake.system.c_build import CompilerUnavailable

    p = load_preset("utn-dynamic")
    L = leg_lengths(p, p.home_pose() + [0.01, 0.02, -0.01, 0.1, 0.05, -0.1])
    compiled = solve(p, L, options=TrackOptions(engine="c"))
    monkeypatch.setenv("STEWART_DRAKE_CC", "/nonexistent/cc")
    monkeypatch.setenv("STEWART_DRAKE_CACHE", str(tmp_path))
    monkeypatch.setattr(ctrack, "_LIB", [])
    monkeypatch.setattr(solve_module, "_PLATFORM_STARTS", {})  # stage one redone (and then forgotten) with numpy
    fallback = solve(p, L, options=TrackOptions(engine="auto"))
    assert fallback.engine == "numpy" and compiled.engine == "c" and fallback.complete
    assert _same_sets(fallback.modes, compiled.modes)
    with pytest.raises(CompilerUnavailable):
        solve(p, L, options=TrackOptions(engine="c"))
    with pytest.raises(ValueError, match="engine"):
        solve(p, L, options=TrackOptions(engine="fortran"))


def test_duplicate_end_points_are_found():
    """Two end points that are the same pose (equal, or negatives: x and −x are one Study point) closer
    than DISTINCT_TOL in the max-norm are reported, both of them; points just farther apart are not.
    Checked against the plain all-pairs comparison on random sets."""
    from stewart_drake.homotopy.solve import DISTINCT_TOL, _duplicates

    rng = np.random.default_rng(11)
    for trial in range(50):
        y = rng.normal(size=(40, 8)) + 1j * rng.normal(size=(40, 8))
        for _ in range(trial % 4):
            a, b = rng.choice(40, 2, replace=False)
            y[b] = rng.choice([-1, 1]) * y[a] + rng.uniform(0, 2 * DISTINCT_TOL) * rng.normal(size=8)
        idx = np.arange(40)[::-1]
        z = y[idx]
        d = np.minimum(np.abs(z[:, None] - z[None]).max(-1), np.abs(z[:, None] + z[None]).max(-1)) + np.diag(
            np.full(40, np.inf)
        )
        expected = sorted(
            int(i) for i in idx[np.any(d <= DISTINCT_TOL * np.maximum(1, np.abs(z).max(-1))[:, None], axis=1)]
        )
        assert _duplicates(y, idx) == expected
    y[7] = -y[3]
    assert {3, 7} <= set(_duplicates(y, np.arange(40)))
