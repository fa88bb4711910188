"""Natural frequencies through Drake, to check ``design.modes``.

Plate only (``drake_modes(..., legs=False)``): a continuous ``MultibodyPlant`` with the plate (and
payload) as a body on an ``RpyFloatingJoint`` and six ``LinearSpringDamper`` legs between the base
anchors and the plate anchors, their free lengths set so that at pose q they push with the static
leg forces (compression F_i = −k_i (ℓ − ℓ0_i)). Drake's ``Linearize`` (automatic differentiation) gives
ẋ = A x about that equilibrium; the eigenvalues of A are ±iω (undamped) and the velocity parts of
the eigenvectors, mapped to [v_C; ω], are the mode shapes.

With the legs' bodies (``legs=True``): the closed-loop plant of ``model.build_plant`` (cylinders,
pistons, ball constraints). Its constrained dynamics are reduced to the plate's motion: the legs'
joint velocities follow from the ball-constraint Jacobian, v = N [v_C; ω]; the reduced inertia is
Nᵀ M N (Drake's ``CalcMassMatrix``) and the stiffness −∂(Nᵀ τ)/∂x, by central differences (step
``FD_STEP``) of Drake's generalized forces τ (gravity + spring-loaded actuators F0 − k δL) on the
constraint manifold. The static actuator forces F0 come from the same plant. Leg damping, if any,
enters this reduced model as Aᵀ diag(c) A (only the plate-only path has Drake's own dampers).
"""

from __future__ import annotations

import numpy as np
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import LinearSpringDamper, RotationalInertia, RpyFloatingJoint, SpatialInertia
from pydrake.systems.framework import InputPortSelection, OutputPortSelection
from pydrake.systems.primitives import Linearize

from stewart_drake.core.dynamics import G_EARTH
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.rotations import rotation_matrix
from stewart_drake.design.modes import analytic_modes, damping_matrix, modes_from_state_eigs
from stewart_drake.design.stiffness import displace, static_leg_forces
from stewart_drake.drake.platform_model import set_pose
from stewart_drake.drake.verify_dynamics import ClosedLoopInverseDynamics
from stewart_drake.errors import SimulationError

FD_STEP = 1e-6  # m and rad: central differences on the constraint manifold (error ~ step² relative)


def _spatial_inertia(platform: Platform):
    I = platform.inertia
    return SpatialInertia.MakeFromCentralInertia(
        platform.mass, platform.com, RotationalInertia(I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2])
    )


def spring_plant(platform: Platform, q, k, c=0.0, convention: str = "utn", gravity: float = G_EARTH):
    """``(plant, context, joint)``: the plate on six spring-damper legs (continuous plant, the plate's
    ``RpyFloatingJoint``), at rest in equilibrium at pose q (6,)."""
    q = np.asarray(q, dtype=float).reshape(6)
    k = np.broadcast_to(np.asarray(k, float), (6,))
    c = np.broadcast_to(np.asarray(c, float), (6,))
    plant = MultibodyPlant(0.0)
    top = plant.AddRigidBody("top", _spatial_inertia(platform))
    joint = plant.AddJoint(RpyFloatingJoint("top_float", plant.world_frame(), top.body_frame()))
    F0 = static_leg_forces(platform, q, convention, False, gravity)
    L = leg_lengths(platform, q, convention)
    free = L + F0 / k
    if np.any(free <= 0):
        i = int(np.argmax(free <= 0))
        raise SimulationError(SimulationError.SPRING.format(leg=i + 1, force=F0[i], k=k[i]))
    for i in range(6):
        plant.AddForceElement(
            LinearSpringDamper(
                plant.world_body(),
                platform.base_anchors[i],
                top,
                platform.top_anchors_per_leg[i],
                float(free[i]),
                float(k[i]),
                float(c[i]),
            )
        )
    plant.mutable_gravity_field().set_gravity_vector([0.0, 0.0, -gravity])
    plant.Finalize()
    ctx = plant.CreateDefaultContext()
    R = rotation_matrix(q[3:], convention)
    X_WT = RigidTransform(RotationMatrix(R), q[:3] - R @ platform.rotation_centre)
    joint.SetPose(ctx, X_WT)
    plant.get_applied_generalized_force_input_port().FixValue(ctx, np.zeros(plant.num_velocities()))
    plant.get_actuation_input_port().FixValue(ctx, np.zeros(plant.num_actuated_dofs()))
    return plant, ctx, joint


