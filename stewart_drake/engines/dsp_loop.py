"""The closed loop of ``drake.tick_loop`` with Pinocchio as the plant: the same law object, the same DSP tick
(``control.dsp_state``: the sensor's reading quantised by the law, ``law.step``, the output released at the next
tick and held), the same actuators (``control.actuation``: saturation, then the lag stepped at every plant step
with the command held before the controller's update there), the same start (the reference's pose and rate,
the controller holding ``initial_leg_forces`` with the feed-forward's share) and the same feed-forward table.
Only the plant differs: Pinocchio's rigid closures and classic RK4 at the plant step (the force constant over
a step, as Drake's actuation input is) in place of Drake's plant and integrator.

The stops are the plant steps m·h (a tick every T = n·h): the loop logs there before its updates (Drake's
logging), then ticks, steps the actuators and advances the plant one step.
"""

from __future__ import annotations

import numpy as np

from stewart_drake.control import dsp_state
from stewart_drake.control.actuation import Actuation
from stewart_drake.control.feedforward import (
    FeedforwardTable,
    feedforward_engine,
    feedforward_lead,
    initial_leg_forces,
)
from stewart_drake.control.laws import FloatLaw
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.engines.plate import plate_state

RATE_STEP = 1e-6  # s: the central difference of the start's rates, as ``drake.simulation`` takes it


def dsp_loop(
    engine,
    platform: Platform,
    trajectory,
    law,
    plant_step: float,
    duration: float,
    time_constant: float,
    max_force: float | None = None,
    feedforward: bool = True,
) -> dict:
    """Run ``law`` (a ``control.laws`` law with ``timing``) on ``engine`` (a ``PinocchioPlatform``) along
    ``trajectory`` (a ``core.trajectory.Trajectory``: ``pose(t)`` (..., 6)) for ``duration`` s with the plant
    step ``plant_step`` s, actuators of lag ``time_constant`` s limited to ``max_force`` N (default the legs').

    The law's period must be a whole number of plant steps and its output released at a tick (latency ``sample``
    or ``none``): the loops ``sd.simulate`` runs by default.

    Returns the logs at t = 0 and every plant step, each before the updates there: ``t`` (n,) s, ``R`` (n, 3, 3)
    and ``p`` (n, 3) the plate frame (R_WT, T's origin, m), ``lengths`` (n, 6) m, ``force`` (n, 6) N,
    ``constraint_m`` the worst closure gap at the logs (m)."""
    timing = law.timing
    T = timing.sample_period
    per = int(round(T / plant_step))
    if per < 1 or abs(per * plant_step - T) > 1e-9 * T or not dsp_state.releases_at_tick(timing):
        # internal: the cross-check runs only the default loops
        raise ValueError(f"period {T} s over plant step {plant_step} s, latency {timing.latency!r}")
    act = Actuation.from_time_constant(
        float(platform.legs.max_force) if max_force is None else max_force, time_constant, plant_step
    )
    n = int(np.floor(duration / plant_step + 1e-9))
    ticks = np.arange(n // per + 1) * T
    ref = trajectory.pose(ticks)
    if hasattr(law, "prime"):
        law.prime(ref)
    ff = None
    if feedforward:
        controller = "float" if isinstance(law, FloatLaw) else "fixed"  # the Drake loop's table (``drake.simulation``)
        lead = feedforward_lead(law.config, time_constant)
        ff = FeedforwardTable(platform, trajectory, lead, T, feedforward_engine(controller)).prime(ticks)
    h = RATE_STEP
    qm, q0, qp = trajectory.pose(np.array([-h, 0.0, h]))
    L0 = leg_lengths(platform, q0)
    rates0 = (leg_lengths(platform, qp) - leg_lengths(platform, qm)) / (2 * h)
    F0 = initial_leg_forces(platform, trajectory)
    held, memory, status = dsp_state.initial_state(law, L0, F0, None if ff is None else ff[0], rates0)
    force = act.saturate(F0) if act.has_lag else act.saturate(held[:6])
    x, v = engine.set_state(plate_state(platform, q0[None], ((qp - qm) / (2 * h))[None]), 0)
    step = engine.stepper()
    at_tick = dsp_state.releases_at_tick(timing)
    out = {k: [] for k in ("R", "p", "lengths", "force")}
    gap = 0.0
    for i in range(n + 1):
        R, p = engine.plate(x)
        L = engine.lengths(x)
        out["R"].append(R)
        out["p"].append(p)
        out["lengths"].append(L)
        out["force"].append(force)
        gap = max(gap, float(engine.closure_residuals_at(x).max()))
        if i == n:
            break
        before = held
        if i % per == 0:
            k = i // per
            new, memory, status = dsp_state.tick(
                law, at_tick, memory, status, k * T, ref[k], L, None if ff is None else ff[k]
            )
            held = held if new is None else new
        force = act.step(force, before[:6]) if act.has_lag else act.saturate(held[:6])
        x, v = step(x, v, force, force, plant_step)
    logs = {k: np.array(a) for k, a in out.items()}
    return {"t": np.arange(n + 1) * plant_step, **logs, "constraint_m": gap}


def loop_difference(platform: Platform, poses, lengths, run: dict, convention: str = "utn") -> dict:
    """The engine's loop ``run`` (``dsp_loop``'s logs) against another's logs at the same times: ``poses``
    (n, 6) the plate's poses and ``lengths`` (n, 6) the legs' (m).

    Returns ``position_m`` the worst plate-origin distance (m), ``angle_rad`` the worst rotation between the two
    plates (rad), ``length_m`` the worst leg-length difference (m)."""
    st = plate_state(platform, poses, convention=convention)
    if st.p.shape != run["p"].shape:  # internal: the callers log the same times
        raise ValueError(f"{len(st.p)} poses against {len(run['p'])} logs")
    c = (np.einsum("kij,kij->k", run["R"], st.R) - 1) / 2
    return {
        "position_m": float(np.linalg.norm(run["p"] - st.p, axis=-1).max()),
        "angle_rad": float(np.arccos(np.clip(c, -1.0, 1.0)).max()),
        "length_m": float(np.abs(run["lengths"] - np.asarray(lengths)).max()),
    }
