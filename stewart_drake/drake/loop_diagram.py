"""The closed loop's Diagram: what runs in C++ between the controller's ticks — the plant, its actuation as the
Diagram's input ``actuation``, a periodic event at every plant step and, for an animation, the plant's scene graph
and the Meshcat visualizer. No actuators and no loggers: the loop stops at every plant step, steps the
actuators' saturation and lag there itself (``control.actuation``: Drake's ``Saturation`` and
``LinearSystem``'s numbers) and logs the plant state and their force (``tick_loop.TickLoop``).

Built once per structure and reused (``DIAGRAM_CACHE``): a Diagram holds no state (every run has its own
context and Simulator), so the runs of a process whose plant platform, plant step and integrator are the same
share one — a Monte Carlo study varying only the sensor, the latency, the sample period, the gains or the
actuators builds it once per worker; a draw that moves an anchor or changes the plate's mass or payload changes
the plant (its SDF) and builds its own. Not cached with a visualizer (it holds the user's Meshcat).

Why a moved anchor rebuilds the plant rather than re-parameterising one: a plate anchor is the point ``p_BQ``
of a ball constraint, which Drake (1.58) fixes at ``AddBallConstraint`` (a context holds only the constraint's
active status); a base anchor moves the universal joint's frame, which is a context parameter
(``FixedOffsetFrame.SetPoseInParentFrame``), but the parsed plant's frame is sdformat's composition of the SDF
poses, which a parameter would have to reproduce bit for bit. So a perturbed plant is parsed again.

Without a visualizer the plant is built alone (``build_plant(visuals=False)``): no visual geometry (nothing shows
it) and no SceneGraph (the model has no collision geometry, so SceneGraph never enters the dynamics). The same
states bit for bit (``tests/drake/test_plant_without_scene.py``, and ``test_tick_loop`` against the all-Drake
Diagram built with them).
"""

from __future__ import annotations

import pickle
from dataclasses import dataclass

import numpy as np
from pydrake.geometry import MeshcatVisualizer, MeshcatVisualizerParams
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource, ZeroOrderHold

from stewart_drake.core.geometry import Platform
from stewart_drake.drake.integrators import CONTINUOUS
from stewart_drake.drake.platform_model import build_plant
from stewart_drake.system.memo import Memo, digest

VISUALIZER_PERIOD = 1 / 32  # s: the Meshcat animation's frame period


@dataclass(frozen=True)
class LoopDiagram:
    """A built loop Diagram: ``diagram``, its ``plant`` and ``visualizer`` (or None)."""

    diagram: object
    plant: object
    visualizer: object = None


def loop_diagram(plant_platform: Platform, plant_time_step: float, integrator: str, meshcat=None) -> LoopDiagram:
    """The loop Diagram of a plant of ``plant_platform`` stepped at ``plant_time_step`` s under ``integrator``
    (from the cache when one with the same inputs was built in this process and ``meshcat`` is None)."""
    if meshcat is not None:
        return _build(plant_platform, plant_time_step, integrator, meshcat)
    inputs = (plant_platform, float(plant_time_step), integrator)
    return DIAGRAM_CACHE.get(digest(pickle.dumps(inputs, protocol=5)), lambda: _build(*inputs, None))


def _build(plant_platform, plant_time_step, integrator, meshcat) -> LoopDiagram:
    builder = DiagramBuilder()
    plant, scene_graph = build_plant(
        plant_platform, plant_time_step, builder, continuous=integrator in CONTINUOUS, visuals=meshcat is not None
    )
    builder.ExportInput(plant.get_actuation_input_port(), "actuation")
    # A periodic discrete update at every plant step (a one-value hold of a constant: nothing to compute), as
    # the actuators' lag had: Drake's Simulator ends a step at an event time otherwise than at an AdvanceTo
    # boundary alone (without these events the states of a run drift by an ulp from t = 1 s on), so the
    # loop keeps the Diagram's event times and its integration bit for bit. It also saves time: without it,
    # stopped at every plant step, Drake reaches a stop that is no event time by an extra short step from
    # t = 1 s on (2496 integrator steps for 2000 plant steps, 11–15 µs more per tick; with it one step per plant
    # step: ``tests/drake/test_loop_steps.py``).
    clock = builder.AddSystem(ZeroOrderHold(plant_time_step, 1))
    builder.Connect(builder.AddSystem(ConstantVectorSource(np.zeros(1))).get_output_port(), clock.get_input_port())
    visualizer = None
    if meshcat is not None:
        visualizer = MeshcatVisualizer.AddToBuilder(
            builder, scene_graph, meshcat, MeshcatVisualizerParams(publish_period=VISUALIZER_PERIOD)
        )
    return LoopDiagram(builder.Build(), plant, visualizer)


DIAGRAM_CACHE = Memo(2)  # the last 2 loop Diagrams built in this process
