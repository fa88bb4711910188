"""Drake systems of the controller-in-the-loop Diagram, each a thin ``LeafSystem`` around numpy code:

- ``ControllerSystem``: a control law (``control.FloatLaw``, ``control.FixedPointLaw`` or the compiled
  ``firmware.sil.CFixedPointLaw``) ticking at exactly t = k·T, with the DSP's output latency and a
  zero-order hold on its outputs (``control.dsp_state``: the same tick as the closed loop's
  ``drake.tick_loop``, which runs it outside the Diagram);
- ``PoseSource``: a ``core.trajectory.Trajectory`` as an output port (computed in Python at any time);
- ``Actuators``: saturation and a first-order lag, discretised exactly at the plant's step (Drake primitives).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from pydrake.systems.framework import Diagram, DiagramBuilder, LeafSystem
from pydrake.systems.primitives import LinearSystem, Saturation

from stewart_drake.control import dsp_state
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
        self._at_tick = dsp_state.releases_at_tick(self.timing)
        if not self._at_tick:  # latency "computation": released at k·T + t_comp
            self.DeclarePeriodicDiscreteUpdateEvent(T, self.timing.output_delay, self._Release)

    def _hold(self, discrete_state, released) -> None:
        """Release ``released`` (12 or more: command N, set-point m) to the output ports."""
        discrete_state.set_value(self._command, released[:6])
        discrete_state.set_value(self._setpoint, released[6:12])

    def _Tick(self, context, discrete_state):
        # one Python call per tick: the ports are read once each (``control.dsp_state.tick``)
        ff = self._ff_port.Eval(context) if self._ff_port.HasValue(context) else None
        held, memory, status = dsp_state.tick(
            self.law,
            self._at_tick,
            context.get_discrete_state(self._memory).value(),
            context.get_discrete_state(self._status).value(),
            context.get_time(),
            self._ref_port.Eval(context),
            self._L_port.Eval(context),
            ff,
        )
        if held is not None:
            self._hold(discrete_state, held)
        discrete_state.set_value(self._memory, memory)
        discrete_state.set_value(self._status, status)

    def _Release(self, context, discrete_state):
        memory = context.get_discrete_state(self._memory).value()
        held, status = dsp_state.release(memory, context.get_discrete_state(self._status).value(), context.get_time())
        if held is not None:
            self._hold(discrete_state, held)
            discrete_state.set_value(self._status, status)

    def initialize(self, context, lengths, hold_forces=None, feedforward=None, rates=None) -> None:
        """Set the controller's state (in its own ``context``) as if it had been holding ``lengths``
        (6, metres) with ``hold_forces`` (6, newtons) for a while (``control.dsp_state.initial_state``)."""
        held, memory, status = dsp_state.initial_state(self.law, lengths, hold_forces, feedforward, rates)
        context.SetDiscreteState(self._command, held[:6])
        context.SetDiscreteState(self._setpoint, held[6:])
        context.SetDiscreteState(self._memory, memory)
        context.SetDiscreteState(self._status, status)


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
    computed in Python at the context's time (for any time; the closed loop reads its tables by tick index)."""

    def __init__(self, trajectory: Trajectory):
        super().__init__()
        self.trajectory = trajectory
        self.DeclareVectorOutputPort("pose", 6, self._CalcPose)

    def _CalcPose(self, context, output):
        # evaluated on a 1-element array, the same code path as a batch of times
        output.SetFromVector(self.trajectory.pose(np.array([context.get_time()]))[0])


class Actuators(Diagram):
    """Input ``command`` (6, N) → output ``force`` (6, N): saturation at ±``max_force``, then a first-order
    lag with time constant ``time_constant`` (s) discretised exactly at ``period`` (the plant's step),
    F ← a·F + (1−a)·u, a = exp(−period/τ); with τ = 0 the saturated command passes straight through.
    Drake's ``Saturation`` and a discrete ``LinearSystem``: no Python runs per step. ``lag``: the
    ``LinearSystem`` (None without a lag). The closed loop steps the same numbers itself
    (``control.actuation``; ``tests/drake/test_actuation.py``)."""

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
