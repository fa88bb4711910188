"""The closed loop's ticks run outside the Diagram: Drake advances the plant (and the actuators' lag) from
one event time to the next with ``Simulator.AdvanceTo``; between two calls the loop does what the DSP does
at that instant — read the plant state, the sensor, the law's tick (``control.dsp_state``: the same code as
``drake.systems.ControllerSystem``), the output release — reading the reference and feed-forward rows of the
tick by index, writes the held command to the actuators' fixed input and logs the controller's outputs, the
plant state and the actuators' force into preallocated arrays (the Diagram has no loggers). No Python runs
inside ``AdvanceTo``. All of a stop's work is one call into C (``firmware.loop_kernel``: the float law or the
compiled firmware, reading and writing Drake's memory through numpy views obtained once); the Python loop
(``_run_python``) is the reference and the fallback (the firmware's Python emulation, no C compiler).
A run can be continued (``TickLoop.extend``): the same stops and numbers as one longer run.

Why the logs are those of the all-Drake Diagram (a ``ControllerSystem`` wired to the plant), bit for bit
(``tests/drake/test_tick_loop.py`` runs both): the loop stops at every time the Diagram had an event
(plant steps m·h, ticks k·T, releases k·T + delay, each computed as Drake computes periodic times,
``offset + k·period``; the progress bar's and the visualizer's times), so the integrator takes the same
steps; at each stop the loop logs what the Diagram's loggers sampled (a publish at t comes before the
discrete updates at t; the actuators' force is their lag's state, or the saturated command) before its updates; and the actuators' discrete update at t reads
the command held *before* the controller's update at t (simultaneous discrete updates read the old
state), except for a continuous plant without lag, which integrates with the command just released. A
discrete (SAP) plant steps by an unrestricted update, which Drake runs before the discrete ones: its tick
reads the state after the plant's step at t, so the loop advances halfway to the next stop first (nothing
happens there) and logs at every stop (Drake's per-step logging).
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
    """The stops of a run after t = 0, in order: ``times`` (s), and per stop whether the loop logs there
    (``log``), the tick index (``tick``, −1: none), whether the output is released there (``release``) and
    whether it is a plant step (``step``: the actuators' lag steps there); ``boundary``: stops the caller
    asked for (a progress update)."""

    times: list
    log: list
    tick: list
    release: list
    boundary: list
    step: list


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
    (0, duration]. The loop logs at the plant steps (``log_every_stop``: at every stop, Drake's per-step
    logging of a discrete plant)."""

    steps, ticks = periodic_times(0.0, step, duration), periodic_times(0.0, period, duration)
    releases = periodic_times(delay, period, duration) if delay is not None else np.zeros(0)
    extra = np.asarray([t for t in extra if 0 < t <= duration], dtype=float)
    times = np.unique(np.concatenate([steps, ticks, releases, extra, [duration]]))
    # membership by exact equality, as Drake's event times and these are the same doubles (numpy, no
    # Python per stop: a run has a stop per plant step)
    log = np.ones(len(times), dtype=bool) if log_every_stop else np.isin(times, steps)
    tick = np.full(len(times), -1, dtype=np.int64)
    tick[np.searchsorted(times, ticks)] = np.round(ticks / period).astype(np.int64)
    return Schedule(
        times.tolist(),
        log.tolist(),
        tick.tolist(),
        np.isin(times, releases).tolist(),
        np.isin(times, extra).tolist(),
        np.isin(times, steps).tolist(),
    )


class TickLoop:
    """The DSP side of a closed loop, run between ``AdvanceTo`` calls (see the module's docstring).

    ``simulator``: the plant's Simulator; ``plant``, ``plant_context``; ``actuation_input``: the plant's
    actuation input port of the Diagram (fixed here: the actuators' force); ``law``: the control law;
    ``sensor``: ``(t, x) -> (6,)`` readings of the plant state ``x``; ``step`` (s): the plant step;
    ``actuators``: their saturation and lag (``control.actuation.Actuation``), stepped here at every plant
    step; ``discrete``: the plant is discrete (it logs at every stop); ``legs``: ``(positions, velocities)``,
    the legs' indices in the plant state, for actuators with a state that read the legs' motion
    (``control.screw.ScrewActuation``, ``control.hydraulic.HydraulicActuation``: ``start(hold_forces, L, L̇)
    -> (state, force)`` and ``advance(state, command, L, L̇) -> (state, force, powers)``, stepped by the Python
    loop: the compiled kernel steps the lag only), None for the lag. Such actuators' energy flows (the powers
    of each plant step, W, held over it) add up in ``energy`` ({flow: (6,) J})."""

    def __init__(
        self, simulator, plant, plant_context, actuation_input, law, sensor, step, actuators, discrete, legs=None
    ):
        self.simulator, self.plant, self.plant_context = simulator, plant, plant_context
        self.law, self.sensor, self.step = law, sensor, step
        self.timing = law.timing
        self.at_tick = dsp_state.releases_at_tick(self.timing)
        self.actuators, self.discrete = actuators, discrete
        self.held = self.memory = self.status = None
        self.lag_force = None  # the actuators' lag state (6, N), None without a lag
        self.reference = self.feedforward = None
        self._fixed = actuation_input.FixValue(simulator.get_mutable_context(), np.zeros(6))
        # the compiled DSP side (one C call per stop), None: the Python loop below (``firmware.loop_kernel``)
        self.kernel = make_kernel(law, sensor) if legs is None else None
        self.legs, self.actuator_state, self.energy = legs, None, None
        self._end, self._boundaries, self._raw = 0.0, (), None  # the last run's end, extra stops and raw logs

    def prime(self, poses) -> None:
        """The law's tables for the reference ``(n_ticks, 6)`` poses of the ticks 0, 1, … (one batch; speed
        only): the compiled kernel's set-points or pose words, else the law's own ``prime``."""
        if self.kernel is not None:
            self.kernel.tables(poses)
        elif hasattr(self.law, "prime"):
            self.law.prime(poses)

    def initialize(self, lengths, hold_forces=None, feedforward=None, rates=None) -> None:
        """The controller's state as if it had been holding ``lengths`` (``dsp_state.initial_state``), the
        actuators' lag at ``hold_forces`` (6, N, saturated; zero if None)."""
        self.held, self.memory, self.status = dsp_state.initial_state(
            self.law, lengths, hold_forces, feedforward, rates
        )
        if self.legs is not None:
            x = self.plant.GetPositionsAndVelocities(self.plant_context)
            hold = np.zeros(6) if hold_forces is None else hold_forces
            self.actuator_state, self.lag_force = self.actuators.start(hold, x[self.legs[0]], x[self.legs[1]])
            self.energy = None  # the flows' names come with the first step
        elif self.actuators.has_lag:
            self.lag_force = self.actuators.saturate(np.zeros(6) if hold_forces is None else hold_forces)
        self._set_force(self._force_of(self.held))

    def _force_of(self, held) -> np.ndarray:
        """The actuators' force while the controller holds ``held``: the lag's state, or the command saturated."""
        return self.lag_force if self.actuators.has_lag else self.actuators.saturate(held[:6])

    def _set_force(self, force) -> None:
        self._fixed.GetMutableData().get_mutable_value().SetFromVector(force)
        self._force = force

    def run(self, duration: float, boundaries=(), on_boundary=None) -> dict:
        """Advance from t = 0 to ``duration`` s; ``on_boundary(t)`` is called at each of ``boundaries``.
        Returns the logs at the plant steps (every stop of a discrete plant), each the values before the
        updates at that time: ``times`` (n,) s, ``command`` (n, 6) N, ``setpoint`` (n, 6) m, ``status``
        (n, len(STATUS)), ``state`` (n, nx) and ``force`` (n, 6) N."""
        s = self._schedule(duration, boundaries)
        self._end, self._boundaries = duration, tuple(boundaries)
        return self._logs_of(s, self._advance(duration, s, on_boundary, self._log_arrays(s), -1, 0))

    def extend(self, duration: float) -> dict:
        """Continue the run that ended at the last ``run``/``extend``'s end time to ``duration`` s: the updates
        at that time (which the run did not take: Drake's ``AdvanceTo`` stops before them), then the stops up to
        ``duration`` of ``run(duration)``'s schedule. Returns the logs from t = 0, ``run``'s: the same numbers
        as one run to ``duration`` when the end time was a stop of that run (a plant step or a tick; else
        the continued run has a stop there that one run has not: ``tests/drake/test_loop_kernel.py``). The
        tables (``reference``, ``feedforward``, ``prime``) must cover the ticks up to ``duration``."""
        end = self._end
        if self._raw is None or not duration > end:
            raise RuntimeError(f"a run that ended at {end} s extended to {duration} s")  # a bug of the caller
        s = self._schedule(duration, (*self._boundaries, end))  # the same stops up to ``end``, ``end`` included
        first = s.times.index(end)
        old = self._raw
        n_old = 1 + sum(s.log[: first + 1])
        if n_old != len(old["held"]):
            raise RuntimeError(f"{len(old['held'])} rows logged up to {end} s, {n_old} expected")  # a bug
        logs = self._log_arrays(s)
        for name, rows in old.items():
            logs[name][:n_old] = rows
        self._end, self._boundaries = duration, (*self._boundaries, end)
        return self._logs_of(s, self._advance(duration, s, None, logs, first, n_old))

    def _schedule(self, duration: float, boundaries) -> Schedule:
        T = self.timing.sample_period
        delay = None if self.at_tick else self.timing.output_delay
        return schedule(duration, self.step, T, delay, self.discrete, boundaries)

    def _advance(self, duration: float, s: Schedule, on_boundary, logs: dict, first: int, row: int) -> dict:
        """Run the stops of ``s`` from ``first`` on (-1: from t = 0, logging there; else resuming after the
        log of stop ``first``), writing ``logs`` from ``row`` on; the raw logs, kept for ``extend``."""
        run = self._run_python if self.kernel is None else self._run_kernel
        self._raw = run(duration, s, on_boundary, logs, first, row)
        return self._raw

    @staticmethod
    def _logs_of(s: Schedule, raw: dict) -> dict:
        held = raw["held"]
        times = np.array([0.0] + [t for t, logged in zip(s.times, s.log) if logged])
        logs = {k: v for k, v in raw.items() if k != "held"}
        return logs | {"times": times, "command": held[:, :6], "setpoint": held[:, 6:]}

    def _log_arrays(self, s: Schedule) -> dict:
        n = 1 + sum(s.log)
        return {
            "held": np.empty((n, 12)),
            "status": np.empty((n, len(self.status))),
            "state": np.empty((n, self.plant.num_multibody_states())),
            "force": np.empty((n, 6)),
        }

    def _half_steps(self, s: Schedule) -> dict:
        """For a discrete plant, stop index -> a time halfway to the next stop, at each plant step (-1: t = 0):
        Drake steps the plant (an unrestricted update) before any discrete update at t, so the loop advances
        there first — the tick reads the step's result, the plant stepped with the force before the actuators'
        step at t. Nothing else happens halfway (no continuous state, no event, no logging)."""
        if not self.discrete:
            return {}
        times = s.times
        return {-1: 0.5 * times[0]} | {i: 0.5 * (times[i] + times[i + 1]) for i in range(len(times) - 1) if s.step[i]}

    def _run_python(self, duration: float, s: Schedule, on_boundary, logs: dict, first: int, row: int) -> dict:
        """``_advance`` in Python: the reference and the fallback of the compiled kernel (``_run_kernel``)."""
        held_log, status_log, x_log, force_log = logs["held"], logs["status"], logs["state"], logs["force"]
        ref, ff = self.reference, self.feedforward
        law, at_tick, sensor, act = self.law, self.at_tick, self.sensor, self.actuators
        pc, get_x = self.plant_context, self.plant.GetPositionsAndVelocities
        advance, half = self.simulator.AdvanceTo, self._half_steps(s)
        held, memory, status = self.held, self.memory, self.status
        if first < 0:
            held_log[0], status_log[0], x_log[0], force_log[0] = held[:12], status, get_x(pc), self._force
            row = 1
        last = len(s.times) - 1
        t, k, rel, step = 0.0, 0, False, True  # t = 0: Initialize has published; the tick at 0 is next
        for i in range(first, last + 1):
            if i >= 0:
                t, k, rel, step = s.times[i], s.tick[i], s.release[i], s.step[i]
            if i > first:  # not the stop a resumed run ended at (and logged)
                advance(t)
                if s.log[i]:
                    held_log[row, :], status_log[row, :] = held[:12], status
                    x_log[row, :], force_log[row, :] = get_x(pc), self._force
                    row += 1
                if s.boundary[i] and on_boundary is not None:
                    on_boundary(t)
                if i == last:
                    break  # the updates at the end time are not run (Drake's AdvanceTo stops before them)
            before = held
            if i in half:
                advance(half[i])
            if k >= 0:
                L = sensor(t, get_x(pc))
                new_held, memory, status = dsp_state.tick(
                    law, at_tick, memory, status, t, ref[k], L, None if ff is None else ff[k]
                )
                held = held if new_held is None else new_held
            elif rel:
                new_held, status = dsp_state.release(memory, status, t)
                held = held if new_held is None else new_held
            # the actuators: at a plant step the lag takes the command held before the controller's update
            # there (simultaneous discrete updates read the old state); without a lag the force follows the
            # command just held
            if act.has_lag:
                if step:
                    if self.legs is None:
                        self.lag_force = act.step(self.lag_force, before[:6])
                    else:
                        self.lag_force = self._actuator_step(before[:6], get_x(pc))
                    self._set_force(self.lag_force)
            elif held is not before:
                self._set_force(act.saturate(held[:6]))
        self.held, self.memory, self.status = held, memory, status
        return logs

    def _actuator_step(self, command, x) -> np.ndarray:
        """The stateful actuators' plant step at plant state ``x`` under the held ``command`` (6, N): their state
        advanced, their energy flows over the step added; the force (6, N) to hold over the step."""
        self.actuator_state, force, powers = self.actuators.advance(
            self.actuator_state, command, x[self.legs[0]], x[self.legs[1]]
        )
        if self.energy is None:
            self.energy = {name: np.zeros(6) for name in powers}
        for name, power in powers.items():
            self.energy[name] += power * self.step
        return force

    _force = None

    def _views(self):
        """Numpy views of Drake's memory (no copies): the plant state — the plant context's continuous (or,
        for a discrete plant, discrete) state vector, positions then velocities, ``GetPositionsAndVelocities``'s
        layout — and the fixed actuation input's vector. Drake writes a step's result into the same memory,
        so the views hold for the run (``tests/drake/test_loop_kernel.py``)."""
        pc = self.plant_context
        state = pc.get_discrete_state(0) if self.discrete else pc.get_continuous_state_vector()
        x = state.get_value()
        if x.shape != (self.plant.num_multibody_states(),):  # a plant with other state: not this loop's
            raise RuntimeError(f"plant state of {x.shape} values, {self.plant.num_multibody_states()} expected")
        return x, self._fixed.GetMutableData().get_mutable_value().get_mutable_value()

    def _run_kernel(self, duration: float, s: Schedule, on_boundary, logs: dict, first: int, row: int) -> dict:
        """``_advance`` with the compiled DSP side (``firmware.loop_kernel``): per stop one ``AdvanceTo`` and one C
        call (log, tick or release, the actuators' force written in Drake's memory), and Drake told of a new
        force (``GetMutableData``) only when it changed. The stops that need Python — a boundary with a
        callback, a discrete plant's step before the loop's updates — split the call in two around it."""
        x, actuation = self._views()
        kern = self.kernel
        kern.start(
            x,
            actuation,
            self.actuators,
            self.lag_force,
            s,
            self.feedforward,
            self.held,
            self.memory,
            self.status,
            self.at_tick,
            logs,
            row,
        )
        notify, advance, stop, ks = self._fixed.GetMutableData, self.simulator.AdvanceTo, kern.stop, kern.s
        times, last = s.times, len(s.times) - 1
        split = {i for i in range(len(times)) if s.boundary[i] and on_boundary is not None}
        half = self._half_steps(s)
        split |= set(half)
        if first < 0:
            kern.log(ks, -1)
        if first in half:
            advance(half[first])
        self._kernel_update(first)
        for i in range(first + 1, last):
            advance(times[i])
            if i in split:
                kern.log(ks, i)
                if s.boundary[i] and on_boundary is not None:
                    on_boundary(times[i])
                if i in half:
                    advance(half[i])
                self._kernel_update(i)
            else:
                r = stop(ks, i)
                if r:
                    if r < 0:
                        kern.raise_error(r)
                    notify()
        advance(times[last])  # the updates at the end time are not run (Drake's AdvanceTo stops before them)
        kern.log(ks, last)
        if s.boundary[last] and on_boundary is not None:
            on_boundary(times[last])
        if ks.row != len(logs["held"]):
            raise RuntimeError(f"the loop logged {ks.row} rows of {len(logs['held'])}")  # a bug
        self.held, self.memory, self.status, lag_force = kern.state()
        self.lag_force = lag_force if self.actuators.has_lag else None
        return logs

    def _kernel_update(self, i: int) -> None:
        """The compiled updates of stop ``i`` alone (its log taken before), Drake told of a new force."""
        r = self.kernel.update(self.kernel.s, i)
        if r < 0:
            self.kernel.raise_error(r)
        if r:
            self._fixed.GetMutableData()
