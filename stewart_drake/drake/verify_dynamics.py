"""Cross-checks of ``dynamics`` against Drake.

(a) **Euler chain** (``chain_plant``): the plate on three prismatic and three revolute joints in the
    convention's order, so that Drake's generalized coordinates are exactly q = [px, py, pz, a_x, a_y,
    a_z]. Drake's ``CalcMassMatrix``, ``CalcBiasTerm`` and ``CalcGravityGeneralizedForces`` are then
    M(q), C(q, q̇) q̇ and −G(q) in our coordinates, and its ``CalcSpatialAccelerationsFromVdot`` gives
    the plate's spatial acceleration from q̈ without our Euler-rate formulas.
(b) **Free body** (``drake_leg_forces``): the plate alone as a free body (quaternion floating joint) in
    a ``MultibodyPlant``; ``CalcInverseDynamics`` with gravity (``CalcForceElementsContribution``) is the
    spatial force the legs must apply at the plate origin; it is mapped to six leg forces through the
    leg directions, F = [Σ (p_i × u_i) ; Σ u_i]⁻¹ [τ; f].
(c) **Closed loop** (``constrained_leg_forces``, ``simulate_open_loop``): the full model of ``model.py``
    (legs with mass, ball constraints). Drake has no constraint-aware inverse dynamics, so we solve
    [B  Gᵀ] [u; λ] = τ_ID ourselves (B the actuation matrix, G the ball constraints' Jacobian); the
    forces are then applied open loop in a discrete simulation and the drift is measured.
"""

from __future__ import annotations

import time

import numpy as np
from pydrake.math import RigidTransform
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import (
    FixedOffsetFrame,
    JacobianWrtVariable,
    MultibodyForces,
    PrismaticJoint,
    RevoluteJoint,
    RotationalInertia,
    SpatialInertia,
)
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

from stewart_drake.core.argcheck import as_poses
from stewart_drake.core.dynamics import G_EARTH
from stewart_drake.core.geometry import Platform
from stewart_drake.core.rotations import check_convention, rotation_matrix
from stewart_drake.drake.platform_model import build_plant, prismatic_joints, prismatic_positions, set_pose

# Joints of the Euler chain, outermost first: (name, axis, index in q).
_CHAIN = {
    "utn": [("x", 0, 0), ("y", 1, 1), ("z", 2, 2), ("beta", 1, 4), ("alpha", 0, 3), ("gamma", 2, 5)],
    "zyx": [("x", 0, 0), ("y", 1, 1), ("z", 2, 2), ("psi", 2, 5), ("theta", 1, 4), ("phi", 0, 3)],
}


def _spatial_inertia(platform: Platform):
    I = platform.inertia
    return SpatialInertia.MakeFromCentralInertia(
        platform.mass, platform.com, RotationalInertia(I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2])
    )


def free_body_plant(platform: Platform, gravity: float = G_EARTH):
    """A finalized continuous ``MultibodyPlant`` with the plate as the free body ``top`` (frame T)."""
    plant = MultibodyPlant(0.0)
    plant.AddRigidBody("top", _spatial_inertia(platform))
    plant.mutable_gravity_field().set_gravity_vector([0.0, 0.0, -gravity])
    plant.Finalize()
    return plant


def chain_plant(platform: Platform, convention: str = "utn", gravity: float = G_EARTH):
    """A finalized continuous plant whose generalized coordinates are the pose q: prismatic x, y, z then
    revolute joints in the convention's order, the last one's child frame at the rotation centre of
    the plate ``top``. Returns ``(plant, perm)`` with ``v_drake = q̇[perm]``."""
    check_convention(convention)
    plant = MultibodyPlant(0.0)
    parent = plant.world_frame()
    perm = []
    chain = _CHAIN[convention]
    for k, (name, axis, index) in enumerate(chain):
        last = k == len(chain) - 1
        body = plant.AddRigidBody(
            "top" if last else f"link_{name}", _spatial_inertia(platform) if last else SpatialInertia.Zero()
        )
        child = body.body_frame()
        if last:
            child = plant.AddFrame(_fixed_frame("C", body, RigidTransform(platform.rotation_centre)))
        e = np.eye(3)[axis]
        joint_type = PrismaticJoint if k < 3 else RevoluteJoint
        perm.append((plant.AddJoint(joint_type(name, parent, child, e)), index))
        parent = body.body_frame()
    plant.mutable_gravity_field().set_gravity_vector([0.0, 0.0, -gravity])
    plant.Finalize()
    order = np.empty(6, int)
    for joint, index in perm:  # velocity_start() is known only after Finalize
        order[joint.velocity_start()] = index
    return plant, order


