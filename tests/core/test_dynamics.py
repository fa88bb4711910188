"""The plate's inverse dynamics (seed 004 part 2) against independent computations: quadrature, the
seed's printed M(q), finite differences, Christoffel symbols and Drake."""

import re

import numpy as np
import pytest

import stewart_drake.core.dynamics as D
from stewart_drake.core.geometry import load_preset, triangular_plate
from stewart_drake.core.kinematics import leg_lengths, leg_unit_vectors, length_jacobian
from stewart_drake.errors import NOT_FINITE_SAMPLE, SHAPE, NotFiniteError, ShapeError, SingularPoseError

G = 9.81


@pytest.fixture(scope="module")
def plat():
    return load_preset("utn-dynamic")


def rotating(t, axis=None, seed=0):
    """A trajectory about the seed's pose that rotates about ``axis`` (0, 1, 2) or all three (None)."""
    rng = np.random.default_rng(seed)
    amp = np.r_[rng.uniform(0.005, 0.03, 3), np.zeros(3)]
    if axis is None:
        amp[3:] = rng.uniform(0.15, 0.35, 3)
    else:
        amp[3 + axis] = 0.35
    return D.harmonic_trajectory(
        t, [-0.02, 0.01, 0.7, 0.02, -0.03, 0.05], amp, rng.uniform(1.5, 4.0, 6), rng.uniform(0, 6.3, 6)
    )


# --- 1. plate inertia ------------------------------------------------------------------------------


def test_plate_quadrature_matches_closed_form_and_seed_mass(plat):
    a, t, rho = 0.2, 0.01036, 7580.0
    quad = D.triangle_plate_quadrature(a, t, rho)
    m, com, I_cm = triangular_plate(a, t, rho)
    # Gauss–Legendre is exact for these degree-2 integrands: agreement to rounding.
    assert quad["mass"] == pytest.approx(m, rel=1e-13)
    np.testing.assert_allclose(quad["com"], com, atol=1e-15)
    np.testing.assert_allclose(quad["inertia_cm"], I_cm, rtol=1e-12, atol=1e-18)
    # The seed quotes m = 1.36 kg (2 decimals): the triangle's ρ A t is 1.36016 kg.
    assert abs(quad["mass"] - 1.36) < 0.005
    # The seed integrates about the T origin (z from 0 to t): Ixx gains m t²/3, not m t²/12.
    np.testing.assert_allclose(quad["inertia_T"], D.inertia_about(plat, [0, 0, 0]), rtol=1e-12, atol=1e-18)
    assert quad["inertia_T"][0, 0] == pytest.approx(m * a**2 / 24 + m * t**2 / 3, rel=1e-12)


def test_plate_quadrature_against_scipy_tplquad():
    from scipy.integrate import tplquad

    a, t, rho = 0.2, 0.01036, 7580.0
    s3 = np.sqrt(3)
    # The seed's limits: x from T2 to T1, y between edges T2T3 and T2T1 (adaptive, not Gauss–Legendre).
    lo = lambda x: -(x + s3 / 3 * a) * (a / 2) / (s3 / 2 * a)  # noqa: E731
    hi = lambda x: (x + s3 / 3 * a) * (a / 2) / (s3 / 2 * a)  # noqa: E731
    Ixx = rho * tplquad(lambda z, y, x: y**2 + z**2, -s3 / 3 * a, s3 / 6 * a, lo, hi, 0, t, epsabs=1e-14)[0]
    Izz = rho * tplquad(lambda z, y, x: x**2 + y**2, -s3 / 3 * a, s3 / 6 * a, lo, hi, 0, t, epsabs=1e-14)[0]
    quad = D.triangle_plate_quadrature(a, t, rho, n=3)
    assert quad["inertia_T"][0, 0] == pytest.approx(Ixx, rel=1e-9)
    assert quad["inertia_T"][2, 2] == pytest.approx(Izz, rel=1e-9)


# --- 2. M, C, G, J ---------------------------------------------------------------------------------


def test_mass_matrix_positive_definite_and_seed_formula(plat):
    rng = np.random.default_rng(1)
    q = plat.home_pose() + np.c_[rng.uniform(-0.05, 0.05, (50, 3)), rng.uniform(-1.2, 1.2, (50, 3))]
    M = D.mass_matrix(plat, q)
    np.testing.assert_allclose(M, np.swapaxes(M, -1, -2), atol=1e-16)
    assert np.linalg.eigvalsh(M).min() > 0
    # With the centre of mass at the rotation centre, M = diag(m, m, m, Eᵀ I E): the seed's printed M_rot.
    p0 = plat.replace(com=[0, 0, 0])
    M0 = D.mass_matrix(p0, q)
    Ix, Iy, Iz = np.diag(p0.inertia)
    np.testing.assert_allclose(M0[:, 3:, 3:], D.seed_rotational_mass_matrix(Ix, Iy, Iz, q[:, 3], q[:, 5]), atol=1e-17)
    np.testing.assert_allclose(M0[:, :3, :3], np.broadcast_to(p0.mass * np.eye(3), (50, 3, 3)))
    np.testing.assert_allclose(M0[:, :3, 3:], 0, atol=1e-17)


