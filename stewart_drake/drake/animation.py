"""Meshcat scenes of a platform: the Drake model's visuals driven by poses, a camera framed on the
platform, and per-leg warning sleeves (red) shown when a leg is near a stroke end or saturating.

``record_animation`` turns a pose history (a simulation log) into a self-contained HTML animation,
thinned to ``fps`` frames per second, with a time slider, a play button and a legend added to the page.
``MeshcatScene`` is the live counterpart the viewer uses.

Meshcat's recordings cannot animate a material's colour (three.js finds no ``.color`` on a mesh), but
they animate ``visible``: each leg carries a red sleeve, slightly wider than its cylinder and piston,
whose visibility follows the warning.
"""

from __future__ import annotations

import html as _html
import logging

import numpy as np
from pydrake.geometry import Cylinder, Meshcat, MeshcatParams, MeshcatVisualizer, MeshcatVisualizerParams, Rgba
from pydrake.math import RigidTransform
from pydrake.systems.framework import DiagramBuilder

from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.leg_bodies import leg_visual_dimensions
from stewart_drake.drake.platform_model import build_plant, set_pose

WARN_RGBA = (0.9, 0.05, 0.05, 1.0)
GHOST_RGBA = (0.1, 0.85, 0.3, 0.5)
# A leg within this fraction of its stroke from either end is flagged (5 % of 0.4 m = 20 mm on utn-dynamic).
WARN_FRACTION = 0.05


def stroke_margin(platform: Platform, lengths) -> np.ndarray:
    """``(..., 6)`` signed distance (m) of each leg length to the nearer stroke end; < 0 outside."""
    L = np.asarray(lengths, dtype=float)
    return np.minimum(L - platform.L_min, platform.L_max - L)


def leg_warnings(platform: Platform, lengths, saturating=None, fraction: float = WARN_FRACTION) -> np.ndarray:
    """``(..., 6)`` bool: the leg is within ``fraction`` of the stroke of an end (or beyond it), or
    its actuator saturates (``saturating``, same shape, optional)."""
    warn = stroke_margin(platform, lengths) < fraction * (platform.L_max - platform.L_min)
    return warn if saturating is None else warn | np.asarray(saturating, dtype=bool)


def camera_pose(platform: Platform) -> tuple[np.ndarray, np.ndarray]:
    """Camera position and target (world, metres) framing the platform at home: looking at the middle
    of its height from the front-right, above, far enough that it fills ~70 % of Meshcat's 75° view."""
    home = platform.home_pose()
    radius = float(
        max(
            np.linalg.norm(platform.base_anchors[:, :2], axis=1).max(),
            np.linalg.norm(platform.top_anchors[:, :2], axis=1).max(),
        )
    )
    height = float(home[2])
    target = np.array([0.0, 0.0, 0.5 * height])
    size = max(height, 2 * radius)
    direction = np.array([1.0, -1.3, 0.7])
    return target + 1.8 * size * direction / np.linalg.norm(direction), target


