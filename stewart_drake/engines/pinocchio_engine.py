"""The platform in Pinocchio: the URDF's open tree (``models.urdf_text``) closed by the six ball closures of
``models.closures`` as ``RigidConstraintModel`` (3-D contact), its kinematics and its constrained inverse dynamics.

Pinocchio has no constraint-aware inverse dynamics either: for one sample the plate's twist and acceleration are
set, the legs' joint rates and accelerations are solved from the closures (tip velocity and classical acceleration
equal to the anchor's), ``rnea`` (gravity included) gives τ (24,), and [B Gᵀ] [u; λ] = τ gives the six actuator
forces u (B selects the prismatic joints, G the closures' 18 × 24 Jacobian).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from stewart_drake.core.dynamics import G_EARTH
from stewart_drake.core.geometry import Platform
from stewart_drake.engines.models import closures, urdf_text
from stewart_drake.engines.plate import ConstrainedSolve, plate_state

NAME = "pinocchio"
VERSION = pin.__version__
LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


class PinocchioPlatform(ConstrainedSolve):
    """The closed-loop platform in Pinocchio, built from URDF text and closure dicts (default: the platform's).

    Attributes:
        model, data: Pinocchio's model of the open tree and its data.
        constraints: the six ``RigidConstraintModel`` (CONTACT_3D) of the closures.
    """

    def __init__(self, platform: Platform, urdf: str | None = None, closure_list: list | None = None):
        self.platform = platform
        self.model = pin.buildModelFromXML(urdf if urdf is not None else urdf_text(platform))
        self.model.gravity.linear = np.array([0.0, 0.0, -G_EARTH])
        model = self.model
        self.top = model.getJointId("top")
        self.universal = [[model.getJointId(f"universal_{i + 1}_{k}") for k in (1, 2)] for i in range(6)]
        self.prismatic = [model.getJointId(f"prismatic_{i + 1}") for i in range(6)]
        self.base_anchor = [model.getFrameId(f"base_anchor_{i + 1}", pin.FrameType.BODY) for i in range(6)]
        self.top_anchor = [model.getFrameId(f"top_anchor_{i + 1}", pin.FrameType.BODY) for i in range(6)]
        self.constraints, self.points = [], []
        for c in closures(platform) if closure_list is None else closure_list:
            fa, fb = (model.frames[model.getFrameId(c[k], pin.FrameType.BODY)] for k in ("frame_a", "frame_b"))
            pa = fa.placement * pin.SE3(np.eye(3), np.asarray(c["p_a"], dtype=float))
            pb = fb.placement * pin.SE3(np.eye(3), np.asarray(c["p_b"], dtype=float))
            self.constraints.append(
                pin.RigidConstraintModel(pin.ContactType.CONTACT_3D, model, fa.parentJoint, pa, fb.parentJoint, pb, LWA)
            )
            ids = []
            for name, joint, placement in (
                (f"{c['name']}_a", fa.parentJoint, pa),
                (f"{c['name']}_b", fb.parentJoint, pb),
            ):
                ids.append(model.addFrame(pin.Frame(name, joint, placement, pin.FrameType.OP_FRAME)))
            self.points.append(ids)
        self.data = model.createData()
        self.i_top = np.arange(model.idx_vs[self.top], model.idx_vs[self.top] + 6)
        self.i_legs = np.setdiff1d(np.arange(model.nv), self.i_top)
        self.B = np.zeros((model.nv, 6))
        for i, j in enumerate(self.prismatic):
            self.B[model.idx_vs[j], i] = 1.0

    def configuration(self, state, k: int) -> np.ndarray:
        """Pinocchio's q (nq,) for sample ``k`` of a ``plate.PlateState``."""
        model = self.model
        q = pin.neutral(model)
        X = model.jointPlacements[self.top].inverse() * pin.SE3(state.R[k], state.p[k])
        q[model.idx_qs[self.top] : model.idx_qs[self.top] + 7] = pin.SE3ToXYZQUAT(X)
        for i in range(6):
            for m, j in enumerate(self.universal[i]):
                q[model.idx_qs[j]] = state.angles[k, i, m]
            q[model.idx_qs[self.prismatic[i]]] = state.lengths[k, i]
        return q

    def closure_residuals(self, poses, convention: str = "utn") -> np.ndarray:
        """``(n, 6)`` |point a − point b| (m) of each closure at ``(n, 6)`` poses, the legs at our closed-form
        joint positions."""
        st = plate_state(self.platform, poses, convention=convention)
        out = np.empty(st.lengths.shape)
        for k in range(len(out)):
            pin.framesForwardKinematics(self.model, self.data, self.configuration(st, k))
            for i, (a, b) in enumerate(self.points):
                out[k, i] = np.linalg.norm(self.data.oMf[a].translation - self.data.oMf[b].translation)
        return out

    def leg_lengths(self, poses, convention: str = "utn") -> np.ndarray:
        """``(n, 6)`` the distances (m) between the model's ``base_anchor_i`` and ``top_anchor_i`` frames."""
        st = plate_state(self.platform, poses, convention=convention)
        out = np.empty(st.lengths.shape)
        for k in range(len(out)):
            pin.framesForwardKinematics(self.model, self.data, self.configuration(st, k))
            for i, (a, b) in enumerate(zip(self.base_anchor, self.top_anchor)):
                out[k, i] = np.linalg.norm(self.data.oMf[a].translation - self.data.oMf[b].translation)
        return out

    def _closure_terms(self, q, v) -> tuple[np.ndarray, np.ndarray]:
        """``(18, nv)`` G and ``(18,)`` Ġv of the closures (point a − point b, in W) at (q, v)."""
        model, data = self.model, self.data
        pin.forwardKinematics(model, data, q, v, np.zeros(model.nv))
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        G, bias = [], []
        for a, b in self.points:
            G.append(pin.getFrameJacobian(model, data, a, LWA)[:3] - pin.getFrameJacobian(model, data, b, LWA)[:3])
            bias.append(
                pin.getFrameClassicalAcceleration(model, data, a, LWA).linear
                - pin.getFrameClassicalAcceleration(model, data, b, LWA).linear
            )
        return np.vstack(G), np.concatenate(bias)

    def system(self, st, k: int) -> tuple[np.ndarray, np.ndarray]:
        """Sample ``k``'s ``(nv, nv)`` [B Gᵀ] and ``(nv,)`` τ of ``rnea`` (legs on the closures)."""
        model = self.model
        q = self.configuration(st, k)
        R = st.R[k]
        v, a = np.zeros(model.nv), np.zeros(model.nv)
        v_l, w_l = R.T @ st.v[k], R.T @ st.w[k]
        v[self.i_top] = np.concatenate([v_l, w_l])
        G, _ = self._closure_terms(q, v)
        v[self.i_legs] = np.linalg.solve(G[:, self.i_legs], -G[:, self.i_top] @ v[self.i_top])
        G, bias = self._closure_terms(q, v)
        a[self.i_top] = np.concatenate([R.T @ st.a[k] - np.cross(w_l, v_l), R.T @ st.wd[k]])
        a[self.i_legs] = np.linalg.solve(G[:, self.i_legs], -G[:, self.i_top] @ a[self.i_top] - bias)
        tau = pin.rnea(model, self.data, q, v, a)
        return np.hstack([self.B, G.T]), tau

    def set_state(self, st, k: int) -> tuple[np.ndarray, np.ndarray]:
        """Pinocchio's (q, v) on the closures for sample ``k`` of a ``plate.PlateState`` (legs' rates solved)."""
        q = self.configuration(st, k)
        v = np.zeros(self.model.nv)
        v[self.i_top] = np.concatenate([st.R[k].T @ st.v[k], st.R[k].T @ st.w[k]])
        G, _ = self._closure_terms(q, v)
        v[self.i_legs] = np.linalg.solve(G[:, self.i_legs], -G[:, self.i_top] @ v[self.i_top])
        return q, v

    def simulate(self, q0, v0, forces, dt: float, record_every: int = 1, baumgarte: float = 0.0) -> dict:
        """Integrate the closed loop from (q0, v0) for ``n − 1`` steps of ``dt`` s under ``(n, 6)`` actuator forces
        (N, at the step boundaries, linear in between) with ``constraintDynamics`` (rigid closures; ``baumgarte`` ω
        rad/s of the drift correction, Kp = ω², Kd = 2ω) and classic fourth-order Runge–Kutta on the configuration
        manifold.

        Returns ``R`` (m, 3, 3), ``p`` (m, 3) the plate frame every ``record_every`` steps (step 0 first),
        ``constraint`` (m,) worst |point a − point b| (m), ``energy`` (m,) kinetic + potential energy (J) and
        ``lengths`` (m, 6) the prismatic positions (m)."""
        step = self.stepper(baumgarte)
        q, v = np.array(q0, dtype=float), np.array(v0, dtype=float)
        out = {k: [] for k in ("R", "p", "constraint", "energy", "lengths")}
        forces = np.asarray(forces, dtype=float)
        for k in range(len(forces) - 1):
            if k % record_every == 0:
                self._record(q, v, out)
            q, v = step(q, v, forces[k], forces[k + 1], dt)
        if (len(forces) - 1) % record_every == 0:
            self._record(q, v, out)
        return {k: np.array(x) for k, x in out.items()}

    def stepper(self, baumgarte: float = 0.0):
        """``step(q, v, f0, f1, dt) -> (q, v)``: one classic RK4 step of ``dt`` s of the closed loop under actuator
        forces (6,) N going linearly from ``f0`` to ``f1`` (``constraintDynamics``, rigid closures, ``baumgarte`` ω
        rad/s of drift correction: Kp = ω², Kd = 2ω)."""
        model, data = self.model, self.data
        cms = pin.StdVec_RigidConstraintModel()
        for c in self.constraints:
            c.setBaumgarteCorrectorParameters(pin.BaumgarteCorrectorParameters(baumgarte**2, 2 * baumgarte))
            cms.append(c)
        cds = pin.StdVec_RigidConstraintData()
        for c in cms:
            cds.append(c.createData())
        pin.initConstraintDynamics(model, data, cms, cds)

        def acc(q, v, tau):
            return pin.constraintDynamics(model, data, q, v, tau, cms, cds)

        def step(q, v, f0, f1, dt):
            tau0, tau1 = self.B @ f0, self.B @ f1
            tau_mid = (tau0 + tau1) / 2
            k1v, k1a = v, acc(q, v, tau0)
            q2 = pin.integrate(model, q, k1v * dt / 2)
            k2v = v + k1a * dt / 2
            k2a = acc(q2, k2v, tau_mid)
            q3 = pin.integrate(model, q, k2v * dt / 2)
            k3v = v + k2a * dt / 2
            k3a = acc(q3, k3v, tau_mid)
            q4 = pin.integrate(model, q, k3v * dt)
            k4v = v + k3a * dt
            k4a = acc(q4, k4v, tau1)
            q_next = pin.integrate(model, q, (k1v + 2 * k2v + 2 * k3v + k4v) * dt / 6)
            return q_next, v + (k1a + 2 * k2a + 2 * k3a + k4a) * dt / 6

        return step

    def closure_residuals_at(self, q) -> np.ndarray:
        """``(6,)`` |point a − point b| (m) of each closure in configuration ``q``."""
        pin.framesForwardKinematics(self.model, self.data, q)
        return np.array(
            [np.linalg.norm(self.data.oMf[a].translation - self.data.oMf[b].translation) for a, b in self.points]
        )

    def lengths(self, q) -> np.ndarray:
        """``(6,)`` the prismatic positions (m) in configuration ``q``."""
        return np.array([q[self.model.idx_qs[j]] for j in self.prismatic])

    def plate(self, q) -> tuple[np.ndarray, np.ndarray]:
        """The plate's R_WT (3, 3) and p_WT (3,) in configuration ``q``."""
        pin.forwardKinematics(self.model, self.data, q)
        X = self.data.oMi[self.top]
        return X.rotation.copy(), X.translation.copy()

    def _record(self, q, v, out) -> None:
        model, data = self.model, self.data
        pin.framesForwardKinematics(model, data, q)
        X = data.oMi[self.top]
        out["R"].append(X.rotation.copy())
        out["p"].append(X.translation.copy())
        out["constraint"].append(
            max(np.linalg.norm(data.oMf[a].translation - data.oMf[b].translation) for a, b in self.points)
        )
        out["energy"].append(pin.computeKineticEnergy(model, data, q, v) + pin.computePotentialEnergy(model, data, q))
        out["lengths"].append([q[model.idx_qs[j]] for j in self.prismatic])

    def task_mass_matrix(self, st, k: int) -> np.ndarray:
        """``(6, 6)`` the closed loop's inertia in the plate's Cartesian coordinates [v_C; ω] (base frame, C the
        rotation centre) at sample ``k`` of a ``plate.PlateState``: Sᵀ M S, S mapping [v_C; ω] to the tree's
        velocities with the legs' rates solved from the closures (kg, kg·m, kg·m²)."""
        model = self.model
        q = self.configuration(st, k)
        M = pin.crba(model, self.data, q)
        M = np.triu(M) + np.triu(M, 1).T
        G, _ = self._closure_terms(q, np.zeros(model.nv))
        R = st.R[k]
        r = R @ self.platform.rotation_centre  # C − T in W
        S = np.zeros((model.nv, 6))
        for j in range(6):
            V = np.eye(6)[j]
            v_T = V[:3] - np.cross(V[3:], r)
            S[self.i_top, j] = np.concatenate([R.T @ v_T, R.T @ V[3:]])
        S[self.i_legs] = np.linalg.solve(G[:, self.i_legs], -G[:, self.i_top] @ S[self.i_top])
        return S.T @ M @ S
