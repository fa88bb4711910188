"""The leg-length sensors of the closed loop (``drake.tick_loop``), on the plant state vector ``x``
(positions, then velocities: ``MultibodyPlant.GetPositionsAndVelocities``'s layout). Plain numpy; the compiled
loop (``firmware.loop_kernel``) computes the same readings in C."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, eq=False)
class IdealSensor:
    """The true leg lengths: ``x[positions]`` (``positions``: the six prismatic joints' indices in ``x``)."""

    positions: np.ndarray

    def __call__(self, t: float, x) -> np.ndarray:
        return x[self.positions]


@dataclass(frozen=True, eq=False)
class SensorReading:
    """A leg-length sensor on the plant state ``x``: L + ``offset`` (6, m) + ``noise[k]`` − ``jitter[k]``·dL/dt
    at tick k = round(t / ``period``) (rows ``(n_ticks, 6)`` m and ``(n_ticks,)`` s, the last row reused
    beyond the table); ``positions``, ``velocities``: the six prismatic joints' indices in the state."""

    positions: np.ndarray
    velocities: np.ndarray
    offset: np.ndarray
    noise: np.ndarray
    jitter: np.ndarray
    period: float

    def __call__(self, t: float, x) -> np.ndarray:
        k = min(int(round(t / self.period)), len(self.jitter) - 1)
        return x[self.positions] + self.offset + self.noise[k] - self.jitter[k] * x[self.velocities]

    def initial_reading(self, L):
        """The reading of true lengths ``L`` (6, m) at rest before t = 0: L + offset."""
        return np.asarray(L, float) + self.offset