def _fixed_frame(name, body, X):
    return FixedOffsetFrame(name, body.body_frame(), X)


def drake_dynamics_terms(platform: Platform, q, qd, convention: str = "utn", gravity: float = G_EARTH) -> dict:
    """Drake's M(q) ``(n, 6, 6)``, C(q, q̇) q̇ ``(n, 6)`` and G(q) ``(n, 6)`` in pose coordinates (chain plant)."""
    plant, perm = chain_plant(platform, convention, gravity)
    ctx = plant.CreateDefaultContext()
    q, qd = np.atleast_2d(as_poses(q)), np.atleast_2d(qd)
    n = len(q)
    M, C, G = np.empty((n, 6, 6)), np.empty((n, 6)), np.empty((n, 6))
    inv = np.argsort(perm)  # q index -> drake index
    for k in range(n):
        plant.SetPositions(ctx, q[k][perm])
        plant.SetVelocities(ctx, qd[k][perm])
        M[k] = plant.CalcMassMatrix(ctx)[np.ix_(inv, inv)]
        C[k] = plant.CalcBiasTerm(ctx)[inv]
        G[k] = -plant.CalcGravityGeneralizedForces(ctx)[inv]
    return {"M": M, "C": C, "G": G}


def _leg_wrench_matrix(platform: Platform, X_WT) -> np.ndarray:
    """``(6, 6)`` W with [τ_To; f] = W F: column i is leg i's unit force at its anchor, about T's origin."""
    p_WA = X_WT.multiply(platform.top_anchors_per_leg.T).T  # (6, 3) anchors in W
    u = p_WA - platform.base_anchors
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    return np.vstack([np.cross(p_WA - X_WT.translation(), u).T, u.T])


class PlateKinematics:
    """The plate's pose X_WT, spatial velocity V_WT and spatial acceleration A_WT (Drake objects, at T's
    origin, in W) from (q, q̇, q̈), computed by Drake on the Euler chain (no formula of ``dynamics``)."""

    def __init__(self, platform: Platform, convention: str = "utn"):
        self.plant, self.perm = chain_plant(platform, convention)
        self.ctx = self.plant.CreateDefaultContext()
        self.top = self.plant.GetBodyByName("top")

    def __call__(self, q, qd, qdd=None):
        self.plant.SetPositions(self.ctx, np.asarray(q, dtype=float)[self.perm])
        self.plant.SetVelocities(self.ctx, np.asarray(qd, dtype=float)[self.perm])
        X = self.plant.EvalBodyPoseInWorld(self.ctx, self.top)
        V = self.plant.EvalBodySpatialVelocityInWorld(self.ctx, self.top)
        if qdd is None:
            return X, V, None
        A = self.plant.CalcSpatialAccelerationsFromVdot(self.ctx, np.asarray(qdd, dtype=float)[self.perm])[
            int(self.top.index())
        ]
        return X, V, A


class DrakeInverseDynamics:
    """Per-sample leg forces from Drake: the chain plant turns (q, q̇, q̈) into the plate's spatial velocity
    and acceleration; the free-body plant's ``CalcInverseDynamics`` (with gravity) gives the spatial force
    at T's origin; the leg directions map it to six leg forces."""

    def __init__(self, platform: Platform, convention: str = "utn", gravity: float = G_EARTH):
        self.platform = platform
        self.kinematics = PlateKinematics(platform, convention)
        self.free = free_body_plant(platform, gravity)
        self.free_ctx = self.free.CreateDefaultContext()
        self.free_top = self.free.GetBodyByName("top")
        self.forces = MultibodyForces(self.free)

    def __call__(self, q, qd, qdd) -> np.ndarray:
        """``(6,)`` leg forces (N) for one sample."""
        X_WT, V_WT, A_WT = self.kinematics(q, qd, qdd)
        fp, fc = self.free, self.free_ctx
        fp.SetFreeBodyPose(fc, self.free_top, X_WT)
        fp.SetFreeBodySpatialVelocity(fc, self.free_top, V_WT)
        fp.CalcForceElementsContribution(fc, self.forces)
        tau = fp.CalcInverseDynamics(fc, A_WT.get_coeffs(), self.forces)  # [τ_W about To; f_W]
        return np.linalg.solve(_leg_wrench_matrix(self.platform, X_WT), tau)


