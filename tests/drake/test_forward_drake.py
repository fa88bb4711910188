"""Drake MathematicalProgram forward kinematics (``drake/program_fk``) and the assembly-mode
search it polishes and certifies (``core/assembly_modes`` through ``drake/program_fk.assembly_modes``)."""

import numpy as np
import pytest

from stewart_drake.core.assembly_modes import is_planar, max_solutions
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths, plate_anchors
from stewart_drake.core.reference_platforms import dietmaier_platform
from stewart_drake.drake.program_fk import ProgramFK, assembly_modes
from stewart_drake.errors import ForwardKinematicsError

MIRROR = np.array([1, 1, -1])


def _mirror_pose_key(m):
    """(p, R) of the mirror image about the base plane: p -> M p, R -> M R M."""
    return m.position * MIRROR, m.rotation * MIRROR[:, None] * MIRROR[None, :]


def _contains(modes, p, R, tol=1e-9):
    return any(np.abs(m.position - p).max() < tol and np.abs(m.rotation - R).max() < tol for m in modes)


@pytest.mark.parametrize("rotation", ["quaternion", "matrix"])
@pytest.mark.parametrize("solver", ["snopt", "ipopt"])
def test_program_recovers_pose(rotation, solver):
    """From a guess 2 cm / 0.1 rad off, the program returns the pose whose IK gave the lengths;
    SNOPT/IPOPT feasibility tolerance 1e-12 m² on squared lengths -> ~1e-12 m; pose to 1e-9."""
    p = load_preset("gonzalez-dutra-2009")
    q = p.home_pose() + [0.05, -0.03, 0.02, 0.1, -0.05, 0.2]
    prog = ProgramFK(p, rotation, solver)
    sol = prog.solve(leg_lengths(p, q), q + [0.02, 0.01, -0.02, 0.1, 0.05, -0.1])
    assert sol.success and sol.solver == solver
    assert sol.residual <= 1e-10
    np.testing.assert_allclose(sol.pose, q, atol=1e-9)
    np.testing.assert_allclose(sol.rotation.T @ sol.rotation, np.eye(3), atol=1e-12)
    assert np.linalg.det(sol.rotation) == pytest.approx(1.0, abs=1e-12)


def test_program_reused_for_new_lengths():
    """One program, many solves: only the bounds of the squared-length variables change."""
    p = load_preset("utn-dynamic")
    prog = ProgramFK(p)
    for k in range(3):
        q = p.home_pose() + [0.01 * k, 0, -0.02 * k, 0.05 * k, 0, 0]
        np.testing.assert_allclose(prog.solve(leg_lengths(p, q)).pose, q, atol=1e-9)


@pytest.mark.parametrize("use_symmetry", [True, False])
def test_all_modes_utn_dynamic_home(use_symmetry):
    """3-6 platform at its home lengths: at most 16 solutions (Nanua, Waldron & Murthy 1990); we find all
    16, the set is closed under the mirror about the base plane (also when the search does not add
    mirror images itself), the IK of every mode gives back the lengths, half lie above the base, and
    the first mode is the home pose."""
    p = load_preset("utn-dynamic")
    L = leg_lengths(p, p.home_pose())
    am = assembly_modes(p, L, use_symmetry=use_symmetry, polish="snopt" if use_symmetry else None)
    assert is_planar(p) and max_solutions(p) == 16
    assert len(am) == 16 and am.complete
    for m in am.modes:
        assert _contains(am.modes, *_mirror_pose_key(m))
        np.testing.assert_allclose(leg_lengths(p, m.pose), L, atol=1e-12)
        assert m.residual <= 1e-13 and m.within_stroke
        assert m.above_base == bool(np.all(plate_anchors(p, m.pose)[:, 2] > 0))
    assert sum(m.above_base for m in am.modes) == 8
    np.testing.assert_allclose(am.modes[0].pose, p.home_pose(), atol=1e-12)
    assert [m.distance_to_home for m in am.modes] == sorted(m.distance_to_home for m in am.modes)
    if use_symmetry:
        assert all(m.certified for m in am.modes)


def test_dietmaier_40_real_solutions():
    """Dietmaier's 1998 geometry: 40 real, distinct, non-singular assembly modes (the complex bound),
    every one confirmed by SNOPT and reproducing the six lengths."""
    p, L = dietmaier_platform()
    assert not is_planar(p) and max_solutions(p) == 40
    am = assembly_modes(p, L)
    assert len(am) == 40 and am.complete
    P = np.array([m.position for m in am.modes])
    gaps = np.linalg.norm(P[:, None] - P[None], axis=-1) + np.array(
        [[np.abs(a.rotation - b.rotation).max() for b in am.modes] for a in am.modes]
    )
    assert np.min(gaps + np.eye(40) * 9) > 1e-4  # well separated: not one solution counted twice
    assert all(m.certified and m.residual <= 1e-13 and m.sigma_min > 0 for m in am.modes)
    np.testing.assert_allclose(leg_lengths(p, am.poses()), np.broadcast_to(L, (40, 6)), atol=1e-12)
    assert sorted({m.det_sign for m in am.modes}) == [-1, 1]


def test_assembly_impossible_lengths():
    p = load_preset("utn-kinematic")
    L = leg_lengths(p, p.home_pose())
    L[0], L[1] = 0.3, 1.3
    with pytest.raises(
        ForwardKinematicsError, match=r"no assembly found for lengths \(300\.000, 1300\.000, .*\) mm from \d+ starts"
    ):
        assembly_modes(p, L, n_starts=200, polish=None)


def test_assembly_modes_deterministic():
    p = load_preset("gonzalez-dutra-2009")
    L = leg_lengths(p, p.home_pose() + [0.02, 0, 0, 0, 0.1, 0])
    a, b = (assembly_modes(p, L, polish=None, seed=7) for _ in range(2))
    np.testing.assert_array_equal(a.poses(), b.poses())


def test_bad_arguments():
    p = load_preset("utn-dynamic")
    with pytest.raises(ValueError, match="unknown solver 'gurobi'"):
        ProgramFK(p, solver="gurobi")
    with pytest.raises(ValueError, match="unknown rotation parametrisation 'euler'"):
        ProgramFK(p, rotation="euler")
    with pytest.raises(ValueError, match=r"one length set of shape \(6,\)"):
        assembly_modes(p, np.full((2, 6), 0.7))
