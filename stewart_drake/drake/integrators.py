"""The closed-loop plant's integrators, and the ball constraints' error they leave.

``sap``: the plant is a discrete ``MultibodyPlant`` stepped at the plant time step with the SAP solver
(the loop closures are SAP constraints; the step is fixed, so every event time is a step boundary).
``cenic``: the plant is continuous (time step 0) and Drake's error-controlled CENIC integrator advances
it (ball constraints supported since Drake 1.56); the controller and the actuators stay discrete
systems, so the integrator stops exactly at their tick times. ``CENIC_ACCURACY`` is its error-control
target (Drake's default). ``cenic-fixed``: the same continuous plant and CENIC's convex step, at the fixed
plant step, without the error estimate.

Why ``cenic-fixed`` is the default (``benchmarks/bench_integrators.py``, utn-dynamic, seed trajectory): the
1 kHz controller and actuator events stop the integrator at every plant step, so error-controlled CENIC
never takes a step longer than the plant step and spends its error estimate (extra convex solves per
step: its results match CENIC at a fixed half step) on steps it never lengthens. Accuracy first: with a
1 nm sensor (so that a flipped sensor count is not mistaken for integration error), the leg lengths
against CENIC at accuracy 1e-9 are within 2.2 µm (``cenic``), 4.7 µm (``cenic-fixed``) and 0.10 mm
(``sap``, its step error): only the two CENIC schemes stay within the 10 µm count of the sensor the
controller reads, and ``cenic-fixed`` runs the loop 1.2× (Python engine) to 1.5× (C engine) faster than
either of the others. Largest ball-constraint gaps with the fixed-point controller: 2.5e-8 m (``cenic``),
8.6e-8 m (``cenic-fixed``), 1.5e-7 m (``sap``).
"""

from __future__ import annotations

import numpy as np
from pydrake.systems.analysis import ApplySimulatorConfig, SimulatorConfig

from stewart_drake.errors import IntegratorError

INTEGRATORS = ("sap", "cenic", "cenic-fixed")
CONTINUOUS = ("cenic", "cenic-fixed")  # the integrators of a continuous plant
DEFAULT_INTEGRATOR = "cenic-fixed"
CENIC_ACCURACY = 1e-4


def check_integrator(name: str) -> str:
    """``name`` if it is one of ``INTEGRATORS``, else ``IntegratorError``."""
    if name not in INTEGRATORS:
        raise IntegratorError(IntegratorError.UNKNOWN.format(valid=", ".join(INTEGRATORS), value=name))
    return name


def apply_integrator(simulator, name: str, step: float, accuracy: float | None = None) -> None:
    """Configure ``simulator`` for ``name``: nothing for ``sap`` (a discrete plant needs no integrator of
    its own); for ``cenic`` Drake's CENIC with error control at ``accuracy`` (default ``CENIC_ACCURACY``,
    read at the call); for ``cenic-fixed`` CENIC at the fixed step ``step`` s (the plant step)."""
    check_integrator(name)
    if name == "cenic":
        accuracy = CENIC_ACCURACY if accuracy is None else accuracy
        ApplySimulatorConfig(SimulatorConfig(integration_scheme="cenic", accuracy=accuracy), simulator)
    elif name == "cenic-fixed":
        config = SimulatorConfig(integration_scheme="cenic", max_step_size=step, use_error_control=False)
        ApplySimulatorConfig(config, simulator)


def constraint_gaps(plant, states) -> np.ndarray:
    """``(n, 6)`` metres: for each logged plant state (``(n, nx)``, rows of the plant's state output)
    and each leg, the distance between the piston tip and the plate anchor the ball constraint joins
    it to (0 for an exact loop closure)."""
    ctx = plant.CreateDefaultContext()
    tips = [plant.GetBodyByName(f"piston_{i + 1}").body_frame() for i in range(6)]
    anchors = [plant.GetFrameByName(f"top_anchor_{i + 1}") for i in range(6)]
    world = plant.world_frame()
    nq = plant.num_positions()
    states = np.asarray(states, dtype=float)
    gaps = np.empty((len(states), 6))
    for k, x in enumerate(states):
        plant.SetPositions(ctx, x[:nq])
        for i in range(6):
            p_tip = plant.CalcPointsPositions(ctx, tips[i], np.zeros((3, 1)), world)
            p_anchor = plant.CalcPointsPositions(ctx, anchors[i], np.zeros((3, 1)), world)
            gaps[k, i] = np.linalg.norm(p_tip - p_anchor)
    return gaps