def drake_leg_forces(platform: Platform, q, qd, qdd, convention: str = "utn", gravity: float = G_EARTH) -> np.ndarray:
    """``(n, 6)`` leg forces (N) for ``(n, 6)`` samples, one Drake inverse-dynamics call per sample."""
    ID = DrakeInverseDynamics(platform, convention, gravity)
    q, qd, qdd = (np.atleast_2d(np.asarray(a, dtype=float)) for a in (q, qd, qdd))
    return np.array([ID(q[k], qd[k], qdd[k]) for k in range(len(q))])


# ----------------------------------------------------------------------------------------------
# The closed-loop model (legs with mass, ball constraints).


class ClosedLoopInverseDynamics:
    """Leg forces for the closed-loop plant of ``model.build_plant`` (plate + cylinders + pistons).

    For one sample: the plate's pose, spatial velocity and acceleration come from the Euler chain; the
    legs' joint velocities and accelerations are solved from the ball constraints (tip velocity and
    acceleration equal to the plate anchor's); ``CalcInverseDynamics`` with gravity gives τ_ID (24,);
    and [B Gᵀ] [u; λ] = τ_ID gives the six actuator forces u and the 18 constraint forces λ.
    """

    def __init__(self, platform: Platform, convention: str = "utn", time_step: float = 1e-3):
        self.platform, self.convention = platform, convention
        self.kinematics = PlateKinematics(platform, convention)
        self.plant, _ = build_plant(platform, time_step, visuals=False)
        plant = self.plant
        g = np.linalg.norm(plant.gravity_field().gravity_vector())
        if abs(g - G_EARTH) > 1e-12:
            # internal: build_plant sets the gravity; a different value is a bug here, not bad input
            raise ValueError(f"the closed-loop plant's gravity is {g} m/s², expected {G_EARTH}")
        self.ctx = plant.CreateDefaultContext()
        self.top = plant.GetBodyByName("top")
        self.forces = MultibodyForces(plant)
        nv = plant.num_velocities()
        self.i_top = np.arange(self.top.floating_velocities_start_in_v(), self.top.floating_velocities_start_in_v() + 6)
        self.i_legs = np.setdiff1d(np.arange(nv), self.i_top)
        B = plant.MakeActuationMatrix()  # (nv, n_actuators), columns in actuator order
        order = [
            int(np.argmax(np.abs(B[plant.GetJointByName(f"prismatic_{i + 1}").velocity_start()]))) for i in range(6)
        ]
        self.order = order  # actuator index of leg i
        self.B = B[:, order]  # columns in leg order
        self.tips = [plant.GetFrameByName(f"piston_{i + 1}") for i in range(6)]
        self.anchors = [plant.GetFrameByName(f"top_anchor_{i + 1}") for i in range(6)]

    def constraint_jacobian(self) -> tuple[np.ndarray, np.ndarray]:
        """``(18, nv)`` G and ``(18,)`` Ġv: tip − anchor translational velocity/acceleration bias, in W."""
        plant, ctx, W = self.plant, self.ctx, self.plant.world_frame()
        G, b = [], []
        kV, o = JacobianWrtVariable.kV, np.zeros(3)
        for tip, anchor in zip(self.tips, self.anchors):
            G.append(
                plant.CalcJacobianTranslationalVelocity(ctx, kV, tip, o, W, W)
                - plant.CalcJacobianTranslationalVelocity(ctx, kV, anchor, o, W, W)
            )
            b.append(
                plant.CalcBiasTranslationalAcceleration(ctx, kV, tip, o, W, W)
                - plant.CalcBiasTranslationalAcceleration(ctx, kV, anchor, o, W, W)
            )
        return np.vstack(G), np.concatenate([x.ravel() for x in b])

    def set_state(self, q, qd) -> tuple[np.ndarray, np.ndarray]:
        """Set the closed-loop state for one sample; returns the constraint Jacobian and bias at it."""
        _, V_WT, _ = self.kinematics(q, qd)
        set_pose(self.plant, self.ctx, self.platform, q, self.convention)
        v = np.zeros(self.plant.num_velocities())
        v[self.i_top] = V_WT.get_coeffs()
        self.plant.SetVelocities(self.ctx, v)
        G, _ = self.constraint_jacobian()
        v[self.i_legs] = np.linalg.solve(G[:, self.i_legs], -G[:, self.i_top] @ v[self.i_top])
        self.plant.SetVelocities(self.ctx, v)
        return self.constraint_jacobian()

    def __call__(self, q, qd, qdd) -> np.ndarray:
        """``(6,)`` actuator forces (N) for one sample, legs' inertia included."""
        G, bias = self.set_state(q, qd)
        vd = np.zeros(self.plant.num_velocities())
        vd[self.i_top] = self.kinematics(q, qd, qdd)[2].get_coeffs()
        vd[self.i_legs] = np.linalg.solve(G[:, self.i_legs], -G[:, self.i_top] @ vd[self.i_top] - bias)
        self.plant.CalcForceElementsContribution(self.ctx, self.forces)
        tau = self.plant.CalcInverseDynamics(self.ctx, vd, self.forces)
        sol = np.linalg.solve(np.hstack([self.B, G.T]), tau)
        return sol[:6]


