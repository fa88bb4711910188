"""The leg actuators as the closed loop computes them between Drake's plant steps: saturation at ±``max_force``,
then a first-order lag discretised exactly at the plant step, F ← a·F + b·sat(u), a = exp(−step/τ), b = 1 − a
(τ = 0: no lag, F = sat(u)). The same numbers as ``drake.systems.Actuators`` (Drake's ``Saturation`` and a
discrete ``LinearSystem`` with A = a·I, B = b·I: each force one product, a second product and their sum, as
numpy computes ``a * F + b * u``), pinned by ``tests/drake/test_tick_loop.py`` against a Diagram built with
them; the loop runs them itself (``drake.tick_loop``, ``firmware.loop_kernel``) rather than as two more
systems Drake evaluates and updates every step."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Actuation:
    """``max_force`` (N), ``a`` and ``b`` the lag's weights (None: no lag); ``from_time_constant`` builds it."""

    max_force: float
    a: float | None = None
    b: float | None = None

    @classmethod
    def from_time_constant(cls, max_force: float, time_constant: float, step: float) -> Actuation:
        """Actuators limited to ``max_force`` N with lag ``time_constant`` s (0: none) at plant step ``step`` s
        (``drake.systems.Actuators``'s a = exp(−step/τ) and B = (1 − a)·I)."""
        if time_constant > 0:
            a = math.exp(-step / time_constant)
            return cls(float(max_force), a, 1 - a)
        return cls(float(max_force))

    @property
    def has_lag(self) -> bool:
        return self.a is not None

    def saturate(self, u) -> np.ndarray:
        """``(6,)`` the command ``u`` (N) saturated at ±max_force."""
        m = self.max_force
        return np.minimum(np.maximum(np.asarray(u, dtype=float), -m), m)

    def step(self, F, u) -> np.ndarray:
        """The lag's state after a plant step from ``F`` (6, N) with command ``u`` (6, N): a·F + b·sat(u)."""
        return self.a * F + self.b * self.saturate(u)
