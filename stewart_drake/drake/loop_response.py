"""The closed leg loop's response measured on the nonlinear Drake loop: a small sine on one leg's set-point about a
held pose, run through the real controller (the float law, or the compiled fixed-point firmware) and the
closed-chain plant, its leg-length response fitted by least squares.

The tolerance of a measured point against the linear model (``control.frequency.LoopModel``) is the sum of
(``MeasuredPoint.tolerance``):

- the fit's standard error, three times (the residual's RMS · √(2/n) per coefficient, over the amplitude);
- the sensor's count ``r``: a bounded error of r/2 moves the fitted sine by at most 4/π · r/2 (its projection on
  a sine), 0.64·r/A per unit response (the set-points' own rounding is in the model's input: the fitted sine of
  the set-points the law computes, ``setpoints``);
- the linearisation: the neglected terms are second order in the amplitude A over the platform's lengths, a
  relative plant error of order A/ℓ (ℓ the shortest leg at the pose);
- the start's transient: the loop starts on the reference, (1 + |H|)·A from its sinusoidal steady state at
  most, decayed by ``TRANSIENT_LEFT`` at the fit (the slowest pole's decay);
- the plant's integrator: CENIC's convex step is first order, a phase error of ω·h/2 at plant step h (a
  relative plant error of that size);
- a relative plant error ε moves the set-point response T by ε·S·T to first order (S = (I + c_y·G)⁻¹): the two
  plant terms count σ̄(S(ω))·‖T e_leg‖·ε — near a lightly damped mode the loop itself magnifies them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import partial

import numpy as np

from stewart_drake.control.frequency import LoopModel
from stewart_drake.control.laws import FixedPointLaw, FloatLaw
from stewart_drake.control.screw import FRICTION_SPEED
from stewart_drake.core.kinematics import leg_lengths, length_jacobian
from stewart_drake.core.trajectory import Trajectory
from stewart_drake.drake.simulation import Scenario, build_simulation

# The sine's command (set-point term, measurement term and feed-forward, from the linear model) is kept below this
# share of the command range: the loop stays far from saturation, where it is linear.
COMMAND_SHARE = 0.1
# The fit starts once the slowest closed-loop pole of the linear model has decayed to this fraction.
TRANSIENT_LEFT = 2e-3


@dataclass(frozen=True)
class MeasuredPoint:
    """One frequency of the measured response: ``freq`` Hz, ``leg`` (0-based) driven with ``amplitude`` m;
    ``response`` (6,) complex: each leg's length per unit amplitude; ``linear`` (6,) complex: the model's for the
    set-points the law computed (``setpoints``) and the reference's feed-forward;
    ``tolerance`` (6,) the allowed |response − linear|; ``residual`` the fit's RMS residual over the amplitude."""

    freq: float
    leg: int
    amplitude: float
    response: np.ndarray
    linear: np.ndarray
    tolerance: np.ndarray
    residual: float

    @property
    def agrees(self) -> bool:
        return bool(np.all(np.abs(self.response - self.linear) <= self.tolerance))


def setpoints(scenario: Scenario, poses) -> np.ndarray:
    """``(n, 6)`` leg set-points (m) the scenario's law computes from ``poses`` (n, 6): the fixed-point IK's
    words times their LSB (``laws.FixedPointLaw``, the C firmware's twin), or the float law's IK."""
    cfg = scenario.config
    if scenario.controller == "fixed":
        return FixedPointLaw(scenario.platform, cfg).ik_words(poses) * cfg.ik_format.length_lsb
    return FloatLaw(scenario.platform, cfg).setpoints(poses)


def settle_time(model: LoopModel) -> float:
    """Seconds until the slowest closed-loop pole of a stable ``model`` has decayed to ``TRANSIENT_LEFT``."""
    return math.log(1 / TRANSIENT_LEFT) / (-math.log(model.spectral_radius) / model.T)


def measure_duration(model: LoopModel, freq: float, window: float = 0.5) -> float:
    """Simulated seconds ``measure_point`` runs at ``freq`` Hz: the settling and whole periods spanning ``window`` s."""
    return settle_time(model) + max(2, math.ceil(window * freq)) / freq