def constrained_leg_forces(platform: Platform, q, qd, qdd, convention: str = "utn") -> np.ndarray:
    """``(n, 6)`` actuator forces (N) of the closed-loop Drake model (legs with mass), per sample."""
    ID = ClosedLoopInverseDynamics(platform, convention)
    q, qd, qdd = (np.atleast_2d(np.asarray(a, dtype=float)) for a in (q, qd, qdd))
    return np.array([ID(q[k], qd[k], qdd[k]) for k in range(len(q))])


def simulate_open_loop(
    platform: Platform, t, q, qd, forces, time_step: float = 1e-3, convention: str = "utn", record_every: int = 10
) -> dict:
    """Apply ``(n, 6)`` leg forces (N, at times ``t`` (n,), first-order hold) open loop to the closed-loop
    plant of ``model.build_plant``, starting on the trajectory at (q[0], q̇[0]); compare the plate with
    the planned ``(n, 6)`` poses q every ``record_every`` samples.

    Returns ``t`` (m,), ``position_error`` (m,) |p_C − p_C,planned| (m), ``angle_error`` (m,) rad (angle of
    R Rᵀ_planned), ``constraint`` (m,) worst |piston tip − plate anchor| (m), ``lengths`` (m, 6) prismatic
    positions, and ``wall_time`` (s).
    """
    t, q, qd, forces = (np.asarray(a, dtype=float) for a in (t, q, qd, forces))
    ID = ClosedLoopInverseDynamics(platform, convention, time_step)
    ID.set_state(q[0], qd[0])
    builder = DiagramBuilder()
    plant, _ = build_plant(platform, time_step, builder, visuals=False)
    u = np.zeros((len(t), plant.num_actuators()))
    u[:, ID.order] = forces
    src = builder.AddSystem(TrajectorySource(PiecewisePolynomial.FirstOrderHold(t, u.T)))
    builder.Connect(src.get_output_port(), plant.get_actuation_input_port())
    diagram = builder.Build()
    sim = Simulator(diagram)
    ctx = sim.get_mutable_context()
    ctx.SetTime(t[0])
    pctx = plant.GetMyMutableContextFromRoot(ctx)
    plant.SetPositions(pctx, ID.plant.GetPositions(ID.ctx))
    plant.SetVelocities(pctx, ID.plant.GetVelocities(ID.ctx))
    sim.Initialize()
    top = plant.GetBodyByName("top")
    tips = [plant.GetFrameByName(f"piston_{i + 1}") for i in range(6)]
    anchors = [plant.GetFrameByName(f"top_anchor_{i + 1}") for i in range(6)]
    legs = prismatic_joints(plant)
    idx = np.arange(0, len(t), record_every)
    R_plans = rotation_matrix(q[idx, 3:], convention)  # elementwise: the same bits as one pose at a time
    out = {k: [] for k in ("position_error", "angle_error", "constraint", "lengths")}
    t0 = time.perf_counter()
    for k, R_plan in zip(idx, R_plans):
        if k > 0:  # the first AdvanceTo also fires the update at t[0]; the state then belongs to t[k]
            sim.AdvanceTo(t[k])
        X = plant.EvalBodyPoseInWorld(pctx, top)
        R = X.rotation().matrix()
        p_C = X.translation() + R @ platform.rotation_centre
        out["position_error"].append(np.linalg.norm(p_C - q[k, :3]))
        c = np.clip((np.trace(R @ R_plan.T) - 1) / 2, -1.0, 1.0)
        out["angle_error"].append(np.arccos(c))
        out["constraint"].append(
            max(
                np.linalg.norm(a.CalcPoseInWorld(pctx).translation() - b.CalcPoseInWorld(pctx).translation())
                for a, b in zip(tips, anchors)
            )
        )
        out["lengths"].append(prismatic_positions(plant, pctx, legs))
    res = {k: np.array(v) for k, v in out.items()}
    res["t"] = t[idx]
    res["wall_time"] = time.perf_counter() - t0
    return res