class MeshcatScene:
    """The platform's Drake model drawn in ``meshcat``, posed by ``show(pose)``; leg sleeves and a
    ghost plate for warnings. Paths: ``/drake/visualizer/<model>/<body>``."""

    def __init__(self, platform: Platform, meshcat, publish_period: float = 1 / 25, convention: str = "utn"):
        self.platform, self.meshcat, self.convention = platform, meshcat, convention
        builder = DiagramBuilder()
        self.plant, scene_graph = build_plant(platform, builder=builder)
        self.visualizer = MeshcatVisualizer.AddToBuilder(
            builder, scene_graph, meshcat, MeshcatVisualizerParams(publish_period=publish_period)
        )
        self.diagram = builder.Build()
        self.context = self.diagram.CreateDefaultContext()
        self.plant_context = self.plant.GetMyMutableContextFromRoot(self.context)
        self.visualizer_context = self.visualizer.GetMyContextFromRoot(self.context)
        self.prefix = (
            f"/drake/visualizer/{self.plant.GetModelInstanceName(self.plant.GetBodyByName('top').model_instance())}"
        )
        self.visualizer.ForcedPublish(self.visualizer_context)
        self._add_sleeves()
        eye, target = camera_pose(platform)
        meshcat.SetCameraPose(eye, target)

    def sleeve_paths(self, leg: int) -> list[str]:
        n = leg + 1
        return [f"{self.prefix}/cylinder_{n}/warning", f"{self.prefix}/piston_{n}/warning"]

    def _add_sleeves(self) -> None:
        vis = leg_visual_dimensions(self.platform)
        for i in range(6):
            cyl, pist = self.sleeve_paths(i)
            self.meshcat.SetObject(
                cyl, Cylinder(1.2 * vis["cylinder_radius"], 1.01 * vis["cylinder_length"]), Rgba(*WARN_RGBA)
            )
            self.meshcat.SetTransform(cyl, RigidTransform([0, 0, vis["cylinder_length"] / 2]))
            self.meshcat.SetObject(
                pist, Cylinder(1.25 * vis["piston_radius"], 1.01 * vis["piston_length"]), Rgba(*WARN_RGBA)
            )
            self.meshcat.SetTransform(pist, RigidTransform([0, 0, -vis["piston_length"] / 2]))
            for p in (cyl, pist):
                self.meshcat.SetProperty(p, "visible", False)

    def pose(self, pose, t: float = 0.0) -> None:
        """Pose the model (``(6,)`` metres/radians in this scene's convention) at time ``t`` and publish."""
        self.context.SetTime(t)
        set_pose(self.plant, self.plant_context, self.platform, pose, self.convention)
        self.visualizer.ForcedPublish(self.visualizer_context)

    def warn(self, warnings, animation=None, frame: int = 0) -> None:
        """Show the sleeves of the legs flagged in ``warnings`` (6,) bool, live or at ``frame`` of ``animation``."""
        for i, w in enumerate(np.asarray(warnings, dtype=bool)):
            for p in self.sleeve_paths(i):
                if animation is None:
                    self.meshcat.SetProperty(p, "visible", bool(w))
                else:
                    animation.SetProperty(frame, p, "visible", bool(w))


def _frames(t: np.ndarray, fps: float) -> np.ndarray:
    """Indices of the log samples nearest to a ``fps`` grid over the log's time span."""
    grid = np.arange(t[0], t[-1] + 0.5 / fps, 1.0 / fps)
    return np.unique(np.clip(np.searchsorted(t, grid), 0, len(t) - 1))


def recording_meshcat() -> Meshcat:
    """A Meshcat server on localhost used only to record an HTML file: nobody is meant to visit it, so
    Drake's "Meshcat listening for connections at ..." INFO message is held back (warnings still show)."""
    drake_logger = logging.getLogger("drake")
    level = drake_logger.level
    drake_logger.setLevel(max(drake_logger.getEffectiveLevel(), logging.WARNING))
    try:
        return Meshcat(MeshcatParams(host="localhost"))
    finally:
        drake_logger.setLevel(level)


