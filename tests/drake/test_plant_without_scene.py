"""The loop's plant without visuals or SceneGraph (``build_plant(visuals=False)``, what ``loop_diagram`` builds
when nothing is shown): the same model less its display elements, and the same numbers as the plant with them,
bit for bit — for a Monte Carlo draw's perturbed plant under both integrators, and for a study's rows."""

import re
from dataclasses import replace

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder

import stewart_drake.drake.loop_diagram as loop_diagram_module
from stewart_drake.analyses import robustness
from stewart_drake.core.dynamics import leg_forces_with_legs
from stewart_drake.core.sdf_models import VISUAL_NOTE, platform_sdf
from stewart_drake.drake.integrators import CONTINUOUS, apply_integrator
from stewart_drake.drake.platform_model import build_plant, set_pose
from stewart_drake.montecarlo.scenario import Study, draw, plant_platform, run_scenario
from stewart_drake.montecarlo.spec import parse_spec
from tests._own_platform import own_radial

VARY = ["anchor=±0.5mm", "plate_mass=±20%", "plate_com=±2mm"]


@pytest.fixture(scope="module")
def perturbed(tmp_path_factory):
    """A draw's plant platform on our own radial platform: anchors, plate mass and centre of mass moved."""
    p = own_radial(tmp_path_factory.mktemp("own"))
    p = p.replace(mass=12.0, inertia=np.diag([0.3, 0.3, 0.5]))  # a plate of its own (the YAML gives none)
    _, d = draw(Study(p, parse_spec(VARY), seed=7, runs=1), 0)
    return plant_platform(p, d)


def test_sdf_without_visuals_is_the_sdf_less_its_visual_elements(perturbed):
    """Only display elements go: the full SDF with its ``<visual>`` elements and the note on them cut out is the
    visual-free SDF, character for character (so the bodies, joints, inertias and constraints are the same text)."""
    full, bare = platform_sdf(perturbed), platform_sdf(perturbed, visuals=False)
    assert "<visual" in full and "<visual" not in bare
    assert re.sub(r"<visual\b.*?</visual>", "", full.replace("\n" + VISUAL_NOTE, ""), flags=re.S) == bare


def _states(platform, integrator: str, visuals: bool) -> tuple[np.ndarray, int]:
    """The plant state every 10 ms over 0.2 s from home at rest, the legs pushing the static forces plus a
    leg-by-leg imbalance (so the plate moves), and the number of geometries SceneGraph holds (−1: no SceneGraph)."""
    builder = DiagramBuilder()
    plant, scene_graph = build_plant(platform, 1e-3, builder, continuous=integrator in CONTINUOUS, visuals=visuals)
    builder.ExportInput(plant.get_actuation_input_port(), "actuation")
    diagram = builder.Build()
    sim = Simulator(diagram)
    apply_integrator(sim, integrator, 1e-3)
    root = sim.get_mutable_context()
    pc = plant.GetMyMutableContextFromRoot(root)
    home = platform.home_pose()
    set_pose(plant, pc, platform, home)
    F = leg_forces_with_legs(platform, home, np.zeros(6), np.zeros(6)) + np.array([40, -30, 20, -10, 30, -50.0])
    diagram.GetInputPort("actuation").FixValue(root, F)
    sim.Initialize()
    out = []
    for k in range(1, 21):
        sim.AdvanceTo(k * 1e-2)
        out.append(plant.GetPositionsAndVelocities(pc).copy())
    n_geometries = -1 if scene_graph is None else scene_graph.model_inspector().num_geometries()
    return np.array(out), n_geometries


@pytest.mark.parametrize("integrator", ["cenic-fixed", "sap"])
def test_perturbed_plant_steps_bit_for_bit_without_scene_graph(perturbed, integrator):
    """A Monte Carlo draw's plant (anchors, plate mass and centre of mass moved) built without visuals and
    SceneGraph steps to the same states, bit for bit, as the one with them: the model has no collision geometry,
    so SceneGraph and the visuals never enter the dynamics. The comparison is between two different builds (one
    holds the display geometry, the other has no SceneGraph) of a plate that moves."""
    with_scene, n_shown = _states(perturbed, integrator, visuals=True)
    alone, n_alone = _states(perturbed, integrator, visuals=False)
    assert n_shown > 0 and n_alone == -1
    assert np.ptp(with_scene[:, :7], axis=0).max() > 1e-4  # the plate moved by more than 0.1 mm
    np.testing.assert_array_equal(alone, with_scene)


def test_study_rows_bit_for_bit_with_the_plant_shown(monkeypatch):
    """The robustness study's rows (its draws, 0.1 s) are the same, bit for bit, whether the loop's plant is built
    without visuals and SceneGraph (as now) or with them (as before): every metric and drawn parameter."""
    study = replace(robustness._study(quick=True), duration=0.1)

    def rows():
        loop_diagram_module.DIAGRAM_CACHE.clear()
        return [{k: v for k, v in run_scenario(study, i).items() if k != "wall_s"} for i in (0, 1)]

    now = rows()
    shown, built = loop_diagram_module.build_plant, []

    def with_visuals(*args, **kwargs):
        plant, scene_graph = shown(*args, **(kwargs | {"visuals": True}))
        built.append(scene_graph)
        return plant, scene_graph

    monkeypatch.setattr(loop_diagram_module, "build_plant", with_visuals)
    before = rows()
    loop_diagram_module.DIAGRAM_CACHE.clear()
    assert len(built) == 2 and all(sg is not None for sg in built)  # each run's plant, with its SceneGraph
    assert now == before
    assert now[0]["plate_mass_kg"] != now[1]["plate_mass_kg"]
    assert all(r["max_leg_error_m"] > 0 for r in now)