@pytest.mark.parametrize("convention", ["utn", "zyx"])
def test_length_jacobian_against_finite_differences(plat, convention):
    rng = np.random.default_rng(2)
    q = plat.home_pose() + np.c_[rng.uniform(-0.05, 0.05, (10, 3)), rng.uniform(-0.5, 0.5, (10, 3))]
    h = 1e-6  # central differences: truncation ~h² L''' ~ 1e-12, rounding ~1e-16 / h ~ 1e-10
    fd = np.stack(
        [
            (leg_lengths(plat, q + h * e, convention) - leg_lengths(plat, q - h * e, convention)) / (2 * h)
            for e in np.eye(6)
        ],
        -1,
    )
    np.testing.assert_allclose(length_jacobian(plat, q, convention), fd, atol=1e-8)


@pytest.mark.parametrize("convention", ["utn", "zyx"])
def test_euler_rate_derivative_against_finite_differences(convention):
    rng = np.random.default_rng(3)
    th, thd = rng.uniform(-1, 1, 3), rng.uniform(-2, 2, 3)
    from stewart_drake.core.rotations import angular_velocity_map

    h = 1e-6
    fd = (
        (angular_velocity_map(th + h * thd, convention) - angular_velocity_map(th - h * thd, convention))
        @ thd
        / (2 * h)
    )
    np.testing.assert_allclose(D.euler_rate_derivative(th, thd, convention), fd, atol=1e-8)


@pytest.mark.parametrize("convention", ["utn", "zyx"])
def test_coriolis_equals_christoffel_terms_of_M(plat, convention):
    """Newton–Euler C q̇ vs the Lagrangian Σ_jk (∂M_ij/∂q_k − ½ ∂M_jk/∂q_i) q̇_j q̇_k from M(q) alone."""
    p = plat.replace(rotation_centre=[0.01, -0.02, 0.004])  # an offset centre of mass exercises every block
    rng = np.random.default_rng(4)
    q = plat.home_pose() + np.r_[rng.uniform(-0.05, 0.05, 3), rng.uniform(-0.6, 0.6, 3)]
    qd = rng.uniform(-1, 1, 6)
    h = 1e-6
    dM = np.stack(
        [
            (D.mass_matrix(p, q + h * e, convention) - D.mass_matrix(p, q - h * e, convention)) / (2 * h)
            for e in np.eye(6)
        ]
    )  # [k, i, j]
    christoffel = np.einsum("kij,j,k->i", dM, qd, qd) - 0.5 * np.einsum("ijk,j,k->i", dM, qd, qd)
    cq = D.coriolis_vector(p, q, qd, convention)
    assert np.abs(cq).max() > 1e-4  # not trivially zero
    np.testing.assert_allclose(cq, christoffel, atol=1e-10)


def test_gravity_is_gradient_of_potential(plat):
    p = plat.replace(rotation_centre=[0.01, 0.0, -0.01])
    q = np.array([0.01, 0.02, 0.7, 0.3, -0.2, 0.5])
    h = 1e-6

    def P(q):
        mo = D.plate_motion(p, q, np.zeros(6), np.zeros(6))
        return p.mass * G * (q[2] + mo["r_cm"][2])

    fd = np.array([(P(q + h * e) - P(q - h * e)) / (2 * h) for e in np.eye(6)])
    np.testing.assert_allclose(D.gravity_vector(p, q), fd, atol=1e-9)


def test_generalized_force_is_M_qdd_plus_C_plus_G(plat):
    q, qd, qdd = rotating(np.linspace(0, 2, 7))
    lhs = D.generalized_force(plat, q, qd, qdd)
    rhs = (
        np.einsum("...ij,...j->...i", D.mass_matrix(plat, q), qdd)
        + D.coriolis_vector(plat, q, qd)
        + D.gravity_vector(plat, q)
    )
    np.testing.assert_allclose(lhs, rhs, atol=1e-13)


# --- the seed's trajectory and model ----------------------------------------------------------------


def test_seed_trajectory_is_the_seeds():
    t = np.arange(0, 4.05, 0.1)
    q, qd, qdd = D.seed_trajectory(t)
    assert q.shape == qd.shape == qdd.shape == (41, 6)
    np.testing.assert_allclose(q[:, 1], 0.1 * np.sin(2 * t))
    np.testing.assert_allclose(q[:, [0, 2]], np.broadcast_to([-0.1, 0.7], (41, 2)))
    np.testing.assert_allclose(qdd[:, 1], -0.4 * np.sin(2 * t))  # the seed's q̈ (Generador.m)
    np.testing.assert_allclose(qd[:, 1], 0.2 * np.cos(2 * t))
    np.testing.assert_array_equal(q[:, 3:], 0)


