"""Whether a reference motion is within the actuators' reach, checked before a closed-loop run.

The force each leg must apply to move plate and legs along the reference is the inverse dynamics at the
controller's ticks (``feedforward.feedforward_forces`` without lead, rates from the sampled reference's
differences, as the firmware's feed-forward table has them); the speed is the legs' length rate.

A piecewise-linear reference asks for a spike of m·Δv/T at every corner, one tick long: the actuator
saturates for that tick and catches up, which the tracking verdict allows (a leg may stay saturated up to
``simulation_log.MAX_SATURATION_S``). What no controller can do is deliver, within that time, an impulse
larger than the force limit times that time: the test is the mean of |F| over every window of
``MAX_SATURATION_S`` against the force limit (a 0.1 m step in 1 ms: ~1e5 m/s², a 50 ms mean of several kN
against 200 N on utn-dynamic; it ran on into raw solver messages). The speed limit (``legs.max_speed``, when
set) is checked tick by tick. Saying so before the run names the cause (where, how much, which limit).
"""

from __future__ import annotations

import numpy as np

from stewart_drake.control.feedforward import feedforward_forces
from stewart_drake.control.simulation_log import MAX_SATURATION_S
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.trajectory import Trajectory


def infeasible_motion(
    platform: Platform, trajectory: Trajectory, ticks, period: float, force_limit: float | None = None
) -> str | None:
    """Why the reference at ``ticks`` (n,) s, differenced over ``period`` s, is beyond the actuators, or None:
    the peak inverse-dynamics leg force against ``force_limit`` (default ``legs.max_force``, N) and the peak
    leg speed against ``legs.max_speed`` (m/s, when set)."""
    ticks = np.asarray(ticks, dtype=float)
    limit = float(platform.legs.max_force if force_limit is None else force_limit)
    F = feedforward_forces(platform, trajectory, ticks, 0.0, period)
    absF = np.where(np.isfinite(F), np.abs(F), np.inf)
    w = max(1, min(len(ticks), int(round(MAX_SATURATION_S / period))))
    c = np.vstack([np.zeros((1, 6)), np.cumsum(absF, axis=0)])
    mean = (c[w:] - c[:-w]) / w  # (n - w + 1, 6): mean |F| over the window starting at each tick
    s, j = np.unravel_index(int(np.argmax(mean)), mean.shape)
    if not mean[s, j] <= limit:
        k = s + int(np.argmax(absF[s : s + w, j]))
        L = leg_lengths(platform, trajectory.pose(ticks[k] + np.array([-period, 0.0, period])))[:, j]
        acc = (L[2] - 2 * L[1] + L[0]) / period**2
        return (
            f"the motion is infeasible: leg {j + 1} needs a mean {mean[s, j]:.4g} N over the {w * period:g} s from "
            f"t = {ticks[s]:.4f} s (peak {absF[k, j]:.4g} N at t = {ticks[k]:.4f} s, leg acceleration {acc:.4g} m/s²), "
            f"more than the actuators' {limit:.4g} N (legs.max_force) for longer than a leg may stay saturated"
        )
    vmax = platform.legs.max_speed
    if vmax is not None:
        L = leg_lengths(platform, trajectory.pose(np.r_[ticks, ticks[-1] + period]))
        v = np.abs(np.diff(L, axis=0)) / period
        k, j = np.unravel_index(int(np.argmax(v)), v.shape)
        if v[k, j] > vmax:
            return (
                f"the motion is infeasible: at t = {ticks[k]:.4f} s leg {j + 1} moves at {v[k, j]:.4g} m/s, "
                f"more than the actuators' {vmax:.4g} m/s (legs.max_speed)"
            )
    return None
