"""Inverse dynamics of the moving plate (seed 004 part 2): the seed's Lagrangian model and the
complete one, vectorised over trajectory samples. Plain numpy, no Drake.

Coordinates ``q = [px, py, pz, a_x, a_y, a_z]`` (metres, radians; ``rotations`` names the Euler
convention) place the plate's rotation centre C at p_BC and orient the plate with R_BT(q). The plate's
centre of mass Tcm sits at ``platform.com`` in T, i.e. at s = p_TTcm − p_TC from C. Lagrange:

    M(q) q̈ + C(q, q̇) q̇ + G(q) = Jᵀ F,       J = ∂L/∂q  (``kinematics.length_jacobian``)

- M(q) = Aᵀ diag(m 1, I_cm) A with A(q) mapping q̇ to [v_Tcm (base frame); ω (plate frame)]:
  A = [[1, −[R s]× E_W], [0, Rᵀ E_W]] (E_W: ω_B = E_W · d(angles)/dt). With s = 0 the rotational block is
  the seed's Eᵀ I E.
- C(q, q̇) q̇ is computed by Newton–Euler on the plate (centripetal and gyroscopic terms, and the
  Euler-rate term Ė θ̇); the tests check it against the Christoffel symbols of M(q).
- G(q) = Aᵀ [m g e_z; 0]: the weight, and its moment about C when the centre of mass is off C.

F > 0 pushes the plate away from the base. ``seed_leg_forces`` is the seed's model as printed:
M = diag(m, m, m, EᵀIE) with I taken about C, G = [0, 0, m g, 0, 0, 0], no Coriolis and no coupling
between translation and rotation (exact only when the centre of mass is at C). ``leg_forces`` with
``coriolis=False`` is the complete model less C q̇ only.

Leg masses (an extension; the seeds neglect them): ``leg_forces_with_legs``. Each leg is a cylinder on
a universal joint at its base anchor and a piston on the prismatic joint (the bodies of the Drake platform model).
By virtual power each leg adds, at its plate anchor, the force f_i with J_tipᵀ f_i = τ_leg,i, where
τ_leg,i is the leg's own inverse dynamics in its joint coordinates (two universal-joint angles and the
length) and J_tip maps those rates to the tip velocity; the actuator force then balances plate + legs.
"""

from __future__ import annotations

import numpy as np

from stewart_drake.core.argcheck import as_poses, first_index
from stewart_drake.core.geometry import SQRT3, Platform
from stewart_drake.core.kinematics import (
    condition_at_most,
    inverse_jacobian_of_legs,
    length_jacobian,
    length_jacobian_of,
    plate_offsets,
    scaled_condition,
)
from stewart_drake.core.leg_bodies import home_leg_frames, leg_dimensions
from stewart_drake.core.rotations import angular_velocity_map, check_convention, rotation_matrix
from stewart_drake.core.small_linalg import Solver2, gram, solve3
from stewart_drake.core.vec3 import cross
from stewart_drake.errors import SINGULAR_SAMPLE, SingularPoseError, counted

G_EARTH = 9.81  # m/s², the seed's Matlab value (its text also quotes 9.8066)
SEED_OMEGA = 2.0  # rad/s, the seed's trajectory
# A Jacobian whose scaled condition number exceeds this is treated as singular: leg forces would carry
# errors of cond × 1e-16 relative and be enormous anyway.
MAX_CONDITION = 1e8
# Order in which the elementary rotations compose (outermost first), as indices into (a_x, a_y, a_z).
_ORDER = {"utn": (1, 0, 2), "zyx": (2, 1, 0)}


# ----------------------------------------------------------------------------------------------
# Plate mass properties.