def test_seed_plot_range_and_symmetry(plat):
    """The seed plots six forces on a -2..6 N axis; px = -0.1 at py = 0 is symmetric about the XZ plane."""
    q, qd, qdd = D.seed_trajectory(np.arange(0, 4.05, 0.1))
    F = D.leg_forces(plat, q, qd, qdd)
    assert -2 < F.min() < 0 < 5 < F.max() < 6
    np.testing.assert_allclose(F[0], F[0, ::-1], rtol=1e-12)  # t = 0: legs 1↔6, 2↔5, 3↔4
    # No rotation: the Coriolis term vanishes identically on the seed's trajectory.
    np.testing.assert_array_equal(D.coriolis_vector(plat, q, qd), 0)


@pytest.mark.parametrize(
    "pose", [[0, 0, 0.7, 0, 0, 0], [-0.1, 0.1, 0.7, 0, 0, 0], [0.02, -0.03, 0.68, 0.2, -0.15, 0.4]]
)
def test_at_rest_the_legs_hold_the_weight(plat, pose):
    F = D.leg_forces(plat, pose, np.zeros(6), np.zeros(6))
    u = leg_unit_vectors(plat, pose)
    total = F @ u  # resultant of the six leg forces on the plate
    np.testing.assert_allclose(total, [0, 0, plat.mass * G], atol=1e-12)


def test_seed_literal_model_is_complete_minus_coriolis_when_com_at_C(plat):
    """The seed's M = diag(m, m, m, EᵀI_C E), G = [0,0,mg,0,0,0] is exact but for C q̇ when the centre of
    mass is at C; with the real plate (com 5.18 mm above T) it also misses the coupling m s × a."""
    q, qd, qdd = rotating(np.linspace(0, 3, 9))
    p0 = plat.replace(com=[0, 0, 0], inertia=D.inertia_about(plat, [0, 0, 0]))
    np.testing.assert_allclose(D.seed_leg_forces(p0, q, qdd), D.leg_forces(p0, q, qd, qdd, coriolis=False), atol=1e-12)
    qs, qds, qdds = D.seed_trajectory(np.arange(0, 4.05, 0.1))
    diff = np.abs(D.seed_leg_forces(plat, qs, qdds) - D.leg_forces(plat, qs, qds, qdds, coriolis=False)).max()
    # m s |a| = 1.36 kg · 5.18 mm · 0.4 m/s² = 2.8 mN·m over a ~0.1 m lever arm: a few mN.
    assert 1e-4 < diff < 2e-2


# --- errors ------------------------------------------------------------------------------------------


def test_gimbal_lock_raises_naming_sample_and_condition(plat):
    q, qd, qdd = D.seed_trajectory(np.linspace(0, 1, 5))
    q[3, 3] = np.pi / 2  # utn: alpha = 90° is the Euler singularity; J = ∂L/∂q loses rank
    with pytest.raises(SingularPoseError, match=r"sample 4: .*condition number (inf|[0-9.e+]+) > 1e\+08"):
        D.leg_forces(plat, q, qd, qdd)


def test_platform_singularity_raises(plat):
    # All six legs horizontal (pz = 0 puts every anchor in the base plane): no vertical force possible.
    q = np.array([[0, 0, 0.7, 0, 0, 0], [0, 0, 0.0, 0, 0, 0]])
    with pytest.raises(SingularPoseError, match=r"sample 2:"):
        D.leg_forces(plat, q, np.zeros(6), np.zeros(6))


def test_bad_inputs_are_named(plat):
    with pytest.raises(ShapeError, match=re.escape(SHAPE.format(name="qd", shape="(..., 6)", got="(5,)"))):
        D.leg_forces(plat, plat.home_pose(), np.zeros(5), np.zeros(6))
    with pytest.raises(
        NotFiniteError, match=re.escape(NOT_FINITE_SAMPLE.format(what="qdd sample", index=2, values=[np.nan] * 6))
    ):
        D.leg_forces(plat, np.tile(plat.home_pose(), (2, 1)), np.zeros(6), [np.zeros(6), [np.nan] * 6])
    with pytest.raises(ValueError, match="unknown rotation convention 'xyz'"):
        D.leg_forces(plat, plat.home_pose(), np.zeros(6), np.zeros(6), convention="xyz")


def test_batch_shapes_broadcast(plat):
    q, qd, qdd = rotating(np.linspace(0, 1, 12).reshape(3, 4))
    F = D.leg_forces(plat, q, qd, qdd)
    assert F.shape == (3, 4, 6)
    np.testing.assert_allclose(F[1, 2], D.leg_forces(plat, q[1, 2], qd[1, 2], qdd[1, 2]), atol=1e-13)
