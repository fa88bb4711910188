"""Drake systems of the controller-in-the-loop Diagram, each a thin ``LeafSystem`` around numpy code:

- ``ControllerSystem``: a control law (``control.FloatLaw``, ``control.FixedPointLaw`` or the compiled
  ``firmware.sil.CFixedPointLaw``) ticking at exactly t = k·T, with the DSP's output latency and a
  zero-order hold on its outputs;
- ``PoseSource``: a ``core.trajectory.Trajectory`` as an output port (computed in Python at any time);
- ``TickTableSource``: rows of values at the controller's ticks as an output port read in C++ (Drake's
  ``TrajectorySource`` of a ``DiscreteTimeTrajectory``): the closed loop's reference and feed-forward;
- ``Actuators``: saturation and a first-order lag, discretised exactly at the plant's step (Drake primitives);
- ``LegLengthSensor``: the plant state's leg lengths plus an offset, white noise and the first-order
  effect of a late sample (a Monte Carlo draw's sensor).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from pydrake.systems.framework import Diagram, DiagramBuilder, LeafSystem
from pydrake.systems.primitives import LinearSystem, Saturation, TrajectorySource
from pydrake.trajectories import DiscreteTimeTrajectory

from stewart_drake.control.gains import ControllerConfig
from stewart_drake.control.laws import CONTROLLER_KINDS, STATUS, FixedPointLaw, FloatLaw
from stewart_drake.core.geometry import Platform
from stewart_drake.core.trajectory import Trajectory
from stewart_drake.errors import SimulationError
from stewart_drake.firmware.engine import ENGINES
from stewart_drake.firmware.sil import CFixedPointLaw


class ControllerSystem(LeafSystem):
    """A leg controller: ``law`` ticking every ``law.timing.sample_period`` seconds at t = k·T.

    Inputs ``reference`` (6: pose, metres/radians, the law's convention), ``leg_lengths`` (6: metres, the
    true prismatic positions: the law quantises them) and the optional ``feedforward`` (6: leg forces,
    newtons; left unconnected it is zero). Outputs ``command`` (6: leg forces, N), ``setpoint`` (6: m) and
    ``status`` (``control.STATUS``). A tick's result is released after the output delay
    (``DspTiming.latency``): ``sample`` at (k+1)·T, ``computation`` at k·T + t_comp, ``none`` at k·T; the
    outputs read discrete state, so between releases the command is held (zero-order hold).

    Discrete state groups: ``command`` (6: the released command, N) and ``setpoint`` (6: the released
    set-point, m), each its output port as it is (read in C++, no Python call per sample); ``memory`` (42:
    ``pending``, the command and set-point computed but not yet released (12), then ``pid``, the law's
    state (30): one group, read and written once per tick), ``status`` (``STATUS``).
    """

    def __init__(self, law):
        super().__init__()
        self.law = law
        self.platform, self.config, self.timing = law.platform, law.config, law.timing
        T = self.timing.sample_period
        self._ref_port = self.DeclareVectorInputPort("reference", 6)
        self._L_port = self.DeclareVectorInputPort("leg_lengths", 6)
        self._ff_port = self.DeclareVectorInputPort("feedforward", 6)
        self._command = self.DeclareDiscreteState(6)
        self._setpoint = self.DeclareDiscreteState(6)
        self._memory = self.DeclareDiscreteState(42)  # pending (12) | pid (30)
        self._status = self.DeclareDiscreteState(len(STATUS))
        self.DeclareStateOutputPort("command", self._command)
        self.DeclareStateOutputPort("setpoint", self._setpoint)
        self.DeclareStateOutputPort("status", self._status)
        self.DeclarePeriodicDiscreteUpdateEvent(T, 0.0, self._Tick)
        d = self.timing.output_delay
        self._release_separately = 0.0 < d < T
        self._latency = self.timing.latency
        self._release_at_tick = self._latency == "sample" or not self._release_separately
        if self._release_separately:
            self.DeclarePeriodicDiscreteUpdateEvent(T, d, self._Release)

    def _hold(self, discrete_state, released) -> None:
        """Release ``released`` (12 or more: command N, set-point m) to the output ports."""
        discrete_state.set_value(self._command, released[:6])
        discrete_state.set_value(self._setpoint, released[6:12])

    def _Tick(self, context, discrete_state):
        # one Python call per tick: the ports are read once each, the status row updated in place
        ref = self._ref_port.Eval(context)
        L = self._L_port.Eval(context)
        ff = self._ff_port.Eval(context) if self._ff_port.HasValue(context) else None
        memory = context.get_discrete_state(self._memory).value()
        command, setpoint, pid_new, saturated = self.law.step(memory[12:], ref, L, ff)
        st = context.get_discrete_state(self._status).value().copy()
        t = context.get_time()
        st[0] += 1
        st[1] = t
        st[3] += float(saturated.any())
        st[4:10] += saturated
        new = np.concatenate([command, setpoint, pid_new])
        if self._latency == "none":
            self._hold(discrete_state, new)
            st[2] = t
        elif self._release_at_tick:
            # release the previous tick's result now, (k+1)·T, then compute the next one
            if st[0] > 1:
                self._hold(discrete_state, memory)
                st[2] = t
        discrete_state.set_value(self._memory, new)
        discrete_state.set_value(self._status, st)

    def _Release(self, context, discrete_state):
        st = context.get_discrete_state(self._status).value().copy()
        if st[0] < 1:
            return
        self._hold(discrete_state, context.get_discrete_state(self._memory).value())
        st[2] = context.get_time()
        discrete_state.set_value(self._status, st)

    def initialize(self, context, lengths, hold_forces=None, feedforward=None, rates=None) -> None:
        """Set the controller's state (in its own ``context``) as if it had been holding ``lengths``
        (6, metres) with ``hold_forces`` (6, newtons; e.g. the static forces against gravity) for a while;
        with a ``feedforward`` (6, N) the integrator holds only the difference hold − feed-forward; with
        ``rates`` (6, m/s) as if the legs had been moving at those rates (the difference filters start
        there: no start-up kick from a derivative that sees the motion but a feed-forward that does not)."""
        lengths = np.asarray(lengths, dtype=float).reshape(6)
        F = np.zeros(6) if hold_forces is None else np.asarray(hold_forces, dtype=float).reshape(6)
        ff = np.zeros(6) if feedforward is None else np.asarray(feedforward, dtype=float).reshape(6)
        pid = self.law.initial_pid_state(lengths, F - ff, rates)
        held = np.concatenate([self.law.command_from_integrator(pid[:6], ff), lengths])
        context.SetDiscreteState(self._command, held[:6])
        context.SetDiscreteState(self._setpoint, held[6:])
        context.SetDiscreteState(self._memory, np.concatenate([held, pid]))
        context.SetDiscreteState(self._status, np.zeros(len(STATUS)))


def make_law(
    kind: str,
    platform: Platform,
    config: ControllerConfig | None = None,
    engine: str = "python",
    firmware: str | Path | None = None,
):
    """The law of controller ``kind`` (``"fixed"`` or ``"float"``); for ``fixed``, ``engine`` ``"python"``
    (the emulation) or ``"c"`` (the compiled firmware; ``firmware``: a user's C file implementing the ABI).
    The float twin has no firmware: ``engine`` does not apply to it."""
    if kind == "fixed" and (engine == "c" or firmware is not None):
        return CFixedPointLaw(platform, config, firmware)
    if engine not in ENGINES:
        raise SimulationError(SimulationError.ENGINE.format(value=engine))
    if kind != "fixed" and firmware is not None:
        raise SimulationError(SimulationError.FIRMWARE_LAW.format(kind=kind))
    if kind == "fixed":
        return FixedPointLaw(platform, config)
    if kind == "float":
        return FloatLaw(platform, config)
    raise SimulationError(
        SimulationError.CONTROLLER.format(valid=" or ".join(repr(k) for k in CONTROLLER_KINDS), value=kind)
    )


def make_controller(
    kind: str,
    platform: Platform,
    config: ControllerConfig | None = None,
    engine: str = "python",
    firmware: str | Path | None = None,
) -> ControllerSystem:
    """``ControllerSystem`` of ``make_law(kind, platform, config, engine, firmware)``."""
    return ControllerSystem(make_law(kind, platform, config, engine, firmware))


class PoseSource(LeafSystem):
    """Output ``pose`` (6) = ``trajectory.pose(t)`` (any 6-vector function of time: also leg lengths),
    computed in Python at the context's time (for any time; the closed loop uses ``TickTableSource``)."""

    def __init__(self, trajectory: Trajectory):
        super().__init__()
        self.trajectory = trajectory
        self.DeclareVectorOutputPort("pose", 6, self._CalcPose)

    def _CalcPose(self, context, output):
        # evaluated on a 1-element array, the same code path as a batch of times
        output.SetFromVector(self.trajectory.pose(np.array([context.get_time()]))[0])


class TickTableSource(TrajectorySource):
    """Output (6) = row k of a table at tick k·``period`` (Drake's ``TrajectorySource`` of a
    ``DiscreteTimeTrajectory``: looked up in C++, no Python per tick). Asked at a time that is not a tick
    within the table, it raises (Drake's error) instead of returning a neighbour. ``rows`` ``(n, 6)``: the
    values at ticks 0 … n−1."""

    def __init__(self, period: float, rows):
        self.period = period
        super().__init__(self._table(rows))

    def _table(self, rows) -> DiscreteTimeTrajectory:
        rows = np.asarray(rows, dtype=float).reshape(-1, 6)
        # k·T as numpy computes it: the times of Drake's periodic events with offset 0, bit for bit
        return DiscreteTimeTrajectory(np.arange(len(rows)) * self.period, list(rows[:, :, None]))

    def set_rows(self, rows) -> None:
        """Replace the table by ``rows`` ``(n, 6)`` (before a run: the values it will read, in one batch)."""
        self.UpdateTrajectory(self._table(rows))


class Actuators(Diagram):
    """Input ``command`` (6, N) → output ``force`` (6, N): saturation at ±``max_force``, then a first-order
    lag with time constant ``time_constant`` (s) discretised exactly at ``period`` (the plant's step),
    F ← a·F + (1−a)·u, a = exp(−period/τ); with τ = 0 the saturated command passes straight through.
    Drake's ``Saturation`` and a discrete ``LinearSystem``: no Python runs per step. ``lag``: the
    ``LinearSystem`` (None without a lag)."""

    def __init__(self, max_force: float, time_constant: float, period: float):
        super().__init__()
        self.max_force = max_force
        builder = DiagramBuilder()
        saturation = builder.AddNamedSystem("saturation", Saturation(np.full(6, -max_force), np.full(6, max_force)))
        builder.ExportInput(saturation.get_input_port(), "command")
        self.lag = None
        if time_constant > 0:
            a = math.exp(-period / time_constant)
            I, O = np.eye(6), np.zeros((6, 6))
            self.lag = builder.AddNamedSystem("lag", LinearSystem(a * I, (1 - a) * I, I, O, period))
            builder.Connect(saturation.get_output_port(), self.lag.get_input_port())
            builder.ExportOutput(self.lag.get_output_port(), "force")
        else:
            builder.ExportOutput(saturation.get_output_port(), "force")
        builder.BuildInto(self)

    def set_force(self, root_context, force) -> None:
        """Start the lag at ``force`` (6, N; saturated here) in the Diagram's ``root_context``."""
        if self.lag is not None:
            ctx = self.lag.GetMyMutableContextFromRoot(root_context)
            ctx.SetDiscreteState(np.clip(force, -self.max_force, self.max_force))


class LegLengthSensor(LeafSystem):
    """Input ``state`` (the plant's state) → output ``lengths`` (6, m) = L + ``offset`` + ``noise[k]`` −
    ``jitter[k]``·dL/dt at tick k = round(t / ``period``) (rows ``(n_ticks, 6)`` m and ``(n_ticks,)`` s,
    the last row reused beyond the table). ``positions``, ``velocities``: indices of the six prismatic
    joints' positions and rates in the state."""

    def __init__(self, n_state: int, positions, velocities, offset, noise, jitter, period: float):
        super().__init__()
        self._pos, self._vel = np.asarray(positions), np.asarray(velocities)
        self._offset, self._noise, self._jitter = (
            np.asarray(offset, float),
            np.asarray(noise, float),
            np.asarray(jitter, float),
        )
        self._period = period
        self._u = self.DeclareVectorInputPort("state", n_state)
        self.DeclareVectorOutputPort("lengths", 6, self._CalcLengths)

    def _CalcLengths(self, context, output):
        x = self._u.Eval(context)
        k = min(int(round(context.get_time() / self._period)), len(self._jitter) - 1)
        output.SetFromVector(x[self._pos] + self._offset + self._noise[k] - self._jitter[k] * x[self._vel])

    def initial_reading(self, L):
        """The reading of true lengths ``L`` (6, m) at rest before t = 0: L + offset."""
        return np.asarray(L, float) + self._offset
