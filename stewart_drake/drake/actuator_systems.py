"""The stateful leg actuators in Drake: ``ScrewActuators`` and ``HydraulicActuators``, thin ``LeafSystem``s
around ``control.screw`` and ``control.hydraulic``, and ``set_reflected_inertia``, the screw's rotor inertia
carried by the plant's prismatic joints.

The rotor turns with the leg (θ = ρ·L), so its inertia is part of the plant's mass matrix: Drake adds a joint
actuator's reflected inertia ρ²·J (gear ratio ρ, rotor inertia J, both context parameters) to the joint's
diagonal, integrated with the plant (implicitly by SAP). The closed loop (``drake.tick_loop``) steps the law
itself at the plant steps, as it does the lag; the systems are the same steps as Diagram systems, for a
Diagram built by hand and for the test that the loop's numbers are the systems'.
"""

from __future__ import annotations

import numpy as np
from pydrake.multibody.tree import JointActuatorIndex
from pydrake.systems.framework import BasicVector, LeafSystem

from stewart_drake.control.hydraulic import HydraulicActuation
from stewart_drake.control.screw import ScrewActuation, leg_force
from stewart_drake.design.hydraulic import HydraulicParameters
from stewart_drake.design.screw import ScrewParameters


def set_reflected_inertia(plant, context, params: ScrewParameters) -> None:
    """Give each of ``plant``'s leg actuators the screw's rotor inertia J and gear ratio ρ = 2π/lead in
    ``context`` (the plant's): the prismatic joints then carry the reflected mass J·ρ² (kg)."""
    for k in range(plant.num_actuators()):
        actuator = plant.get_joint_actuator(JointActuatorIndex(k))
        actuator.SetRotorInertia(context, params.rotor_inertia)
        actuator.SetGearRatio(context, params.ratio)


class ScrewActuators(LeafSystem):
    """Six screw actuators stepped every ``step`` s (``control.screw.ScrewActuation``).

    Inputs ``command`` (6: force commands, N) and ``leg_velocity`` (6: m/s); output ``force`` (6: N, the
    force on the legs, held between steps). Discrete state: the motor currents (6, A) and the force (6, N);
    at each step the current advances under the command and the force is that of the new current at the
    velocity read then (the numbers of ``drake.tick_loop``'s step)."""

    def __init__(self, params: ScrewParameters, step: float, initial_current=None, initial_velocity=None):
        super().__init__()
        self.law = ScrewActuation(params, step)
        i0 = np.zeros(6) if initial_current is None else np.asarray(initial_current, dtype=float)
        v0 = np.zeros(6) if initial_velocity is None else np.asarray(initial_velocity, dtype=float)
        self._command = self.DeclareVectorInputPort("command", 6)
        self._velocity = self.DeclareVectorInputPort("leg_velocity", 6)
        self._current = self.DeclareDiscreteState(BasicVector(i0))
        self._force = self.DeclareDiscreteState(BasicVector(leg_force(params, i0, v0)))
        self.DeclareStateOutputPort("force", self._force)
        self.DeclarePeriodicDiscreteUpdateEvent(step, 0.0, self._Step)

    def _Step(self, context, discrete_state):
        current = self.law.step(context.get_discrete_state(self._current).value(), self._command.Eval(context))
        discrete_state.set_value(self._current, current)
        discrete_state.set_value(self._force, leg_force(self.law.params, current, self._velocity.Eval(context)))


class HydraulicActuators(LeafSystem):
    """Six hydraulic cylinders stepped every ``step`` s (``control.hydraulic.HydraulicActuation``), the legs'
    shortest length ``L_min`` m, starting as ``HydraulicActuation.start`` holding ``hold_forces`` (6, N) at rest.

    Inputs ``command`` (6: force commands, N), ``leg_length`` (6: m) and ``leg_velocity`` (6: m/s); output
    ``force`` (6: N, held between steps). Discrete state: the pressures and spools (18: p_A, p_B, s per leg) and
    the force (6, N); at each step the state is integrated over the step that ends there (the loop's step)."""

    def __init__(self, params: HydraulicParameters, step: float, L_min: float, hold_forces, lengths):
        super().__init__()
        self.law = HydraulicActuation(params, step, L_min)
        state, force = self.law.start(hold_forces, lengths, np.zeros(6))
        self._command = self.DeclareVectorInputPort("command", 6)
        self._length = self.DeclareVectorInputPort("leg_length", 6)
        self._velocity = self.DeclareVectorInputPort("leg_velocity", 6)
        self._state = self.DeclareDiscreteState(BasicVector(state.reshape(-1)))
        self._force = self.DeclareDiscreteState(BasicVector(force))
        self.DeclareStateOutputPort("force", self._force)
        self.DeclarePeriodicDiscreteUpdateEvent(step, step, self._Step)  # the first step ends at t = step

    def _Step(self, context, discrete_state):
        state = context.get_discrete_state(self._state).value().reshape(3, 6)
        state, force, _ = self.law.advance(
            state, self._command.Eval(context), self._length.Eval(context), self._velocity.Eval(context)
        )
        discrete_state.set_value(self._state, state.reshape(-1))
        discrete_state.set_value(self._force, force)
