"""What a person perceives of a motion: the otolith (specific force) and semicircular-canal (angular velocity)
models, per head axis, as continuous transfer functions, their state-space forms and a filter over a drive.

Both are the models of Reid & Nahon's classical-washout study (Reid, L. D., Nahon, M. A., "Flight simulation
motion-base drive algorithms: part 1", UTIAS Report 296, 1985), which takes them from Young & Meiry (1968) and
Zacharias (1978):

- otolith, each axis: ``f̂/f = K (τ_a s + 1) / ((τ_L s + 1)(τ_s s + 1))`` with τ_a = 13.2 s, τ_L = 5.33 s,
  τ_s = 0.66 s (Young & Meiry); K = 1 here (the papers' K = 0.4 only scales the afferent firing rate), so the
  perceived specific force is in m/s² and equals the stimulus at steady state;
- semicircular canals, each axis: ``ω̂/ω = τ_a τ_L s² / ((τ_a s + 1)(τ_L s + 1)(τ_s s + 1))`` (the torsion
  pendulum τ_L, τ_s and the adaptation τ_a) with τ_L = 6.1 s (roll), 5.3 s (pitch), 10.2 s (yaw), τ_s = 0.1 s,
  τ_a = 30 s (Zacharias); unit gain between 1/τ_L and 1/τ_s, zero at steady state.

The perception thresholds are those of the same table: 0.17 m/s² (x, y), 0.28 m/s² (z) and 3.0, 3.6, 2.6 °/s
(roll, pitch, yaw). ``perceive`` filters a drive through the models (bilinear transform at the drive's step,
each filter starting at rest at the drive's first value).
"""

from __future__ import annotations

import functools

import numpy as np
from scipy import signal

from stewart_drake.control.cueing.drive import Drive

OTOLITH_TAU = (13.2, 5.33, 0.66)  # s: τ_a (lead), τ_L, τ_s (Young & Meiry 1968), same on every axis
CANAL_TAU_L = (6.1, 5.3, 10.2)  # s: roll, pitch, yaw (Zacharias 1978)
CANAL_TAU_S = 0.1  # s
CANAL_TAU_A = 30.0  # s: adaptation
FORCE_THRESHOLD = np.array([0.17, 0.17, 0.28])  # m/s², x, y, z
RATE_THRESHOLD = np.radians([3.0, 3.6, 2.6])  # rad/s, roll, pitch, yaw


def otolith_tf(axis: int) -> tuple[np.ndarray, np.ndarray]:
    """``(num, den)`` in descending powers of s: the otolith's perceived over actual specific force on ``axis``
    (0, 1, 2: x, y, z)."""
    _axis(axis)
    ta, tl, ts = OTOLITH_TAU
    return np.array([ta, 1.0]), np.polymul([tl, 1.0], [ts, 1.0])


def canal_tf(axis: int) -> tuple[np.ndarray, np.ndarray]:
    """``(num, den)`` in descending powers of s: the canal's perceived over actual angular velocity on ``axis``
    (0, 1, 2: roll, pitch, yaw)."""
    tl = CANAL_TAU_L[_axis(axis)]
    return np.array([CANAL_TAU_A * tl, 0.0, 0.0]), np.polymul(
        np.polymul([CANAL_TAU_A, 1.0], [tl, 1.0]), [CANAL_TAU_S, 1.0]
    )


def otolith_ss(axis: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Continuous ``(A, B, C, D)`` of ``otolith_tf(axis)``: ``ẋ = A x + B f``, ``f̂ = C x + D f``
    (two states; f in m/s²)."""
    return signal.tf2ss(*otolith_tf(axis))


def canal_ss(axis: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Continuous ``(A, B, C, D)`` of ``canal_tf(axis)``: ``ẋ = A x + B ω``, ``ω̂ = C x + D ω``
    (three states; ω in rad/s)."""
    return signal.tf2ss(*canal_tf(axis))


def _axis(axis: int) -> int:
    if axis not in (0, 1, 2):
        raise ValueError(f"axis must be 0, 1 or 2, got {axis!r}")  # internal: callers pass 0..2
    return axis


def bilinear(num, den, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """``(b, a)``: the continuous ``num/den`` (descending powers of s) with s = (2/dt)(z − 1)/(z + 1), as
    ``scipy.signal.bilinear`` (whose polynomial classes cost milliseconds a call: the tuning makes thousands)."""
    n = max(len(num), len(den)) - 1
    k = 2.0 / dt
    terms = []
    for power in range(n, -1, -1):  # (k (z − 1))^power (z + 1)^(n − power)
        term = np.array([1.0])
        for _ in range(power):
            term = np.convolve(term, [k, -k])
        for _ in range(n - power):
            term = np.convolve(term, [1.0, 1.0])
        terms.append(term)

    def poly(c):
        c = np.concatenate([np.zeros(n + 1 - len(c)), np.asarray(c, dtype=float)])
        return np.sum([ci * term for ci, term in zip(c, terms)], axis=0)

    b, a = poly(num), poly(den)
    return b / a[0], a / a[0]


def filter_series(tf: tuple[np.ndarray, np.ndarray], u: np.ndarray, dt: float) -> np.ndarray:
    """``u`` ``(N,)`` through the continuous ``tf`` discretised by the bilinear transform at ``dt`` s, starting
    at rest at ``u[0]`` (the filter's steady state for a constant ``u[0]``)."""
    b, a, zi = _discrete(tuple(tf[0]), tuple(tf[1]), dt)
    y, _ = signal.lfilter(b, a, u, zi=zi * u[0])
    return y


@functools.lru_cache(maxsize=256)
def _discrete(num: tuple, den: tuple, dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(b, a, zi)`` of ``bilinear`` and ``lfilter_zi``, once per filter and step (the models are fixed)."""
    b, a = bilinear(num, den, dt)
    return b, a, signal.lfilter_zi(b, a)


def perceive(drive: Drive) -> Drive:
    """The perceived motion of ``drive``: its specific force through the otoliths and its angular velocity
    through the canals, per head axis (``(N, 3)`` each, same units and times; no attitude)."""
    f = np.column_stack([filter_series(otolith_tf(i), drive.specific_force[:, i], drive.dt) for i in range(3)])
    w = np.column_stack([filter_series(canal_tf(i), drive.angular_velocity[:, i], drive.dt) for i in range(3)])
    return Drive(f"{drive.name} (perceived)", drive.t, f, w)