def triangle_plate_quadrature(side: float, thickness: float, density: float, n: int = 4) -> dict:
    """The seed's integral (``i_tensor.m``): ρ ∫∫∫ over the equilateral triangle T1 T2 T3 (centroid at
    the T origin) × 0 <= z <= thickness, by Gauss–Legendre quadrature with ``n`` points per axis, in the
    seed's own limits (x from T2 to T1, y between the edges T2T3 and T2T1). Exact for n >= 2.

    Returns ``mass`` (kg), ``com`` (3,) m and ``inertia_T`` (3, 3) kg·m² about the T origin (the seed's
    Ixx, Iyy, Izz are its diagonal) and ``inertia_cm`` about the centre of mass.
    """
    xt2, xt1 = -SQRT3 / 3 * side, SQRT3 / 6 * side
    yt1, yt3 = side / 2, -side / 2
    g, w = np.polynomial.legendre.leggauss(n)
    x = xt2 + (g + 1) / 2 * (xt1 - xt2)
    wx = w / 2 * (xt1 - xt2)
    lo = (x - xt2) * (yt3 - 0.0) / (xt1 - xt2)  # edge T2T3 (yt2 = 0, xt3 = xt1)
    hi = (x - xt2) * (yt1 - 0.0) / (xt1 - xt2)  # edge T2T1
    y = lo[:, None] + (g[None, :] + 1) / 2 * (hi - lo)[:, None]
    wy = wx[:, None] * w[None, :] / 2 * (hi - lo)[:, None]
    z = (g + 1) / 2 * thickness
    wz = w / 2 * thickness
    X = np.broadcast_to(x[:, None, None], (n, n, n))
    Y = np.broadcast_to(y[:, :, None], (n, n, n))
    Z = np.broadcast_to(z[None, None, :], (n, n, n))
    W = density * wy[:, :, None] * wz[None, None, :]
    P = np.stack([X, Y, Z], -1)
    mass = W.sum()
    com = np.einsum("abc,abck->k", W, P) / mass
    second = np.einsum("abc,abck,abcl->kl", W, P, P)  # ρ ∫ p pᵀ
    inertia_T = np.trace(second) * np.eye(3) - second
    inertia_cm = inertia_T - mass * (com @ com * np.eye(3) - np.outer(com, com))
    return {"mass": float(mass), "com": com, "inertia_T": inertia_T, "inertia_cm": inertia_cm}


def inertia_about(platform: Platform, point) -> np.ndarray:
    """``(3, 3)`` the plate's rotational inertia about ``point`` (p_TP, metres, in T), kg·m²
    (parallel-axis theorem from the inertia about the centre of mass)."""
    d = platform.com - np.asarray(point, dtype=float)
    return platform.inertia + platform.mass * (d @ d * np.eye(3) - np.outer(d, d))


# ----------------------------------------------------------------------------------------------
# Trajectories.


