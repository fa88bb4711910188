"""The closed leg loop linearised about a held pose, in the z domain: frequency responses, margins, bandwidth,
sensitivity peak.

The model is built from the platform's closed forms rather than from Drake's ``Linearize``: the plant is a
closed-chain ``MultibodyPlant`` whose loop closures are SAP/CENIC constraints, which Drake's linearisation of a
continuous system does not take. About a pose at rest the legs obey

    M_L·δL̈ = δF − K·δL        M_L = J⁻ᵀ M J⁻¹ (``gains.leg_space_inertia``), K = ∂F_static/∂L

(the leg forces that hold the plate, differentiated along the legs: ``leg_space_stiffness``; the rate terms are
quadratic at rest). The actuators are the loop's own discrete lag F ← a·F + b·u at each plant step h
(``control.actuation``), reading the command held just before that step; without a lag the force follows the
command from its release. Screw actuators (``control.screw``) are their small signal at rest (``SmallSignal``:
the current loop, the force of the current and the velocity's damping, the rotor's mass on the legs), hydraulic
cylinders theirs (``control.hydraulic.SmallSignal``: pressures and spool, the valve's describing gain). The
mechanics between plant steps are integrated exactly (zero-order hold), so the tick-to-tick map of (lengths, rates, forces) is exact for the linear plant. The controller is the PID of
``control.laws`` as a discrete state space (integrator, measurement and set-point difference filters), its
command released ``DspTiming.output_delay`` after the tick. The feed-forward table's rows enter, linearised, as
(K − ω̃²·M_L)·e^{jω·lead} per unit set-point (ω̃² = (2 − 2 cos ωT)/T², the table's central second difference).

Loops and margins: the controller is the same scalar c_y(z) on every leg, so the loop broken at the input of leg
i with the other five closed has the return ratio L_i = 1/[S]_ii − 1, S = (I + c_y·G)⁻¹ (the loop-at-a-time
margins per leg); the sensitivity peak is the largest singular value of S over frequency (the multivariable
peak; 1/peak is the distance of the return difference from singularity). Lengths in metres, forces in newtons,
frequencies in hertz, phases in degrees where named so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg import expm

from stewart_drake.control.gains import ControllerConfig, FixedGains, PidGains, leg_space_inertia
from stewart_drake.control.hydraulic import SmallSignal as HydraulicSignal
from stewart_drake.control.screw import SmallSignal
from stewart_drake.core.dynamics import leg_forces_with_legs
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import length_jacobian

# The minimums a loop must keep (the usual ones for a loop with delay and unmodelled lag): gain margin in dB and
# phase margin in degrees, per leg with the other legs closed.
MIN_GAIN_MARGIN_DB = 6.0
MIN_PHASE_MARGIN_DEG = 30.0


def leg_space_stiffness(platform: Platform, pose, h: float = 1e-6) -> np.ndarray:
    """``(6, 6)`` K = ∂F_static/∂L (N/m) at ``pose`` (6,): the change of the leg forces that hold the plate at rest
    per unit change of the leg lengths (central differences of step ``h`` in the pose, ``(∂F/∂q)·J⁻¹``). Negative
    eigenvalues are the struts' negative stiffness (``gains.strut_stiffness``)."""
    q0 = np.asarray(pose, dtype=float).reshape(6)
    steps = h * np.eye(6)
    poses = np.concatenate([q0 + steps, q0 - steps])
    z = np.zeros((12, 6))
    F = leg_forces_with_legs(platform, poses, z, z)
    dFdq = ((F[:6] - F[6:]) / (2 * h)).T  # column k: ∂F/∂q_k
    return dFdq @ np.linalg.inv(length_jacobian(platform, q0))


def leg_space_mass(platform: Platform, pose) -> np.ndarray:
    """``(6, 6)`` M_L (kg) at ``pose`` (6,): ``gains.leg_space_inertia``."""
    return leg_space_inertia(platform, np.asarray(pose, dtype=float).reshape(6))