def _sine_pose(pose, dq, w, t):
    return pose + np.sin(w * np.asarray(t, dtype=float))[..., None] * dq


def sine_amplitude(model: LoopModel, freq: float, leg: int, command_range: float, amplitude: float) -> float:
    """The set-point amplitude (m): ``amplitude``, or less where the model's command perturbation would exceed
    ``COMMAND_SHARE`` of ``command_range`` (N)."""
    cr, cy = model.controller_response([freq])
    U = cr[0] * np.eye(6) - cy[0] * model.setpoint_response([freq])[0] + model.feedforward_gain([freq])[0]
    return float(min(amplitude, COMMAND_SHARE * command_range / np.abs(U[:, leg]).max()))


def measure_point(
    scenario: Scenario,
    model: LoopModel,
    freq: float,
    leg: int = 0,
    amplitude: float = 1e-3,
    window: float = 0.5,
) -> MeasuredPoint:
    """Drive leg ``leg``'s set-point with a sine of ``freq`` Hz about ``model.pose`` (the pose moves by
    J⁻¹·e_leg·A·sin ωt, so the other legs' set-points move only to second order) through ``scenario``'s loop,
    and fit the ticks' leg lengths over whole periods spanning at least ``window`` s after the start's
    transient. ``amplitude`` (m): at most, see ``sine_amplitude`` (with screw actuators, also at most
    v_s/(20π·freq): the leg's velocity a tenth of the friction's blend, ``control.screw.FRICTION_SPEED``)."""
    T = model.T
    pose = model.pose
    if scenario.actuators.screw is not None:  # the screws' small signal: |L̇| ≤ v_s/10, where tanh is linear
        amplitude = min(amplitude, FRICTION_SPEED / (20 * math.pi * freq))
    A = sine_amplitude(model, freq, leg, scenario.config.timing.command_range, amplitude)
    w = 2 * math.pi * freq
    dq = np.linalg.solve(length_jacobian(scenario.platform, pose), np.eye(6)[leg]) * A
    traj = Trajectory(f"sine {freq:g} Hz", partial(_sine_pose, pose, dq, w))
    settle = settle_time(model)
    duration = measure_duration(model, freq, window)
    log = build_simulation(replace(scenario, trajectory=traj, duration=duration)).run(duration)
    k = np.round(log.t / T)
    at = np.isclose(log.t, k * T, atol=1e-9 * T) & (log.t >= settle - 1e-9 * T)
    t, y = log.t[at], log.lengths[at]
    cols = [np.ones_like(t), np.sin(w * t), np.cos(w * t)]
    X = np.stack(cols, axis=1)
    coef, *_ = np.linalg.lstsq(X, y, rcond=None)
    res = y - X @ coef
    response = (coef[1] + 1j * coef[2]) / A
    # the set-points the law computes from the reference's poses at the fitted ticks (the fixed-point IK's words
    # are not exactly J·δq): their sine drives the PID; the feed-forward rows follow the reference itself
    S = np.linalg.lstsq(X, setpoints(scenario, traj.pose(t)), rcond=None)[0]
    S = (S[1] + 1j * S[2]) / A
    pid, fwd = model.setpoint_parts([freq])
    linear = pid[0] @ S + fwd[0][:, leg]
    sigma = np.sqrt(np.mean(res**2, axis=0)) * math.sqrt(2.0 / len(t)) / A
    ell = float(leg_lengths(scenario.platform, pose).min())
    r = scenario.config.timing.sensor_resolution
    # a relative plant error ε moves the set-point response T by ε·S·T (first order): the model terms are scaled
    # by the sensitivity's largest singular value at this frequency and the response's size
    s_max = float(np.linalg.svd(model.loops([freq])[1][0], compute_uv=False)[0])
    model_error = s_max * np.linalg.norm(linear) * (A / ell + w * scenario.plant_time_step / 2)
    tol = 3 * sigma + 0.64 * r / A + model_error
    tol = tol + TRANSIENT_LEFT * (1 + np.abs(linear))
    return MeasuredPoint(float(freq), leg, A, response, linear, tol, float(np.sqrt(np.mean(res[:, leg] ** 2)) / A))