def harmonic_trajectory(t, mean, amplitude, omega, phase=0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``q = mean + amplitude · sin(omega t + phase)`` per coordinate, with exact derivatives.

    ``t`` any shape (s); ``mean``, ``amplitude``, ``omega`` (rad/s), ``phase`` (rad) broadcast to (6,).
    Returns ``(q, qd, qdd)``, each ``t.shape + (6,)`` in metres/radians and their time derivatives.
    """
    t = np.asarray(t, dtype=float)[..., None]
    mean, amplitude, omega, phase = (
        np.broadcast_to(np.asarray(v, dtype=float), (6,)) for v in (mean, amplitude, omega, phase)
    )
    arg = omega * t + phase
    s, c = np.sin(arg), np.cos(arg)
    return mean + amplitude * s, amplitude * omega * c, -amplitude * omega**2 * s


def seed_trajectory(t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The seed's test trajectory: px = −0.1 m, py = 0.1 sin(2t) m, pz = 0.7 m, no rotation.

    ``t`` any shape (s) -> ``(q, qd, qdd)``, each ``t.shape + (6,)``.
    """
    return harmonic_trajectory(t, [-0.1, 0, 0.7, 0, 0, 0], [0, 0.1, 0, 0, 0, 0], SEED_OMEGA)


# ----------------------------------------------------------------------------------------------
# Kinematics of the plate.


def _states(q, qd, qdd):
    """``(q, qd, qdd)`` as float arrays ``(..., 6)`` broadcast together; each checked for shape and finite samples."""
    q = as_poses(q)
    arrs = []
    for name, v in (("qd", qd), ("qdd", qdd)):
        arrs.append(as_poses(v, name, f"{name} sample"))
    q, qd, qdd = np.broadcast_arrays(q, *arrs)
    return q, qd, qdd


def euler_rate_derivative(angles, rates, convention: str = "utn", E=None) -> np.ndarray:
    """``(..., 3)`` Ė_W(angles) · rates, the part of the angular acceleration ω̇_B = E_W θ̈ + Ė_W θ̇ that
    does not depend on θ̈ (rad/s²). Column k of E_W is the axis of the k-th rotation; it is carried by
    the angular velocity of the rotations composed before it. ``E``: E_W(angles) where the caller has it."""
    check_convention(convention)
    E = angular_velocity_map(angles, convention) if E is None else E
    rates = np.asarray(rates, dtype=float)
    out = np.zeros(np.broadcast_shapes(E.shape[:-1], rates.shape))
    w_before = np.zeros_like(out)
    for k in _ORDER[convention]:
        w_k = E[..., :, k] * rates[..., k : k + 1]
        out = out + cross(w_before, w_k)
        w_before = w_before + w_k
    return out


def plate_motion(platform: Platform, q, qd, qdd, convention: str = "utn") -> dict:
    """Rigid-body motion of the plate for ``(..., 6)`` q, q̇, q̈ (base frame, SI units):
    ``R`` (..., 3, 3), ``E`` (..., 3, 3), ``omega``, ``omega_dot``, ``r_cm`` (p_CTcm in B),
    ``a_cm`` (acceleration of the centre of mass) and its q̈-free part ``a_cm_bias``, ``omega_dot_bias``."""
    q, qd, qdd = _states(q, qd, qdd)
    R = rotation_matrix(q[..., 3:], convention)
    E = angular_velocity_map(q[..., 3:], convention)
    w = np.einsum("...ij,...j->...i", E, qd[..., 3:])
    wd_bias = euler_rate_derivative(q[..., 3:], qd[..., 3:], convention, E)
    wd = np.einsum("...ij,...j->...i", E, qdd[..., 3:]) + wd_bias
    r = np.einsum("...ij,j->...i", R, platform.com - platform.rotation_centre)
    centripetal = cross(w, cross(w, r))
    a_bias = cross(wd_bias, r) + centripetal
    a = qdd[..., :3] + cross(wd, r) + centripetal
    return {
        "R": R,
        "E": E,
        "omega": w,
        "omega_dot": wd,
        "omega_dot_bias": wd_bias,
        "r_cm": r,
        "a_cm": a,
        "a_cm_bias": a_bias,
    }


# ----------------------------------------------------------------------------------------------
# The Lagrangian terms.


def velocity_map(platform: Platform, q, convention: str = "utn") -> np.ndarray:
    """``(..., 6, 6)`` A(q): [v_Tcm in B; ω in the plate frame T] = A(q) · q̇."""
    q = as_poses(q)
    R = rotation_matrix(q[..., 3:], convention)
    E = angular_velocity_map(q[..., 3:], convention)
    r = np.einsum("...ij,j->...i", R, platform.com - platform.rotation_centre)
    A = np.zeros(q.shape[:-1] + (6, 6))
    A[..., :3, :3] = np.eye(3)
    A[..., :3, 3:] = -skew(r) @ E
    A[..., 3:, 3:] = np.swapaxes(R, -1, -2) @ E
    return A


def mass_matrix(platform: Platform, q, convention: str = "utn") -> np.ndarray:
    """``(..., 6, 6)`` M(q) = Aᵀ diag(m 1, I_cm) A (kg, kg·m, kg·m²), symmetric positive definite away
    from the convention's gimbal lock."""
    A = velocity_map(platform, q, convention)
    D = np.zeros((6, 6))
    D[:3, :3] = platform.mass * np.eye(3)
    D[3:, 3:] = platform.inertia
    return np.swapaxes(A, -1, -2) @ D @ A


def gravity_vector(platform: Platform, q, convention: str = "utn", gravity: float = G_EARTH) -> np.ndarray:
    """``(..., 6)`` G(q) = ∂P/∂q with P = m g z_Tcm (N, N·m)."""
    A = velocity_map(platform, q, convention)
    return platform.mass * gravity * A[..., 2, :]


def coriolis_vector(platform: Platform, q, qd, convention: str = "utn") -> np.ndarray:
    """``(..., 6)`` C(q, q̇) q̇ (N, N·m): the generalized force the plate needs at q̈ = 0 without gravity,
    by Newton–Euler: f = m a_cm, τ_cm = I ω̇ + ω × I ω, projected on q as [f; E_Wᵀ (τ_cm + r_cm × f)]."""
    return _generalized_force(
        platform, plate_motion(platform, q, qd, np.zeros_like(np.asarray(qd, float)), convention), 0.0
    )


def _generalized_force(platform: Platform, mo: dict, gravity: float, bias_only: bool = False) -> np.ndarray:
    R, w = mo["R"], mo["omega"]
    wd = mo["omega_dot_bias"] if bias_only else mo["omega_dot"]
    a = mo["a_cm_bias"] if bias_only else mo["a_cm"]
    I_W = R @ platform.inertia @ np.swapaxes(R, -1, -2)
    f = platform.mass * (a + np.array([0.0, 0.0, gravity]))
    tau = np.einsum("...ij,...j->...i", I_W, wd) + cross(w, np.einsum("...ij,...j->...i", I_W, w))
    tau_C = tau + cross(mo["r_cm"], f)
    return np.concatenate([f, np.einsum("...ji,...j->...i", mo["E"], tau_C)], axis=-1)


def generalized_force(
    platform: Platform, q, qd, qdd, convention: str = "utn", coriolis: bool = True, gravity: float = G_EARTH
) -> np.ndarray:
    """``(..., 6)`` Q = M q̈ + C q̇ + G (the last two optional): what Jᵀ F must equal (N, N·m)."""
    mo = plate_motion(platform, q, qd, qdd, convention)
    Q = _generalized_force(platform, mo, gravity)
    if not coriolis:
        Q = Q - _generalized_force(platform, mo, 0.0, bias_only=True)
    return Q


def seed_generalized_force(platform: Platform, q, qdd, convention: str = "utn", gravity: float = G_EARTH) -> np.ndarray:
    """``(..., 6)`` the seed's M(q) q̈ + G exactly as printed: M = diag(m, m, m, E_Tᵀ I_C E_T) with I_C
    the plate's inertia about the rotation centre (the seed integrates about the T origin), and
    G = [0, 0, m g, 0, 0, 0]. It neglects the translation–rotation coupling of an offset centre of mass."""
    q, _, qdd = _states(q, np.zeros(6), qdd)
    R = rotation_matrix(q[..., 3:], convention)
    E_T = np.swapaxes(R, -1, -2) @ angular_velocity_map(q[..., 3:], convention)
    M_rot = np.swapaxes(E_T, -1, -2) @ inertia_about(platform, platform.rotation_centre) @ E_T
    rot = np.einsum("...ij,...j->...i", M_rot, qdd[..., 3:])
    trans = platform.mass * qdd[..., :3] + np.array([0.0, 0.0, platform.mass * gravity])
    return np.concatenate([trans, rot], axis=-1)


def seed_rotational_mass_matrix(Ix: float, Iy: float, Iz: float, alpha, gamma) -> np.ndarray:
    """``(..., 3, 3)`` the seed's printed M_rot(alpha, gamma) (``MatrizInercia.m``), kg·m², for principal
    inertias Ix, Iy, Iz; a literal transcription used to check ``mass_matrix``."""
    ca, sa, cg, sg = np.cos(alpha), np.sin(alpha), np.cos(gamma), np.sin(gamma)
    z = np.zeros_like(ca)
    m12 = (Ix - Iy) * ca * cg * sg
    rows = [
        [Ix * cg**2 + Iy * sg**2, m12, z],
        [m12, ca**2 * (Ix * sg**2 + Iy * cg**2) + Iz * sa**2, -Iz * sa],
        [z, -Iz * sa, Iz + z],
    ]
    return np.stack([np.stack(r, -1) for r in rows], -2)


# ----------------------------------------------------------------------------------------------
# Leg forces.


def jacobian_condition(platform: Platform, q, convention: str = "utn") -> np.ndarray:
    """``(...)`` 2-norm condition number of J = ∂L/∂q with its angle columns scaled by the plate's anchor
    radius (both blocks in metres); inf on a singularity (platform singularity or Euler gimbal lock)."""
    return scaled_condition(platform, length_jacobian(platform, q, convention))


def solve_leg_forces(platform: Platform, q, Q, convention: str = "utn") -> np.ndarray:
    """``(..., 6)`` F (N) with Jᵀ(q) F = Q; raises ``SingularPoseError`` naming the first sample whose J
    has a scaled condition number above ``MAX_CONDITION``."""
    return leg_forces_from_jacobians(platform, length_jacobian(platform, q, convention), Q)


def leg_forces_from_jacobians(platform: Platform, J, Q, rows=None) -> np.ndarray:
    """``(..., 6)`` F with Jᵀ F = Q for the length Jacobians ``J`` (``solve_leg_forces``, for a caller that has
    them); ``SingularPoseError`` naming the first sample above ``MAX_CONDITION``. ``rows``: ``(n,)`` indices into
    ``(m, 6, 6)`` J, sample k's Jacobian being ``J[rows[k]]``: each distinct J's condition is checked once."""
    ok = condition_at_most(platform, J, MAX_CONDITION)
    if rows is not None:
        ok, J = ok[rows], J[rows]
    idx = first_index(~ok)
    if idx is not None:
        k = scaled_condition(platform, J[idx])
        raise SingularPoseError(SINGULAR_SAMPLE.format(index=counted(idx), cond=float(k), limit=MAX_CONDITION))
    Q = np.broadcast_to(Q, J.shape[:-1])
    return np.linalg.solve(np.swapaxes(J, -1, -2), Q[..., None])[..., 0]


def leg_forces(
    platform: Platform, q, qd, qdd, convention: str = "utn", coriolis: bool = True, gravity: float = G_EARTH
) -> np.ndarray:
    """``(..., 6)`` leg forces F (N, > 0 pushes the plate away from the base) that move the plate along
    ``(..., 6)`` q, q̇, q̈ (metres, radians and their time derivatives): Jᵀ F = M q̈ + C q̇ + G.

    ``coriolis=False`` drops C(q, q̇) q̇ (the seed's simplification); ``gravity`` in m/s² (0 turns it
    off). Legs are massless here (see ``leg_forces_with_legs``). Raises ``SingularPoseError`` naming the
    sample and the condition number when J is singular or ill-conditioned.
    """
    check_convention(convention)
    q, qd, qdd = _states(q, qd, qdd)
    Q = generalized_force(platform, q, qd, qdd, convention, coriolis, gravity)
    return solve_leg_forces(platform, q, Q, convention)


def seed_leg_forces(platform: Platform, q, qdd, convention: str = "utn", gravity: float = G_EARTH) -> np.ndarray:
    """``(..., 6)`` the seed's F = J⁻ᵀ (M q̈ + G) (``Generador.m``), with its M and G (see
    ``seed_generalized_force``), N."""
    check_convention(convention)
    return solve_leg_forces(platform, q, seed_generalized_force(platform, q, qdd, convention, gravity), convention)


def coriolis_leg_forces(platform: Platform, q, qd, convention: str = "utn") -> np.ndarray:
    """``(..., 6)`` J⁻ᵀ C(q, q̇) q̇ (N): what the seed's model misses (complete − no-Coriolis forces)."""
    q, qd, _ = _states(q, qd, np.zeros(6))
    return solve_leg_forces(platform, q, coriolis_vector(platform, q, qd, convention), convention)


# ----------------------------------------------------------------------------------------------
# Leg masses (extension).


def leg_forces_with_legs(
    platform: Platform, q, qd, qdd, convention: str = "utn", gravity: float = G_EARTH
) -> np.ndarray:
    """``(..., 6)`` leg forces (N) for the plate **and** the legs' cylinders and pistons (masses from
    ``platform.legs``, uniform rods of ``leg_bodies.leg_dimensions``; cylinder centre of mass half its
    length above the base anchor, piston's half its length below the tip), with the universal joints of
    ``leg_bodies.home_leg_frames``. Coriolis terms included. See the module docstring for how the legs enter."""
    check_convention(convention)
    q, qd, qdd = _states(q, qd, qdd)
    mo = plate_motion(platform, q, qd, qdd, convention)
    w, wd = mo["omega"][..., None, :], mo["omega_dot"][..., None, :]
    r = plate_offsets(platform, mo["R"])  # (...,6,3) p_CTi
    # Leg vectors base anchor -> plate anchor and their first two time derivatives.
    l = q[..., None, :3] + r - platform.base_anchors
    ld = qd[..., None, :3] + cross(w, r)
    ldd = qdd[..., None, :3] + cross(wd, r) + cross(w, cross(w, r))
    L = np.linalg.norm(l, axis=-1, keepdims=True)
    u = l / L
    Ld = np.sum(u * ld, -1, keepdims=True)
    ud = (ld - Ld * u) / L
    Ldd = np.sum(ud * ld + u * ldd, -1, keepdims=True)
    udd = (ldd - Ldd * u - 2 * Ld * ud) / L
    # Universal joint i: first axis a1 fixed in the base (x of the home leg frame), second a2 ⊥ a1, u.
    a1 = np.broadcast_to(home_leg_frames(platform)[:, :, 0], u.shape)
    a2 = cross(u, a1)
    a2 = a2 / np.linalg.norm(a2, axis=-1, keepdims=True)
    B = np.stack([cross(a1, u), cross(a2, u)], -1)  # (...,6,3,2): u̇ = B [q̇0, q̇1]
    BtB = Solver2(gram(B))  # numpy's Bᵀ B and solves, one C loop each (``small_linalg``)
    rates = BtB.solve(np.einsum("...ji,...j->...i", B, ud))
    omega_c = rates[..., :1] * a1 + rates[..., 1:] * a2
    a12 = rates[..., :1] * rates[..., 1:] * cross(a1, a2)  # ω̇ part from the moving second axis
    rhs = udd - cross(a12, u) - cross(omega_c, cross(omega_c, u))
    acc = BtB.solve(np.einsum("...ji,...j->...i", B, rhs))
    omega_c_dot = acc[..., :1] * a1 + acc[..., 1:] * a2 + a12

    dims = leg_dimensions(platform)
    g_vec = np.array([0.0, 0.0, gravity])
    uu = u[..., :, None] * u[..., None, :]
    M_B = np.zeros_like(u)  # moment about the base anchor of the legs' inertia + weight
    f_piston = None
    for mass, radius, length, pos in (
        (platform.legs.cylinder_mass, dims["cylinder_radius"], dims["cylinder_length"], "cylinder"),
        (platform.legs.piston_mass, dims["piston_radius"], dims["piston_length"], "piston"),
    ):
        t_perp = mass * (3 * radius**2 + length**2) / 12
        I_W = t_perp * (np.eye(3) - uu) + mass * radius**2 / 2 * uu
        if pos == "cylinder":
            e, ed, edd = length / 2, 0.0, 0.0
        else:
            e, ed, edd = L - length / 2, Ld, Ldd
        a_cm = edd * u + 2 * ed * ud + e * udd
        f = mass * (a_cm + g_vec)
        tau = np.einsum("...ij,...j->...i", I_W, omega_c_dot) + cross(
            omega_c, np.einsum("...ij,...j->...i", I_W, omega_c)
        )
        M_B = M_B + tau + cross(e * u, f)
        f_piston = f
    tau_leg = np.stack([np.sum(a1 * M_B, -1), np.sum(a2 * M_B, -1), np.sum(u * f_piston, -1)], -1)
    J_tip = np.stack([cross(a1, l), cross(a2, l), u], -1)  # ṗ_tip = J_tip [q̇0, q̇1, L̇]
    f_tip = solve3(np.swapaxes(J_tip, -1, -2), tau_leg)  # J_tipᵀ f = τ_leg
    # The plate must carry f_tip at each anchor on top of its own inertia and weight.
    Q = _generalized_force(platform, mo, gravity)
    f_sum = f_tip.sum(-2)
    m_sum = cross(r, f_tip).sum(-2)
    Q = Q + np.concatenate([f_sum, np.einsum("...ji,...j->...i", mo["E"], m_sum)], -1)
    # J = ∂L/∂q from the legs and E_W at hand: ``length_jacobian``'s numbers without its second pass over the poses
    return leg_forces_from_jacobians(platform, length_jacobian_of(inverse_jacobian_of_legs(l, r), mo["E"]), Q)


def skew(v) -> np.ndarray:
    """``(..., 3, 3)`` the cross-product matrix [v]× of ``(..., 3)`` vectors: [v]× w = v × w (entries written into
    zeros of v's dtype: 4x cheaper than stacking them)."""
    v = np.asarray(v)
    S = np.zeros(v.shape + (3,), dtype=v.dtype)
    S[..., 0, 1], S[..., 0, 2] = -v[..., 2], v[..., 1]
    S[..., 1, 0], S[..., 1, 2] = v[..., 2], -v[..., 0]
    S[..., 2, 0], S[..., 2, 1] = -v[..., 1], v[..., 0]
    return S


def open_loop_growth_rates(
    platform: Platform, q, convention: str = "utn", legs: bool = True, gravity: float = G_EARTH
) -> np.ndarray:
    """``(6,)`` exponential rates λ (1/s, real part, descending) of small errors about the static pose
    ``q`` (6,) when the static leg forces are applied open loop (constant forces, no feedback).

    Linearisation: M_eff ë = Jᵀ (F(q0) − F_static(q0 + e)) ≈ −Jᵀ (∂F_static/∂q) e, with M_eff and
    ∂F_static/∂q from this module's inverse dynamics (central differences, h = 1e-6). λ = √eig > 0 means
    the errors grow like e^{λt}: struts pushing the plate up behave like inverted pendulums.
    """
    q0 = as_poses(q).reshape(6)
    z = np.zeros(6)
    if legs:

        def forces(q_, qdd_, g):
            return leg_forces_with_legs(platform, q_, z, qdd_, convention, gravity=g)
    else:

        def forces(q_, qdd_, g):
            return leg_forces(platform, q_, z, qdd_, convention, gravity=g)

    J = length_jacobian(platform, q0, convention)
    # two batches (the inverse dynamics is row by row: the numbers of one call per pose, at a tenth of the cost)
    eye = np.eye(6)
    M_eff = J.T @ np.ascontiguousarray(forces(np.broadcast_to(q0, (6, 6)), eye, 0.0).T)
    h = 1e-6
    F = forces(np.concatenate([q0 + h * eye, q0 - h * eye]), z, gravity)
    dF = np.ascontiguousarray(((F[:6] - F[6:]) / (2 * h)).T)
    ev = np.linalg.eigvals(np.linalg.solve(M_eff, -J.T @ dF))
    return np.sort(np.sqrt(ev.astype(complex)).real)[::-1]