def effective_gains(law: str, config: ControllerConfig) -> PidGains:
    """The SI gains a law applies: ``config.gains`` for ``float``; for ``fixed`` the Q15 words' values
    (``FixedGains``) turned back into SI, with the filters' Q15 weights."""
    g = config.gains
    if law != "fixed":
        return g
    t = config.timing
    fg = FixedGains.from_si(g, t)
    scale = 32768.0 * t.sensor_resolution / t.command_range  # word per SI gain, as FixedGains.from_si
    T, d = t.sample_period, 2.0**6
    return PidGains(
        kp=fg.kp.value / scale,
        ki=fg.ki.value / scale / T,
        kd=fg.kd.value / scale * T * d,
        kv=fg.kv.value / scale * T * d,
        derivative_filter=fg.alpha / 32768.0,
        feedforward_filter=fg.alpha_ff / 32768.0,
    )


def controller_matrices(gains: PidGains, T: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """One leg's PID (``laws.FloatLaw.step``) as a discrete state space ``(Ac (5, 5), Bc (5, 2), Cc (1, 5),
    Dc (1, 2))``: state (integrator N, previous measurement m, its filtered difference m, previous set-point m, its
    filtered difference m), inputs (set-point, measurement) m, output the command N before the feed-forward."""
    kp, ki, kd, kv = gains.kp, gains.ki, gains.kd, gains.kv
    a, af = gains.derivative_filter, gains.feedforward_filter
    Ac = np.array(
        [
            [1, 0, 0, 0, 0],
            [0, 0, 0, 0, 0],
            [0, -a, 1 - a, 0, 0],
            [0, 0, 0, 0, 0],
            [0, 0, 0, -af, 1 - af],
        ],
        dtype=float,
    )
    Bc = np.array([[ki * T, -ki * T], [0, 1], [0, a], [1, 0], [af, 0]], dtype=float)
    Cc = np.array([[1, kd / T * a, -kd / T * (1 - a), -kv / T * af, kv / T * (1 - af)]], dtype=float)
    Dc = np.array([[kp + kv / T * af, -kp - kd / T * a]], dtype=float)
    return Ac, Bc, Cc, Dc


def _zoh(A: np.ndarray, B: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray]:
    """``(e^{At}, ∫₀ᵗ e^{Aσ} dσ B)``: the exact map of x' = Ax + Bu over ``t`` s with u held."""
    n, m = B.shape
    E = expm(np.block([[A, B], [np.zeros((m, n + m))]]) * t)
    return E[:n, :n], E[:n, n:]


def plant_matrices(M: np.ndarray, K: np.ndarray, lag: float, step: float, T: float, delay: float):
    """The leg plant from one tick to the next: ``(Phi, G_old, G_new)`` with s_{k+1} = Phi·s_k + G_old·u_{k−1} +
    G_new·u_k, s = (lengths m, rates m/s[, lag forces N]) at the tick, u_k the command (N) computed at tick k and
    released ``delay`` s (0 ≤ delay ≤ T) later. ``M``, ``K``: (6, 6) leg-space mass (kg) and stiffness (N/m);
    ``lag``: the actuators' time constant (s, 0: none), stepped at the plant ``step`` (s, T a whole number of
    steps)."""
    Minv = np.linalg.inv(M)
    Am = np.block([[np.zeros((6, 6)), np.eye(6)], [-Minv @ K, np.zeros((6, 6))]])
    Bm = np.vstack([np.zeros((6, 6)), Minv])
    if lag <= 0:  # the force follows the command from its release
        Phi, _ = _zoh(Am, Bm, T)
        E1, G1 = _zoh(Am, Bm, delay)
        E2, G2 = _zoh(Am, Bm, T - delay)
        return Phi, E2 @ G1, G2
    Ad, Bd = _zoh(Am, Bm, step)
    a = math.exp(-step / lag)
    sub = np.block([[Ad, Bd], [np.zeros((6, 12)), a * np.eye(6)]])  # mechanics with F held, then F ← a·F
    inj = np.vstack([np.zeros((12, 6)), (1 - a) * np.eye(6)])  # ... + b·u
    return _tick_map(sub, inj, step, T, delay)


def _tick_map(sub: np.ndarray, inj: np.ndarray, step: float, T: float, delay: float):
    """``(Phi, G_old, G_new)`` of a tick from the plant-step map s ← ``sub``·s (+ ``inj``·u at each step's end):
    a step reads the command held just before it, u_{k−1} until the release ``delay`` s after the tick."""
    n = int(round(T / step))
    Phi, G_old, G_new = np.eye(len(sub)), np.zeros((len(sub), 6)), np.zeros((len(sub), 6))
    for j in range(1, n + 1):
        Phi, G_old, G_new = sub @ Phi, sub @ G_old, sub @ G_new
        if j * step > delay + 1e-9 * T:  # the actuators read the command held just before this plant step
            G_new = G_new + inj
        else:
            G_old = G_old + inj
    return Phi, G_old, G_new


def screw_plant_matrices(M: np.ndarray, K: np.ndarray, screw: SmallSignal, step: float, T: float, delay: float):
    """``plant_matrices`` with screw actuators (``control.screw.SmallSignal``) in place of the lag: the legs
    carry the rotors' reflected mass, and at each plant step the currents take the command held just before it,
    i ← a·i + β·u, and the force c·i + d·L̇ is held over the next step. State s = (lengths m, rates m/s, currents
    A, held forces N)."""
    Minv = np.linalg.inv(M + screw.reflected_mass * np.eye(6))
    Am = np.block([[np.zeros((6, 6)), np.eye(6)], [-Minv @ K, np.zeros((6, 6))]])
    Bm = np.vstack([np.zeros((6, 6)), Minv])
    Ad, Bd = _zoh(Am, Bm, step)
    I6, Z6, D = np.eye(6), np.zeros((6, 6)), np.diag(screw.d)
    rate = np.hstack([Z6, I6])  # picks L̇ from (L, L̇)
    # mechanics with F held, then i ← a·i (+ β·u) and F ← c·i + d·L̇ at the step's end
    sub = np.block(
        [
            [Ad, np.zeros((12, 6)), Bd],
            [np.zeros((6, 12)), screw.a * I6, Z6],
            [D @ rate @ Ad, screw.c * screw.a * I6, D @ rate @ Bd],
        ]
    )
    inj = np.vstack([np.zeros((12, 6)), screw.beta * I6, screw.c * screw.beta * I6])
    return _tick_map(sub, inj, step, T, delay)


def hydraulic_plant_matrices(M: np.ndarray, K: np.ndarray, cyl: HydraulicSignal, step: float, T: float, delay: float):
    """``plant_matrices`` with hydraulic cylinders (``control.hydraulic.SmallSignal``) in place of the lag: at
    each plant step the cylinders' state a = (p_A, p_B, s) takes the command held just before it and the legs'
    velocity at the step's end, a ← E·a + G_u·u + G_v·L̇, and the force c·a is held over the next step. State
    s = (lengths m, rates m/s, p_A Pa, p_B Pa, spools, held forces N)."""
    Minv = np.linalg.inv(M)
    Am = np.block([[np.zeros((6, 6)), np.eye(6)], [-Minv @ K, np.zeros((6, 6))]])
    Bm = np.vstack([np.zeros((6, 6)), Minv])
    Ad, Bd = _zoh(Am, Bm, step)
    # the cylinders' 18 states ordered (p_A legs 1..6, p_B legs 1..6, spools legs 1..6)
    E, Gu, Gv = np.zeros((18, 18)), np.zeros((18, 6)), np.zeros((18, 6))
    for leg in range(6):
        idx = [leg, 6 + leg, 12 + leg]
        E[np.ix_(idx, idx)] = cyl.E[leg]
        Gu[idx, leg], Gv[idx, leg] = cyl.G_u[leg], cyl.G_v[leg]
    C = np.kron(cyl.c[None, :], np.eye(6))  # (6, 18): F = c·a per leg
    rate = np.hstack([np.zeros((6, 6)), np.eye(6)])  # picks L̇ from (L, L̇)
    new_rate_m, new_rate_f = rate @ Ad, rate @ Bd  # L̇ at the step's end, of (L, L̇) and F at its start
    # mechanics with F held; then a ← E·a + G_v·L̇(end) (+ G_u·u), F ← C·a
    sub = np.block(
        [
            [Ad, np.zeros((12, 18)), Bd],
            [Gv @ new_rate_m, E, Gv @ new_rate_f],
            [C @ Gv @ new_rate_m, C @ E, C @ Gv @ new_rate_f],
        ]
    )
    inj = np.vstack([np.zeros((12, 6)), Gu, C @ Gu])
    return _tick_map(sub, inj, step, T, delay)


@dataclass(frozen=True)
class LoopModel:
    """The discrete closed leg loop about ``pose`` (6,): inputs the six leg set-points (m) and the six
    feed-forward forces (N) at the ticks, outputs the six leg lengths (m) at the ticks.

    ``A`` (n, n), ``B`` (n, 12), ``C`` (6, n), ``D`` (6, 12): the closed loop's state space (state: plant,
    released command, controller). ``plant``: (Phi, Gamma) of the plant with its delayed command (state and
    command input: u_k → lengths); ``gains``: the law's SI gains; ``M``, ``K``: (6, 6) leg-space mass and
    stiffness; ``J``: (6, 6) ∂L/∂q at the pose; ``lead``: seconds the feed-forward table leads the reference
    (None: no feed-forward); ``T``: the sample period (s)."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    plant: tuple
    gains: PidGains
    M: np.ndarray
    K: np.ndarray
    J: np.ndarray
    lead: float | None
    T: float
    pose: np.ndarray

    @classmethod
    def build(
        cls,
        platform: Platform,
        pose,
        gains: PidGains,
        T: float,
        delay: float,
        lag: float,
        step: float,
        lead: float | None,
        screw: SmallSignal | None = None,
        hydraulic: HydraulicSignal | None = None,
    ) -> LoopModel:
        """The loop of ``platform`` at ``pose`` (6,) with the law's SI ``gains``, sample period ``T`` (s), output
        ``delay`` (s, ≤ T), actuator ``lag`` (s) stepped at the plant ``step`` (s) and the feed-forward ``lead``
        (s; None: no feed-forward); ``screw``, ``hydraulic``: the screws' or cylinders' small signal in place of
        the lag."""
        pose = np.asarray(pose, dtype=float).reshape(6)
        M, K = leg_space_mass(platform, pose), leg_space_stiffness(platform, pose)
        if screw is not None:
            Phi, G_old, G_new = screw_plant_matrices(M, K, screw, step, T, delay)
        elif hydraulic is not None:
            Phi, G_old, G_new = hydraulic_plant_matrices(M, K, hydraulic, step, T, delay)
        else:
            Phi, G_old, G_new = plant_matrices(M, K, lag, step, T, delay)
        ns = len(Phi)
        I6, Z = np.eye(6), np.zeros
        # plant with the released command as state: p = (s, u_{k−1}); p' = Pa·p + Ga·u_k; y = Cp·p
        Pa = np.block([[Phi, G_old], [Z((6, ns)), Z((6, 6))]])
        Ga = np.vstack([G_new, I6])
        Cp = np.hstack([I6, Z((6, len(Pa) - 6))])
        Ac, Bc, Cc, Dc = (np.kron(X, I6) for X in controller_matrices(gains, T))
        Bsp, Bm, Dsp, Dm = Bc[:, :6], Bc[:, 6:], Dc[:, :6], Dc[:, 6:]
        # u = Cc·c + Dsp·r + Dm·Cp·p + f
        A = np.block([[Pa + Ga @ Dm @ Cp, Ga @ Cc], [Bm @ Cp, Ac]])
        B = np.block([[Ga @ Dsp, Ga], [Bsp, Z((len(Ac), 6))]])
        C = np.hstack([Cp, Z((6, len(Ac)))])
        D = Z((6, 12))
        return cls(A, B, C, D, (Pa, Ga, Cp), gains, M, K, length_jacobian(platform, pose), lead, T, pose)

    @property
    def spectral_radius(self) -> float:
        """The largest |z| of the closed loop's poles (< 1: stable)."""
        return float(np.abs(np.linalg.eigvals(self.A)).max())

    def _z(self, freqs) -> np.ndarray:
        return np.exp(1j * 2 * np.pi * np.asarray(freqs, dtype=float) * self.T)

    def controller_response(self, freqs) -> tuple[np.ndarray, np.ndarray]:
        """``(c_r, c_y)`` (n,) complex N/m at ``freqs`` (n,) Hz: the PID's command per unit set-point and per unit
        measurement (u = c_r·r − c_y·y)."""
        Ac, Bc, Cc, Dc = controller_matrices(self.gains, self.T)
        out = []
        for z in self._z(freqs):
            H = Cc @ np.linalg.solve(z * np.eye(5) - Ac, Bc) + Dc
            out.append(H[0])
        H = np.array(out)
        return H[:, 0], -H[:, 1]

    def plant_response(self, freqs) -> np.ndarray:
        """``(n, 6, 6)`` complex m/N: the sampled lengths per unit command at ``freqs`` (n,) Hz, through the
        output delay, the actuators and the mechanics."""
        Pa, Ga, Cp = self.plant
        eye = np.eye(len(Pa))
        return np.array([Cp @ np.linalg.solve(z * eye - Pa, Ga) for z in self._z(freqs)])

    def feedforward_gain(self, freqs) -> np.ndarray:
        """``(n, 6, 6)`` complex N/m: the feed-forward rows per unit leg set-point at ``freqs`` (n,) Hz (zero
        without feed-forward)."""
        f = np.asarray(freqs, dtype=float)
        if self.lead is None:
            return np.zeros((len(f), 6, 6), dtype=complex)
        w2 = (2 - 2 * np.cos(2 * np.pi * f * self.T)) / self.T**2
        ph = np.exp(1j * 2 * np.pi * f * self.lead)
        return (self.K[None] - w2[:, None, None] * self.M[None]) * ph[:, None, None]

    def setpoint_parts(self, freqs) -> tuple[np.ndarray, np.ndarray]:
        """``(through_pid, through_feedforward)``, each ``(n, 6, 6)`` complex m/m at ``freqs`` (n,) Hz: the leg
        lengths per unit leg set-point through the PID, and through the feed-forward rows the reference's own
        motion adds (``setpoint_response`` is their sum)."""
        freqs = np.asarray(freqs, dtype=float)
        eye = np.eye(len(self.A))
        ff = self.feedforward_gain(freqs)
        pid, fwd = [], []
        for z, F in zip(self._z(freqs), ff):
            H = self.C @ np.linalg.solve(z * eye - self.A, self.B) + self.D
            pid.append(H[:, :6])
            fwd.append(H[:, 6:] @ F)
        return np.array(pid), np.array(fwd)

    def setpoint_response(self, freqs) -> np.ndarray:
        """``(n, 6, 6)`` complex: the leg lengths per unit leg set-point (m/m) at ``freqs`` (n,) Hz, the
        feed-forward included (entry [i, j]: length i per set-point j)."""
        pid, fwd = self.setpoint_parts(freqs)
        return pid + fwd

    def cartesian_response(self, freqs) -> np.ndarray:
        """``(n, 6, 6)`` complex: the pose per unit pose reference, J⁻¹·T·J (pose in m and rad)."""
        Jinv = np.linalg.inv(self.J)
        return Jinv[None] @ self.setpoint_response(freqs) @ self.J[None]

    def loops(self, freqs) -> tuple[np.ndarray, np.ndarray]:
        """``(L, S)``: ``(n, 6)`` the return ratio of each leg's loop broken at its command with the other legs
        closed, and ``(n, 6, 6)`` the sensitivity S = (I + c_y·G)⁻¹, at ``freqs`` (n,) Hz."""
        _, cy = self.controller_response(freqs)
        G = self.plant_response(freqs)
        S = np.linalg.inv(np.eye(6)[None] + cy[:, None, None] * G)
        L = 1.0 / np.diagonal(S, axis1=1, axis2=2) - 1.0
        return L, S


def default_frequencies(T: float, n: int = 300) -> np.ndarray:
    """``(n,)`` Hz, log-spaced from 0.1 Hz to just below the Nyquist frequency 1/(2T)."""
    return np.logspace(-1, math.log10(0.499 / T), n)


def margins(freqs, L) -> dict:
    """Gain and phase margins of one return ratio ``L`` (n,) complex over ``freqs`` (n,) Hz (ascending):
    ``gain_margin_db`` the smallest |20·log10|L|| where the phase crosses −180° (inf: no crossing),
    ``phase_crossover_hz``; ``phase_margin_deg`` the smallest 180° + ∠L where |L| crosses 1 (inf: none),
    ``gain_crossover_hz``. Crossings are interpolated linearly in log frequency."""
    f = np.asarray(freqs, dtype=float)
    lf = np.log(f)
    mag = np.abs(L)
    ph = np.unwrap(np.angle(L))
    gm, f_gm = math.inf, None
    # phase crossings of −180° (mod 360°)
    r = (ph + np.pi) / (2 * np.pi)
    for i in np.flatnonzero(np.floor(r[:-1]) != np.floor(r[1:])):
        level = np.floor(max(r[i], r[i + 1]))
        s = (level - r[i]) / (r[i + 1] - r[i])
        m = math.exp(np.log(mag[i]) + s * (np.log(mag[i + 1]) - np.log(mag[i])))
        g = abs(20 * math.log10(m))
        if g < gm:
            gm, f_gm = g, math.exp(lf[i] + s * (lf[i + 1] - lf[i]))
    pm, f_pm = math.inf, None
    lm = np.log(mag)
    for i in np.flatnonzero(np.sign(lm[:-1]) != np.sign(lm[1:])):
        s = -lm[i] / (lm[i + 1] - lm[i])
        p = ph[i] + s * (ph[i + 1] - ph[i])
        margin = abs((math.degrees(p) + 180.0 + 180.0) % 360.0 - 180.0)
        if margin < pm:
            pm, f_pm = margin, math.exp(lf[i] + s * (lf[i + 1] - lf[i]))
    return {"gain_margin_db": gm, "phase_crossover_hz": f_gm, "phase_margin_deg": pm, "gain_crossover_hz": f_pm}


def bandwidth(freqs, T_diag) -> float | None:
    """The lowest frequency (Hz) at which ``|T_diag|`` (n,) falls below 1/√2 (interpolated; None: never on
    ``freqs``)."""
    f = np.asarray(freqs, dtype=float)
    below = np.abs(T_diag) < 1 / math.sqrt(2)
    if not below.any():
        return None
    i = int(np.argmax(below))
    if i == 0:
        return float(f[0])
    m0, m1 = np.abs(T_diag[i - 1]), np.abs(T_diag[i])
    s = (m0 - 1 / math.sqrt(2)) / (m0 - m1)
    return float(math.exp(math.log(f[i - 1]) + s * (math.log(f[i]) - math.log(f[i - 1]))))