def record_animation(platform: Platform, t, poses, saturating=None, fps: float = 25.0, title: str = "") -> str:
    """A self-contained HTML Meshcat animation of ``poses`` ``(n, 6)`` (utn convention, SI) at times
    ``t`` ``(n,)`` s, thinned to ``fps`` frames per second; legs turn red where ``leg_warnings`` flags
    them (``saturating`` ``(n, 6)`` bool: saturated during that sample, optional; a frame shows a
    saturation of any sample since the previous frame)."""
    t, poses = np.asarray(t, dtype=float), np.asarray(poses, dtype=float)
    meshcat = recording_meshcat()
    scene = MeshcatScene(platform, meshcat, publish_period=1.0 / fps)
    idx = _frames(t, fps)
    warn = leg_warnings(platform, leg_lengths(platform, poses[idx]))
    if saturating is not None:
        sat = np.logical_or.reduceat(np.asarray(saturating, dtype=bool), np.r_[0, idx[1:]], axis=0)
        warn |= sat
    animation = scene.visualizer.StartRecording(set_transforms_while_recording=False)
    previous = None
    for k, i in enumerate(idx):
        scene.pose(poses[i], t[i] - t[0])
        frame = int(round((t[i] - t[0]) * fps))
        if previous is None or (warn[k] != previous).any():
            scene.warn(warn[k], animation, frame)
            previous = warn[k]
    scene.visualizer.StopRecording()
    scene.visualizer.PublishRecording()
    page = meshcat.StaticHtml()
    return _with_time_control(page, float(t[-1] - t[0]), title, int(warn.any(axis=1).sum()), len(idx))


_OVERLAY = """
<div id="sd-panel" style="position:fixed;left:10px;top:10px;z-index:10;font:15px/1.4 sans-serif;
 background:rgba(255,255,255,.9);padding:8px 12px;border-radius:6px;box-shadow:0 1px 4px rgba(0,0,0,.3);max-width:46vw">
 <div style="font-weight:bold">{title}</div>
 <div><button id="sd-play" style="font-size:15px;width:5.5em">pause</button>
 <input id="sd-slider" type="range" min="0" max="{duration}" step="0.01" value="0" style="width:18em;vertical-align:middle">
 <span id="sd-time" style="font-variant-numeric:tabular-nums">t = 0.00 s</span> / {duration:.2f} s</div>
 <div style="font-size:13px"><span style="color:#e00">&#9632;</span> red legs: within {pct:g} % of a stroke end
 or saturating ({warned} of {frames} frames). Drag to rotate, scroll to zoom.</div>
</div>
<script>
(function () {{
  const a = viewer.animator, slider = document.getElementById("sd-slider"),
        label = document.getElementById("sd-time"), button = document.getElementById("sd-play");
  const now = () => a.actions.reduce((m, x) => Math.max(m, x.time), 0);
  button.onclick = () => {{ if (a.playing) a.pause(); else {{ if (now() >= {duration} - 1e-3) a.seek(0); a.play(); }} }};
  slider.oninput = () => {{ a.pause(); a.seek(parseFloat(slider.value)); }};
  (function tick() {{
    const t = now();
    if (a.playing) slider.value = t;
    label.textContent = "t = " + t.toFixed(2) + " s";
    button.textContent = a.playing ? "pause" : "play";
    requestAnimationFrame(tick);
  }})();
}})();
</script>
"""


def _with_time_control(page: str, duration: float, title: str, warned: int, frames: int) -> str:
    """``page`` with a panel (title, play/pause, a time slider and readout, the colour legend) before </body>."""
    overlay = _OVERLAY.format(
        title=_html.escape(title or "stewart-drake animation"),
        duration=duration,
        pct=WARN_FRACTION * 100,
        warned=warned,
        frames=frames,
    )
    head, sep, tail = page.rpartition("</body>")
    if not sep:
        # internal: Meshcat's own page always has one; its absence is a pydrake change, not bad input
        raise ValueError("Meshcat's StaticHtml has no </body>")
    return head + overlay + sep + tail


def log_saturating(status: np.ndarray) -> np.ndarray:
    """``(n, 6)`` bool: leg saturated during a sample, from a simulation log's cumulative per-leg
    saturation counts (``status`` columns 4..9)."""
    counts = np.asarray(status, dtype=float)[:, 4:10]
    return np.diff(counts, axis=0, prepend=counts[:1]) > 0


__all__ = [
    "MeshcatScene",
    "camera_pose",
    "leg_warnings",
    "log_saturating",
    "record_animation",
    "recording_meshcat",
    "stroke_margin",
]