def _to_C(platform: Platform, R, v_drake) -> np.ndarray:
    """Drake free-body velocities [ω; v_To] (6, m) -> [v_C; ω]."""
    w, v = v_drake[:3], v_drake[3:]
    r = (R @ platform.rotation_centre)[:, None] if v_drake.ndim == 2 else R @ platform.rotation_centre
    vC = v + np.cross(w, r, axis=0)
    return np.concatenate([vC, w], 0)


def drake_modes(
    platform: Platform, q, k, c=0.0, convention: str = "utn", gravity: float = G_EARTH, legs: bool = False
) -> dict:
    """Natural frequencies and mode shapes by Drake about the static equilibrium at pose q (6,), leg
    stiffnesses k (N/m) and damping c (N·s/m). Returns ``modes`` (``Modes``; shapes in [δp; δθ]) and
    ``residual`` (the equilibrium's largest |ẋ|, resp. |Nᵀτ|)."""
    if legs:
        return _closed_loop_modes(platform, q, k, c, convention)

    plant, ctx, joint = spring_plant(platform, q, k, c, convention, gravity)
    xdot = plant.EvalTimeDerivatives(ctx).CopyToVector()
    lin = Linearize(
        plant, ctx, InputPortSelection.kNoInput, OutputPortSelection.kNoOutput, equilibrium_check_tolerance=1e-6
    )
    lam, vec = np.linalg.eig(lin.A())
    nq = plant.num_positions()
    vs = joint.velocity_start()
    R = rotation_matrix(np.asarray(q, float)[3:], convention)
    vel = vec[nq + vs : nq + vs + 6]  # velocity part: λ × position mode
    shapes = _to_C(platform, R, vel)
    m = modes_from_state_eigs(lam, shapes)
    return {"modes": m, "residual": float(np.abs(xdot).max())}


def _closed_loop_modes(platform: Platform, q, k, c, convention: str) -> dict:
    q = np.asarray(q, dtype=float).reshape(6)
    k = np.broadcast_to(np.asarray(k, float), (6,))
    ID = ClosedLoopInverseDynamics(platform, convention)
    plant, ctx = ID.plant, ID.ctx
    F0 = ID(q, np.zeros(6), np.zeros(6))
    L0 = leg_lengths(platform, q, convention)

    def reduced(dx):
        qx = displace(q, dx, convention)
        set_pose(plant, ctx, platform, qx, convention)
        plant.SetVelocities(ctx, np.zeros(plant.num_velocities()))
        G, _ = ID.constraint_jacobian()
        R = rotation_matrix(qx[3:], convention)
        # [ω; v_To] from [v_C; ω]: v_To = v_C − ω × (R p_TC).
        T = np.zeros((6, 6))
        T[:3, 3:] = np.eye(3)
        r = R @ platform.rotation_centre
        T[3:, :3] = np.eye(3)
        T[3:, 3:] = np.array([[0, r[2], -r[1]], [-r[2], 0, r[0]], [r[1], -r[0], 0]])
        N = np.zeros((plant.num_velocities(), 6))
        N[ID.i_top] = T
        N[ID.i_legs] = -np.linalg.solve(G[:, ID.i_legs], G[:, ID.i_top] @ T)
        Lx = leg_lengths(platform, qx, convention)
        tau = plant.CalcGravityGeneralizedForces(ctx) + ID.B @ (F0 - k * (Lx - L0))
        return N, N.T @ tau

    N0, res = reduced(np.zeros(6))
    set_pose(plant, ctx, platform, q, convention)
    M = N0.T @ plant.CalcMassMatrix(ctx) @ N0
    h = FD_STEP
    K = -np.stack([(reduced(h * e)[1] - reduced(-h * e)[1]) / (2 * h) for e in np.eye(6)], -1)
    C_d = damping_matrix(platform, q, c, convention) if np.any(np.asarray(c) != 0) else None
    return {"modes": analytic_modes(K, M, C_d), "residual": float(np.abs(res).max()), "K": K, "M": M}
