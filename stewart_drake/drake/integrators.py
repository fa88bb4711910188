"""The closed-loop plant's integrators, and the ball constraints' error they leave.

``sap``: the plant is a discrete ``MultibodyPlant`` stepped at the plant time step with the SAP solver
(the loop closures are SAP constraints; the step is fixed, so every event time is a step boundary).
``cenic``: the plant is continuous (time step 0) and Drake's error-controlled CENIC integrator advances
it (ball constraints supported since Drake 1.56); the controller and the actuators stay discrete
systems, so the integrator stops exactly at their tick times. ``CENIC_ACCURACY`` is its error-control
target (Drake's default; ``benchmarks/bench_integrators.py`` measures what it gives).

Measured (``bench_integrators.py``, utn-dynamic, seed, 4 s): the largest ball-constraint gap is
2.5e-8 m under CENIC and 1.5e-7 m under SAP (fixed-point controller; 7.4e-9 vs 5.6e-8 m with the float
twin); against CENIC at accuracy 1e-8 the leg lengths of CENIC (1e-4) are within 9 µm, SAP's within
0.11 mm (its first-order step error); in the loop both run at the same speed (the Python controller
and the 1 kHz ticks set the pace), so CENIC is the default: accuracy first.
"""

from __future__ import annotations

import numpy as np
from pydrake.systems.analysis import ApplySimulatorConfig, SimulatorConfig

from stewart_drake.errors import IntegratorError

INTEGRATORS = ("sap", "cenic")
DEFAULT_INTEGRATOR = "cenic"
CENIC_ACCURACY = 1e-4


def check_integrator(name: str) -> str:
    """``name`` if it is one of ``INTEGRATORS``, else ``IntegratorError``."""
    if name not in INTEGRATORS:
        raise IntegratorError(IntegratorError.UNKNOWN.format(valid=", ".join(INTEGRATORS), value=name))
    return name


def apply_integrator(simulator, name: str, accuracy: float | None = None) -> None:
    """Configure ``simulator`` for ``name``: nothing for ``sap`` (a discrete plant needs no integrator
    of its own), ``SimulatorConfig(integration_scheme="cenic", accuracy=accuracy)`` for ``cenic``
    (default ``CENIC_ACCURACY``, read at the call)."""
    check_integrator(name)
    accuracy = CENIC_ACCURACY if accuracy is None else accuracy
    if name == "cenic":
        ApplySimulatorConfig(SimulatorConfig(integration_scheme="cenic", accuracy=accuracy), simulator)


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
