"""A Meshcat HTML animation of a logged run, rebuilt from the log (the run itself is not touched)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from pydrake.geometry import MeshcatVisualizer, MeshcatVisualizerParams
from pydrake.systems.framework import DiagramBuilder

from stewart_drake.core.geometry import Platform
from stewart_drake.drake.animation import recording_meshcat
from stewart_drake.drake.platform_model import build_plant, set_pose
from stewart_drake.system.output_folder import write_text_atomic

FRAME_RATE = 32.0  # frames per second of the animation


def write_animation(platform: Platform, log, path) -> Path:
    """Write a self-contained Meshcat HTML animation of ``log`` (its plate poses, the legs from the
    closed-form joint positions) on ``platform`` to ``path``; return the path."""
    builder = DiagramBuilder()
    plant, scene_graph = build_plant(platform, 1e-3, builder)
    meshcat = recording_meshcat()
    vis = MeshcatVisualizer.AddToBuilder(
        builder, scene_graph, meshcat, MeshcatVisualizerParams(publish_period=1 / FRAME_RATE)
    )
    diagram = builder.Build()
    ctx = diagram.CreateDefaultContext()
    pc = plant.GetMyMutableContextFromRoot(ctx)
    frames = np.arange(0.0, log.t[-1] + 1e-12, 1 / FRAME_RATE)
    idx = np.minimum(np.searchsorted(log.t, frames), len(log.t) - 1)
    vis.StartRecording()
    for t, k in zip(frames, idx):
        ctx.SetTime(float(t))
        set_pose(plant, pc, platform, log.pose[k])
        diagram.ForcedPublish(ctx)
    vis.StopRecording()
    vis.PublishRecording()
    return write_text_atomic(path, meshcat.StaticHtml())
