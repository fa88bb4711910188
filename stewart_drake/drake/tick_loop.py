"""The closed loop's ticks run outside the Diagram: Drake advances the plant (and the actuators' lag) from
one event time to the next with ``Simulator.AdvanceTo``; between two calls, one tight Python loop does
what the DSP does at that instant — read the plant state once, the sensor, the law's tick
(``control.dsp_state``: the same code as ``drake.systems.ControllerSystem``), the output release —
reads the reference and feed-forward rows of the tick by index, writes the held command to the
actuators' fixed input in place, and logs the controller's outputs into preallocated arrays. No Python
runs inside ``AdvanceTo``.

Why the logs are those of the all-Drake Diagram (a ``ControllerSystem`` wired to the plant), bit for bit
(``tests/drake/test_tick_loop.py`` runs both): the loop stops at every time the Diagram had an event
(plant steps m·h, ticks k·T, releases k·T + delay, each computed as Drake computes periodic times,
``offset + k·period``; the progress bar's and the visualizer's times), so the integrator takes the same
steps; at each stop Drake has published (the plant loggers sampled) before the loop's updates, as the
Simulator publishes at t before the discrete updates at t; and the actuators' discrete update at t reads
the command held *before* the controller's update at t (simultaneous discrete updates read the old
state), except for a continuous plant without lag, which integrates with the command just released. A
discrete (SAP) plant steps by an unrestricted update, which Drake runs before the discrete ones: its tick
reads the state after the plant's step at t, so the loop advances halfway to the next stop first (nothing
happens there) and logs the plant state and forces itself at every stop (Drake's per-step logging).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stewart_drake.control import dsp_state
from stewart_drake.control.loop_sensor import IdealSensor, SensorReading
from stewart_drake.firmware.loop_kernel import make_kernel

__all__ = ["IdealSensor", "SensorReading", "TickLoop", "periodic_times", "schedule"]


@dataclass(frozen=True)
class Schedule:
    """The stops of a run after t = 0, in order: ``times`` (s), and per stop whether the plant loggers
    record there (``log``), the tick index (``tick``, −1: none) and whether the output is released there
    (``release``); ``boundary``: stops the caller asked for (a progress update)."""

    times: list
    log: list
    tick: list
    release: list
    boundary: list


def periodic_times(offset: float, period: float, end: float) -> np.ndarray:
    """The times in (0, ``end``] of a Drake periodic event, computed as Drake does: offset + k·period."""
    k = np.arange(int(np.floor((end - offset) / period)) + 2)
    t = offset + k * period
    return t[(t > 0) & (t <= end)]


def schedule(
    duration: float, step: float, period: float, delay: float | None, log_every_stop: bool, extra=()
) -> Schedule:
    """The stops of a run of ``duration`` s: plant steps m·``step``, ticks k·``period``, releases
    ``delay`` + k·``period`` (None: none), the ``extra`` times (boundaries) and ``duration`` itself, all in
    (0, duration]. The plant loggers record at the plant steps (``log_every_stop``: at every stop, Drake's
    per-step logging of a discrete plant)."""

    steps, ticks = periodic_times(0.0, step, duration), periodic_times(0.0, period, duration)
    releases = periodic_times(delay, period, duration) if delay is not None else np.zeros(0)
    extra = np.asarray([t for t in extra if 0 < t <= duration], dtype=float)
    times = np.unique(np.concatenate([steps, ticks, releases, extra, [duration]]))
    tick_of = {float(t): int(k) for k, t in zip(np.round(ticks / period).astype(int), ticks)}
    steps_set, release_set, extra_set = set(steps.tolist()), set(releases.tolist()), set(extra.tolist())
    tl = times.tolist()
    return Schedule(
        tl,
        [log_every_stop or t in steps_set for t in tl],
        [tick_of.get(t, -1) for t in tl],
        [t in release_set for t in tl],
        [t in extra_set for t in tl],
    )


class TickLoop:
    """The DSP side of a closed loop, run between ``AdvanceTo`` calls (see the module's docstring).

    ``simulator``: the plant's Simulator (initialised); ``plant``, ``plant_context``; ``command_input``:
    the actuators' command input port of the Diagram (fixed here); ``law``: the control law;
    ``sensor``: ``(t, x) -> (6,)`` readings of the plant state ``x``; ``step`` (s): the plant step;
    ``input_after_update``: the plant integrates with the command released at a stop (continuous plant,
    no actuator lag) rather than the actuators sampling the command held before it; ``force``: for a
    discrete plant, ``(port, context)`` of the actuators' force, logged here with the plant state at
    every stop (a discrete plant's per-step logs; the continuous plant's are Drake loggers)."""

    def __init__(self, simulator, plant, plant_context, command_input, law, sensor, step, input_after_update, force):
        self.simulator, self.plant, self.plant_context = simulator, plant, plant_context
        self.law, self.sensor, self.step = law, sensor, step
        self.timing = law.timing
        self.at_tick = dsp_state.releases_at_tick(self.timing)
        self.input_after_update = input_after_update
        self.force = force
        self.discrete = force is not None
        self.held = self.memory = self.status = None
        self.reference = self.feedforward = None
        root = simulator.get_mutable_context()
        self._fixed = command_input.FixValue(root, np.zeros(6))
        # the compiled DSP side (one C call per stop), None: the Python loop below (``firmware.loop_kernel``)
        self.kernel = make_kernel(law, sensor)

    def prime(self, poses) -> None:
        """The law's tables for the reference ``(n_ticks, 6)`` poses of the ticks 0, 1, … (one batch; speed
        only): the compiled kernel's set-points or pose words, else the law's own ``prime``."""
        if self.kernel is not None:
            self.kernel.tables(poses)
        elif hasattr(self.law, "prime"):
            self.law.prime(poses)

    def initialize(self, lengths, hold_forces=None, feedforward=None, rates=None) -> None:
        """The controller's state as if it had been holding ``lengths`` (``dsp_state.initial_state``)."""
        self.held, self.memory, self.status = dsp_state.initial_state(
            self.law, lengths, hold_forces, feedforward, rates
        )
        self._set_input(self.held)

    def _set_input(self, held) -> None:
        self._fixed.GetMutableData().get_mutable_value().SetFromVector(held[:6])
        self._input_held = held

    def run(self, duration: float, boundaries=(), on_boundary=None) -> dict:
        """Advance from t = 0 to ``duration`` s; ``on_boundary(t)`` is called at each of ``boundaries``.
        Returns the logs at the plant loggers' times (the held values, before the updates at each time):
        ``command`` (n, 6) N, ``setpoint`` (n, 6) m, ``status`` (n, len(STATUS)); for a discrete plant
        also ``state`` (n, nx) and ``force`` (n, 6) N."""
        T = self.timing.sample_period
        delay = None if self.at_tick else self.timing.output_delay
        s = schedule(duration, self.step, T, delay, self.discrete, boundaries)
        if self.kernel is not None:
            return self._run_kernel(duration, s, on_boundary)
        n = 1 + sum(s.log)
        held_log, status_log = np.empty((n, 12)), np.empty((n, len(self.status)))
        ref, ff = self.reference, self.feedforward
        law, at_tick, sensor = self.law, self.at_tick, self.sensor
        # which command the Diagram reads until the next stop: the one held before this stop's updates
        # (the actuators' lag samples it at the stop), or the one just released (a continuous plant
        # without lag integrates with it; a discrete plant has already stepped, see below)
        after = self.input_after_update or self.discrete
        pc, get_x = self.plant_context, self.plant.GetPositionsAndVelocities
        advance = self.simulator.AdvanceTo
        held, memory, status = self.held, self.memory, self.status
        if self.discrete:
            x_log, force_log = np.empty((n, self.plant.num_multibody_states())), np.empty((n, 6))
            force_port, force_context = self.force
            x_log[0], force_log[0] = get_x(pc), force_port.Eval(force_context)
            steps = set(periodic_times(0.0, self.step, duration).tolist()) | {0.0}
        held_log[0], status_log[0] = held[:12], status
        row, last = 1, len(s.times) - 1
        t, k, rel = 0.0, 0, False  # t = 0: Initialize has published; the tick at 0 is next
        for i in range(-1, last + 1):
            if i >= 0:
                t, k, rel = s.times[i], s.tick[i], s.release[i]
                advance(t)
                if s.log[i]:
                    held_log[row, :], status_log[row, :] = held[:12], status
                    if self.discrete:
                        x_log[row, :], force_log[row, :] = get_x(pc), force_port.Eval(force_context)
                    row += 1
                if s.boundary[i] and on_boundary is not None:
                    on_boundary(t)
                if i == last:
                    break  # the updates at the end time are not run (Drake's AdvanceTo stops before them)
            before = held
            if self.discrete and (k >= 0 or rel) and t in steps:
                # a discrete plant steps (an unrestricted update) before any discrete update at t: the tick
                # reads the step's result and the actuators' lag the command held before the tick. Halfway
                # to the next stop nothing else happens (no continuous state, no event, no logging).
                advance(0.5 * (t + s.times[i + 1]))
            if k >= 0:
                L = sensor(t, get_x(pc))
                new_held, memory, status = dsp_state.tick(
                    law, at_tick, memory, status, t, ref[k], L, None if ff is None else ff[k]
                )
                held = held if new_held is None else new_held
            elif rel:
                new_held, status = dsp_state.release(memory, status, t)
                held = held if new_held is None else new_held
            now = held if after else before
            if now is not self._input_held:
                self._set_input(now)
        self.held, self.memory, self.status = held, memory, status
        logs = {"command": held_log[:, :6], "setpoint": held_log[:, 6:], "status": status_log}
        if self.discrete:
            times = np.array([0.0] + [t for t, logged in zip(s.times, s.log) if logged])
            logs |= {"times": times, "state": x_log, "force": force_log}
        return logs

    _input_held = None

    def _views(self):
        """Numpy views of the plant state and of the command input where Drake keeps them (no copies):
        the plant context's continuous (or, for a discrete plant, discrete) state vector — positions then
        velocities, ``GetPositionsAndVelocities``'s layout — and the fixed input's vector. Drake writes a
        step's result into the same memory, so the views hold for the run (``tests/drake/test_tick_loop.py``)."""
        pc = self.plant_context
        state = pc.get_discrete_state(0) if self.discrete else pc.get_continuous_state_vector()
        x = state.get_value()
        if x.shape != (self.plant.num_multibody_states(),):  # a plant with other state: not this loop's
            raise RuntimeError(f"plant state of {x.shape} values, {self.plant.num_multibody_states()} expected")
        return x, self._fixed.GetMutableData().get_mutable_value().get_mutable_value()

    def _run_kernel(self, duration: float, s: Schedule, on_boundary) -> dict:
        """``run`` with the compiled DSP side (``firmware.loop_kernel``): per stop one ``AdvanceTo`` and one C
        call (log, tick or release, the command written in Drake's memory), and Drake told of a new command
        (``GetMutableData``) only when it changed. The stops that need Python — a boundary with a callback,
        a discrete plant's step before its tick — split the call in two around it."""
        n = 1 + sum(s.log)
        logs = {"held": np.empty((n, 12)), "status": np.empty((n, len(self.status)))}
        if self.discrete:
            logs["x"] = np.empty((n, self.plant.num_multibody_states()))
            force_log = np.empty((n, 6))
            force_port, force_context = self.force
        x, command = self._views()
        kern, after = self.kernel, self.input_after_update or self.discrete
        kern.start(x, command, s, self.feedforward, self.held, self.memory, self.status, self.at_tick, after, logs)
        notify, advance, stop = self._fixed.GetMutableData, self.simulator.AdvanceTo, kern.stop
        times, last = s.times, len(s.times) - 1
        split = {i for i in range(len(times)) if s.boundary[i] and on_boundary is not None}
        half = {}
        if self.discrete:
            steps = set(periodic_times(0.0, self.step, duration).tolist()) | {0.0}
            half = {
                i: 0.5 * (times[i] + times[i + 1])
                for i in range(last)
                if (s.tick[i] >= 0 or s.release[i]) and times[i] in steps
            }
            split = set(range(len(times)))  # the forces are logged by Drake's port at every stop
            if 0.0 in steps:  # the tick at t = 0 after the plant's step at 0
                half[-1] = 0.5 * times[0]
        kern.log(kern.s, -1)
        if self.discrete:
            force_log[0] = force_port.Eval(force_context)
        if -1 in half:
            advance(half[-1])
        self._kernel_update(-1)
        for i in range(last):
            advance(times[i])
            if i in split:
                kern.log(kern.s, i)
                if self.discrete:
                    force_log[kern.s.row - 1] = force_port.Eval(force_context)
                if s.boundary[i] and on_boundary is not None:
                    on_boundary(times[i])
                if i in half:
                    advance(half[i])
                self._kernel_update(i)
            else:
                r = stop(kern.s, i)
                if r:
                    if r < 0:
                        kern.raise_error(r)
                    notify()
        advance(times[last])  # the updates at the end time are not run (Drake's AdvanceTo stops before them)
        kern.log(kern.s, last)
        if self.discrete:
            force_log[kern.s.row - 1] = force_port.Eval(force_context)
        if s.boundary[last] and on_boundary is not None:
            on_boundary(times[last])
        if kern.s.row != n:
            raise RuntimeError(f"the loop logged {kern.s.row} rows of {n}")  # a bug
        self.held, self.memory, self.status = kern.state()
        held = logs["held"]
        out = {"command": held[:, :6], "setpoint": held[:, 6:], "status": logs["status"]}
        if self.discrete:
            t = np.array([0.0] + [t for t, logged in zip(times, s.log) if logged])
            out |= {"times": t, "state": logs["x"], "force": force_log}
        return out

    def _kernel_update(self, i: int) -> None:
        r = self.kernel.update(self.kernel.s, i)
        if r < 0:
            self.kernel.raise_error(r)
        if r:
            self._fixed.GetMutableData()
