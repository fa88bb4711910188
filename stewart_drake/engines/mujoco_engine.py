"""The platform in MuJoCo: the MJCF of ``models.mjcf_text`` (legs on two hinges and a slide, the plate on a free
joint, the closures as ``connect`` equalities between sites), its kinematics and its constrained inverse dynamics.

The inverse dynamics uses MuJoCo's rigid-body quantities only, as for Pinocchio: the legs' joint rates and
accelerations are solved from the closures (site Jacobians ``mj_jacSite``, Ġv from ``mj_jacDot``), ``mj_rne``
(gravity included) gives τ, and [B Gᵀ] [u; λ] = τ the six actuator forces. MuJoCo's own constraint solver, whose
``connect`` is soft, does not enter this number.
"""

from __future__ import annotations

import mujoco
import numpy as np

from stewart_drake.core.geometry import Platform
from stewart_drake.engines.models import mjcf_text
from stewart_drake.engines.plate import ConstrainedSolve, plate_state

NAME = "mujoco"
VERSION = mujoco.__version__


def _quat_wxyz(R) -> np.ndarray:
    q = np.empty(4)
    mujoco.mju_mat2Quat(q, np.ascontiguousarray(R, dtype=float).ravel())
    return q


class MujocoPlatform(ConstrainedSolve):
    """The closed-loop platform in MuJoCo, built from MJCF text (default: the platform's).

    Attributes:
        model, data: ``mujoco.MjModel`` and ``mujoco.MjData``.
    """

    def __init__(self, platform: Platform, mjcf: str | None = None):
        self.platform = platform
        self.model = mujoco.MjModel.from_xml_string(mjcf if mjcf is not None else mjcf_text(platform))
        self.data = mujoco.MjData(self.model)
        m = self.model
        obj = mujoco.mjtObj

        def jid(name):
            return mujoco.mj_name2id(m, obj.mjOBJ_JOINT, name)

        def sid(name):
            return mujoco.mj_name2id(m, obj.mjOBJ_SITE, name)

        self.top = jid("top")
        self.universal = [[jid(f"universal_{i + 1}_{k}") for k in (1, 2)] for i in range(6)]
        self.prismatic = [jid(f"prismatic_{i + 1}") for i in range(6)]
        self.base_anchor = [sid(f"base_anchor_{i + 1}") for i in range(6)]
        self.top_anchor = [sid(f"top_anchor_{i + 1}") for i in range(6)]
        self.actuators = [mujoco.mj_name2id(m, obj.mjOBJ_ACTUATOR, f"leg_{i + 1}") for i in range(6)]
        # The closures as written: each connect equality's two sites.
        self.points = [(int(m.eq_obj1id[e]), int(m.eq_obj2id[e])) for e in range(m.neq)]
        d0 = int(m.jnt_dofadr[self.top])
        self.i_top = np.arange(d0, d0 + 6)
        self.i_legs = np.setdiff1d(np.arange(m.nv), self.i_top)
        self.B = np.zeros((m.nv, 6))
        for i, j in enumerate(self.prismatic):
            self.B[m.jnt_dofadr[j], i] = 1.0

    def set_configuration(self, state, k: int) -> None:
        """Write sample ``k`` of a ``plate.PlateState`` into qpos and run the kinematics."""
        m, d = self.model, self.data
        a = int(m.jnt_qposadr[self.top])
        d.qpos[a : a + 3] = state.p[k]
        d.qpos[a + 3 : a + 7] = _quat_wxyz(state.R[k])
        for i in range(6):
            for n, j in enumerate(self.universal[i]):
                d.qpos[m.jnt_qposadr[j]] = state.angles[k, i, n]
            d.qpos[m.jnt_qposadr[self.prismatic[i]]] = state.lengths[k, i]
        mujoco.mj_kinematics(m, d)

    def closure_residuals(self, poses, convention: str = "utn") -> np.ndarray:
        """``(n, 6)`` |site 1 − site 2| (m) of each ``connect`` at ``(n, 6)`` poses, legs at our joint positions."""
        st = plate_state(self.platform, poses, convention=convention)
        out = np.empty(st.lengths.shape)
        for k in range(len(out)):
            self.set_configuration(st, k)
            x = self.data.site_xpos
            out[k] = [np.linalg.norm(x[a] - x[b]) for a, b in self.points]
        return out

    def leg_lengths(self, poses, convention: str = "utn") -> np.ndarray:
        """``(n, 6)`` the distances (m) between the model's ``base_anchor_i`` and ``top_anchor_i`` sites."""
        st = plate_state(self.platform, poses, convention=convention)
        out = np.empty(st.lengths.shape)
        for k in range(len(out)):
            self.set_configuration(st, k)
            x = self.data.site_xpos
            out[k] = [np.linalg.norm(x[a] - x[b]) for a, b in zip(self.base_anchor, self.top_anchor)]
        return out

    def _closure_terms(self) -> tuple[np.ndarray, np.ndarray]:
        """``(18, nv)`` G and ``(18,)`` Ġv of the closures (site 1 − site 2, in W) at the data's (qpos, qvel)."""
        m, d = self.model, self.data
        mujoco.mj_forward(m, d)
        G, bias = [], []
        for a, b in self.points:
            rows, drows = [], []
            for s in (a, b):
                jp, jpd = np.zeros((3, m.nv)), np.zeros((3, m.nv))
                mujoco.mj_jacSite(m, d, jp, None, s)
                mujoco.mj_jacDot(m, d, jpd, None, d.site_xpos[s], m.site_bodyid[s])
                rows.append(jp)
                drows.append(jpd @ d.qvel)
            G.append(rows[0] - rows[1])
            bias.append(drows[0] - drows[1])
        return np.vstack(G), np.concatenate(bias)

    def system(self, st, k: int) -> tuple[np.ndarray, np.ndarray]:
        """Sample ``k``'s ``(nv, nv)`` [B Gᵀ] and ``(nv,)`` τ of ``mj_rne`` (legs on the closures)."""
        m, d = self.model, self.data
        self.set_configuration(st, k)
        R = st.R[k]
        w_l = R.T @ st.w[k]
        d.qvel[:] = 0.0
        d.qvel[self.i_top] = np.concatenate([st.v[k], w_l])  # free joint: linear in W, angular in the body frame
        G, _ = self._closure_terms()
        d.qvel[self.i_legs] = np.linalg.solve(G[:, self.i_legs], -G[:, self.i_top] @ d.qvel[self.i_top])
        G, bias = self._closure_terms()
        qacc = np.zeros(m.nv)
        qacc[self.i_top] = np.concatenate([st.a[k], R.T @ st.wd[k]])
        qacc[self.i_legs] = np.linalg.solve(G[:, self.i_legs], -G[:, self.i_top] @ qacc[self.i_top] - bias)
        tau = np.zeros(m.nv)
        d.qacc[:] = qacc
        mujoco.mj_rne(m, d, 1, tau)
        return np.hstack([self.B, G.T]), tau

    def set_state(self, st, k: int) -> None:
        """Write sample ``k`` of a ``plate.PlateState`` into (qpos, qvel) on the closures (legs' rates solved)."""
        d = self.data
        self.set_configuration(st, k)
        d.qvel[:] = 0.0
        d.qvel[self.i_top] = np.concatenate([st.v[k], st.R[k].T @ st.w[k]])
        G, _ = self._closure_terms()
        d.qvel[self.i_legs] = np.linalg.solve(G[:, self.i_legs], -G[:, self.i_top] @ d.qvel[self.i_top])
        mujoco.mj_forward(self.model, d)

    def simulate(self, forces, record_every: int = 1) -> dict:
        """Step MuJoCo ``n − 1`` times from the data's state under ``(n, 6)`` actuator forces (N, at the step
        boundaries of ``opt.timestep``; each step holds the mean of its two ends), with its own soft ``connect``
        closures and its semi-implicit Euler integrator.

        Returns ``R`` (m, 3, 3), ``p`` (m, 3) the plate frame every ``record_every`` steps (step 0 first),
        ``constraint`` (m,) worst |site 1 − site 2| (m), ``energy`` (m,) kinetic + potential energy (J) and
        ``lengths`` (m, 6) the slide positions (m)."""
        m, d = self.model, self.data
        m.opt.enableflags |= int(mujoco.mjtEnableBit.mjENBL_ENERGY)
        body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "top")
        out = {k: [] for k in ("R", "p", "constraint", "energy", "lengths")}
        slides = [m.jnt_qposadr[j] for j in self.prismatic]

        def record():
            mujoco.mj_forward(m, d)
            out["R"].append(d.xmat[body].reshape(3, 3).copy())
            out["p"].append(d.xpos[body].copy())
            out["constraint"].append(max(np.linalg.norm(d.site_xpos[a] - d.site_xpos[b]) for a, b in self.points))
            out["energy"].append(float(d.energy.sum()))
            out["lengths"].append(d.qpos[slides].copy())

        forces = np.asarray(forces, dtype=float)
        for k in range(len(forces) - 1):
            if k % record_every == 0:
                record()
            d.ctrl[self.actuators] = (forces[k] + forces[k + 1]) / 2
            mujoco.mj_step(m, d)
        if (len(forces) - 1) % record_every == 0:
            record()
        return {k: np.array(x) for k, x in out.items()}

    def advance(self, force, steps: int = 1) -> None:
        """Step MuJoCo ``steps`` times from the data's state with actuator forces ``force`` (6,) N held."""
        self.data.ctrl[self.actuators] = force
        mujoco.mj_step(self.model, self.data, steps)

    def closure_gap(self) -> float:
        """The worst |site 1 − site 2| (m) of the connect equalities at the data's state (after ``mj_step``)."""
        x = self.data.site_xpos
        return float(max(np.linalg.norm(x[a] - x[b]) for a, b in self.points))

    def lengths(self) -> np.ndarray:
        """``(6,)`` the slide positions (m) of the data's state."""
        return np.array([self.data.qpos[self.model.jnt_qposadr[j]] for j in self.prismatic])

    def plate(self) -> tuple[np.ndarray, np.ndarray]:
        """The plate's R_WT (3, 3) and p_WT (3,) of the data's state."""
        m, d = self.model, self.data
        mujoco.mj_kinematics(m, d)
        body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "top")
        return d.xmat[body].reshape(3, 3).copy(), d.xpos[body].copy()

    def task_mass_matrix(self, st, k: int) -> np.ndarray:
        """``(6, 6)`` the closed loop's inertia in the plate's Cartesian coordinates [v_C; ω] (base frame, C the
        rotation centre) at sample ``k`` of a ``plate.PlateState``: Sᵀ M S, S mapping [v_C; ω] to MuJoCo's velocities
        with the legs' rates solved from the closures (kg, kg·m, kg·m²)."""
        m, d = self.model, self.data
        self.set_configuration(st, k)
        d.qvel[:] = 0.0
        G, _ = self._closure_terms()
        M = np.zeros((m.nv, m.nv))
        mujoco.mj_fullM(m, d, M)
        R = st.R[k]
        r = R @ self.platform.rotation_centre  # C − T in W
        S = np.zeros((m.nv, 6))
        for j in range(6):
            V = np.eye(6)[j]
            S[self.i_top, j] = np.concatenate([V[:3] - np.cross(V[3:], r), R.T @ V[3:]])
        S[self.i_legs] = np.linalg.solve(G[:, self.i_legs], -G[:, self.i_top] @ S[self.i_top])
        return S.T @ M @ S
