"""The DSP's discrete state around a control law, as plain numpy: what one tick and one output release do
to it. One implementation for both places a controller runs: ``drake.systems.ControllerSystem`` (the
state in a Drake context) and ``drake.tick_loop`` (the closed loop's own arrays, no Python inside the
Diagram).

The state is ``held`` (12: the released command, N, then set-point, m: what the outputs show),
``memory`` (42: ``pending``, the command and set-point computed but not yet released (12), then the law's
PID state (30)) and ``status`` (``control.STATUS``). A tick's result is released after the output delay
(``DspTiming.latency``): ``none`` at the tick itself, ``sample`` at the next tick (k+1)·T, ``computation``
by a separate release at k·T + t_comp.
"""

from __future__ import annotations

import numpy as np

from stewart_drake.control.laws import STATUS


def releases_at_tick(timing) -> bool:
    """Whether the previous tick's result is released at the tick itself (latency ``sample``, or an
    output delay of 0 or ≥ T) rather than by a separate release event at k·T + delay."""
    return timing.latency == "sample" or not 0.0 < timing.output_delay < timing.sample_period


def initial_state(law, lengths, hold_forces=None, feedforward=None, rates=None) -> tuple:
    """``(held (12,), memory (42,), status)`` of a controller that has been holding ``lengths`` (6, m)
    with ``hold_forces`` (6, N; e.g. the static forces against gravity) for a while; with a
    ``feedforward`` (6, N) its integrator holds only hold − feed-forward; with ``rates`` (6, m/s) as if the
    legs had been moving at those rates (no start-up kick from the difference filters)."""
    lengths = np.asarray(lengths, dtype=float).reshape(6)
    F = np.zeros(6) if hold_forces is None else np.asarray(hold_forces, dtype=float).reshape(6)
    ff = np.zeros(6) if feedforward is None else np.asarray(feedforward, dtype=float).reshape(6)
    pid = law.initial_pid_state(lengths, F - ff, rates)
    held = np.concatenate([law.command_from_integrator(pid[:6], ff), lengths])
    return held, np.concatenate([held, pid]), np.zeros(len(STATUS))


def tick(law, at_tick: bool, memory, status, t: float, reference, lengths, feedforward) -> tuple:
    """One tick at time ``t`` (s): ``law.step`` on the PID state in ``memory`` with the ``reference``
    pose (6), the sensor's ``lengths`` (6, m) and the ``feedforward`` (6, N, or None). Returns
    ``(held, memory, status)``: ``held`` the 12 values released now (None: no release at this tick),
    the new memory and status (new arrays; the arguments are not changed). ``at_tick``:
    ``releases_at_tick`` of the law's timing."""
    command, setpoint, pid_new, saturated = law.step(memory[12:], reference, lengths, feedforward)
    st = status.copy()
    st[0] += 1
    st[1] = t
    st[3] += float(saturated.any())
    st[4:10] += saturated
    new = np.concatenate([command, setpoint, pid_new])
    held = None
    if law.timing.latency == "none":
        held = new
        st[2] = t
    elif at_tick and st[0] > 1:
        held = memory  # the previous tick's result, released now at (k+1)·T
        st[2] = t
    return held, new, st


def release(memory, status, t: float) -> tuple:
    """The separate release at time ``t`` (latency ``computation``): ``(held, status)``, ``held`` the
    pending command and set-point (12; None before the first tick, status then unchanged)."""
    if status[0] < 1:
        return None, status
    st = status.copy()
    st[2] = t
    return memory[:12], st
