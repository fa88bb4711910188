"""The interactive viewer: a platform in Meshcat with six pose sliders and live readouts (leg lengths,
stroke margins, condition number, singularity distance, assembly modes), or the replay of a log.

Readouts are Meshcat buttons whose labels are the text (Meshcat offers no text element; a button label
is the one string it shows in the page). An unreachable pose is drawn as asked, legs red, with the
nearest reachable pose on the straight line from home ghosted beside it.
"""

from __future__ import annotations

import csv
import io
import json
import textwrap
import time
import zipfile
import zlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from pydrake.geometry import Cylinder, Meshcat, MeshcatParams, Rgba
from pydrake.math import RigidTransform, RotationMatrix

from stewart_drake.core.assembly_modes import assembly_modes
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_lengths, plate_anchors
from stewart_drake.core.leg_bodies import leg_visual_dimensions
from stewart_drake.core.newton_fk import anchor_scale, jacobian_analysis
from stewart_drake.core.realtime_fk import certificate
from stewart_drake.core.rotations import angle_scale, angles_from_matrix, length_scale, rotation_matrix
from stewart_drake.core.sanity import memory_budget
from stewart_drake.drake.animation import GHOST_RGBA, MeshcatScene, leg_warnings, log_saturating, stroke_margin
from stewart_drake.errors import ReplayError, SimulationError, StewartError
from stewart_drake.system.input_stream import decode_text, read_input

AXES = ("px", "py", "pz", "alpha", "beta", "gamma")
MAX_LABEL = 28  # characters of a readout line (a Meshcat button label) that the control panel shows
# Above this condition number a pose counts as singular (kinematics.require_nonsingular's default).
MAX_CONDITION = 1e8
# Assembly modes closer than this (|Δp| / anchor radius + rotation angle in rad) count as "near" the pose.
NEAR_MODE = 0.5


@dataclass
class Readout:
    """What the viewer shows for one pose (SI). ``lengths``/``margin`` ``(6,)`` m; ``condition`` and
    ``sigma_min`` of the scaled J⁻¹; ``modes``/``modes_near``: assembly modes for these lengths, all
    and within ``NEAR_MODE`` of the pose (None when not computed); ``reachable``: every leg within its
    stroke and the pose non-singular; ``nearest``: the last reachable pose on the line from home and
    ``fraction`` how far along it lies (1 when reachable)."""

    pose: np.ndarray
    lengths: np.ndarray
    margin: np.ndarray
    condition: float
    sigma_min: float
    reachable: bool
    nearest: np.ndarray
    fraction: float
    modes: int | None = None
    modes_near: int | None = None
    warnings: np.ndarray = field(default_factory=lambda: np.zeros(6, bool))
    uniqueness_radius: float = 0.0  # m: no other assembly mode this close to the pose (realtime_fk certificate)

    def to_dict(self) -> dict:
        return {
            "pose": self.pose.tolist(),
            "lengths_m": self.lengths.tolist(),
            "stroke_margin_m": self.margin.tolist(),
            "condition": self.condition,
            "sigma_min": self.sigma_min,
            "reachable": self.reachable,
            "nearest_reachable_pose": self.nearest.tolist(),
            "fraction_from_home": self.fraction,
            "assembly_modes": self.modes,
            "assembly_modes_near": self.modes_near,
            "uniqueness_radius_m": self.uniqueness_radius,
        }


def reachable(platform: Platform, poses, convention: str = "utn") -> np.ndarray:
    """``(...)`` bool: every leg within the stroke and the condition number below ``MAX_CONDITION``."""
    ok = (stroke_margin(platform, leg_lengths(platform, poses, convention)) >= 0).all(axis=-1)
    return ok & (jacobian_analysis(platform, poses, convention).condition < MAX_CONDITION)


def nearest_reachable(
    platform: Platform, pose, convention: str = "utn", iterations: int = 40
) -> tuple[np.ndarray, float]:
    """The last reachable pose on the straight line (in pose coordinates) from home to ``pose`` (6,),
    by bisection on the fraction s in [0, 1], and s. ``pose`` itself when reachable; home (s = 0) when
    home is the only reachable point found."""
    pose = np.asarray(pose, dtype=float)
    home = platform.home_pose()
    if reachable(platform, pose, convention):
        return pose.copy(), 1.0
    lo, hi = 0.0, 1.0
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        if reachable(platform, home + mid * (pose - home), convention):
            lo = mid
        else:
            hi = mid
    return home + lo * (pose - home), lo


def readout(platform: Platform, pose, convention: str = "utn", modes: bool = True) -> Readout:
    """Everything the viewer shows for ``pose`` (6,) SI; ``modes``: also count the assembly modes
    (a seeded multi-start Newton, ~0.1–0.5 s)."""
    pose = np.asarray(pose, dtype=float)
    L = leg_lengths(platform, pose, convention)
    jac = jacobian_analysis(platform, pose, convention)
    ok = bool(reachable(platform, pose, convention))
    nearest, s = nearest_reachable(platform, pose, convention)
    r = Readout(
        pose,
        L,
        stroke_margin(platform, L),
        float(jac.condition),
        float(jac.sigma_min),
        ok,
        nearest,
        s,
        warnings=leg_warnings(platform, L),
        uniqueness_radius=uniqueness_radius(platform, pose, L, convention),
    )
    if modes:
        r.modes, r.modes_near = count_modes(platform, pose, L, convention)
    return r


def uniqueness_radius(platform: Platform, pose, lengths, convention: str = "utn") -> float:
    """Metres within which no other assembly mode of ``lengths`` lies around ``pose`` (6,): the real-time
    FK's certified uniqueness radius (``core.realtime_fk.certificate``), a bound that costs no search."""
    p, R = np.asarray(pose, dtype=float)[None, :3], rotation_matrix(np.asarray(pose, dtype=float)[None, 3:], convention)
    return float(certificate(platform, p, R, np.asarray(lengths, dtype=float)[None])[0][0])


def count_modes(platform: Platform, pose, lengths, convention: str = "utn") -> tuple[int, int]:
    """Assembly modes found for ``lengths`` (a quick search: 256 seeded starts, up to two rounds, no
    MathematicalProgram polish) and how many lie within ``NEAR_MODE`` of ``pose``; (0, 0) if none."""
    try:
        found = assembly_modes(platform, lengths, convention, n_starts=256, max_rounds=2, patience=1, polish=None)
    except StewartError:
        return 0, 0
    P = found.poses()
    R0 = rotation_matrix(np.asarray(pose)[3:], convention)
    R = rotation_matrix(P[:, 3:], convention)
    angle = np.arccos(np.clip((np.einsum("kij,ij->k", R, R0) - 1) / 2, -1.0, 1.0))
    d = np.linalg.norm(P[:, :3] - np.asarray(pose)[:3], axis=1) / anchor_scale(platform) + angle
    return len(P), int((d < NEAR_MODE).sum())


def labels(r: Readout, length_unit: str = "mm") -> list[str]:
    """The readout lines shown in the page (unique strings: each becomes a button label)."""
    k = 1.0 / length_scale(length_unit)
    out = [f"L{i + 1} {r.lengths[i] * k:.1f} {length_unit}, margin {r.margin[i] * k:+.1f}" for i in range(6)]
    out.append(f"condition {r.condition:.3g}, σmin {r.sigma_min:.3g}")
    out.append(f"no other assembly mode within {r.uniqueness_radius * k:.1f} {length_unit} (certified)")
    if r.modes is not None:
        out.append(f"assembly modes {r.modes}, {r.modes_near} near")
    if r.reachable:
        out.append("pose reachable")
    else:
        bad = [str(i + 1) for i in np.flatnonzero(r.margin < 0)]
        out.append(f"UNREACHABLE: {'legs ' + ','.join(bad) + ' out of stroke' if bad else 'singular'}")
        out.append(f"ghost: nearest reachable, {r.fraction * 100:.0f} % from home")
    # Meshcat's control panel cuts a button label at its width (~30 characters): longer lines are wrapped
    # at words, the continuation indented (the unreachable lines were cut off)
    wrapped = []
    for line in out:
        wrapped += textwrap.wrap(line, MAX_LABEL, subsequent_indent="  ") if len(line) > MAX_LABEL else [line]
    return wrapped


def open_meshcat(port: int | None = None) -> Meshcat:
    """A Meshcat server on localhost at ``port`` (None: the first free port from 7000). A port that
    cannot be listened on raises ``ValueError`` naming it (the CLI prints it as one line); so does a port
    below 1024, which Drake does not return from but aborts on (a ``SystemExit`` from its DRAKE_DEMAND)."""
    if port is not None and not 1024 <= port <= 65535:
        raise SimulationError(SimulationError.PORT.format(port=port, reason="give 1024..65535"))
    try:
        return Meshcat(MeshcatParams(host="localhost", port=port))
    except RuntimeError as e:
        raise SimulationError(SimulationError.PORT.format(port=port, reason=e)) from None


class Viewer:
    """Pose sliders + readouts on a ``MeshcatScene``. Sliders are in ``length_unit``/``angle_unit`` and
    the Euler ``convention``; internally SI."""

    def __init__(
        self,
        platform: Platform,
        meshcat,
        length_unit: str = "mm",
        angle_unit: str = "deg",
        convention: str = "utn",
        modes: bool = True,
    ):
        self.platform, self.meshcat, self.convention, self.modes = platform, meshcat, convention, modes
        self.length_unit = length_unit
        self.lk, self.ak = length_scale(length_unit), angle_scale(angle_unit)
        self.scene = MeshcatScene(platform, meshcat, convention=convention)
        self._labels: list[str] = []
        self.names = [f"{a} [{length_unit if i < 3 else angle_unit}]" for i, a in enumerate(AXES)]
        self.readout: Readout | None = None

    def add_sliders(self, initial) -> None:
        """Six sliders around home: positions ± the stroke, angles ± 30°, starting at ``initial`` (6,) SI."""
        home, stroke = self.platform.home_pose(), self.platform.L_max - self.platform.L_min
        span = np.array([stroke] * 3 + [np.radians(30.0)] * 3)
        for i, name in enumerate(self.names):
            k = self.lk if i < 3 else self.ak
            lo, hi = (home[i] - span[i]) / k, (home[i] + span[i]) / k
            step = 10 ** np.floor(np.log10((hi - lo) / 2000))
            self.meshcat.AddSlider(name, lo, hi, step, float(initial[i]) / k)

    def slider_pose(self) -> np.ndarray:
        """The sliders' pose in SI."""
        v = np.array([self.meshcat.GetSliderValue(n) for n in self.names])
        return np.r_[v[:3] * self.lk, v[3:] * self.ak]

    def show(self, pose, t: float = 0.0, modes: bool | None = None, saturating=None) -> Readout:
        """Pose the model, colour the legs, ghost the nearest reachable pose, update the readouts."""
        r = readout(self.platform, pose, self.convention, self.modes if modes is None else modes)
        if saturating is not None:
            r.warnings = r.warnings | np.asarray(saturating, bool)
        self.scene.pose(pose, t)
        self.scene.warn(r.warnings | (r.margin < 0))
        self._ghost(None if r.reachable else r.nearest)
        self._set_labels(labels(r, self.length_unit))
        self.readout = r
        return r

    def _ghost(self, pose) -> None:
        """The platform at ``pose`` as a translucent ghost: a leg rod per leg and the plate (None: hide it)."""
        if pose is None:
            self.meshcat.Delete("/ghost")
            return
        top = plate_anchors(self.platform, pose, self.convention)  # (6, 3) per leg
        r = 0.8 * leg_visual_dimensions(self.platform)["cylinder_radius"]
        for i, (a, b) in enumerate(zip(self.platform.base_anchors, top)):
            d = b - a
            path = f"/ghost/leg_{i + 1}"
            self.meshcat.SetObject(path, Cylinder(r, float(np.linalg.norm(d))), Rgba(*GHOST_RGBA))
            self.meshcat.SetTransform(path, RigidTransform(RotationMatrix.MakeFromOneVector(d, 2), (a + b) / 2))
        centre = top.mean(axis=0)
        order = np.argsort(np.arctan2(top[:, 1] - centre[1], top[:, 0] - centre[0]))  # a fan around the centre
        top = top[order]
        faces = np.array([[6, i, (i + 1) % 6] for i in range(6)], dtype=np.int32).T
        self.meshcat.SetTriangleMesh("/ghost/plate", np.c_[top.T, centre], faces, Rgba(*GHOST_RGBA))

    def _set_labels(self, new: list[str]) -> None:
        if new == self._labels:
            return
        for name in self._labels:
            self.meshcat.DeleteButton(name, strict=False)
        for name in new:
            self.meshcat.AddButton(name)
        self._labels = new

    def interact(self, duration: float | None = None, poll: float = 0.05, settle: float = 0.3) -> Readout:
        """Follow the sliders until ``duration`` seconds have passed (None: until interrupted). While a
        slider moves, the cheap readouts follow it; the assembly modes are counted once it rests for
        ``settle`` s."""
        start = time.monotonic()
        last = self.slider_pose()
        self.show(last)
        moved_at, counted = None, True
        while duration is None or time.monotonic() - start < duration:
            time.sleep(poll)
            pose = self.slider_pose()
            if not np.array_equal(pose, last):
                last, moved_at, counted = pose, time.monotonic(), False
                self.show(pose, modes=False)
            elif not counted and self.modes and time.monotonic() - moved_at > settle:
                self.show(pose)
                counted = True
        return self.readout

    def replay(
        self, t, poses, saturating=None, speed: float = 1.0, loop: bool = False, duration: float | None = None
    ) -> Readout:
        """Play ``poses`` ``(n, 6)`` SI at times ``t`` ``(n,)`` s in real time × ``speed`` (25 frames/s),
        once or in a loop, until ``duration`` wall seconds if given."""
        t = np.asarray(t, dtype=float) - t[0]
        start = time.monotonic()
        while True:
            played = time.monotonic()
            while True:
                now = (time.monotonic() - played) * speed
                i = min(int(np.searchsorted(t, now)), len(t) - 1)
                self.show(poses[i], t[i], modes=False, saturating=None if saturating is None else saturating[i])
                if i == len(t) - 1 or (duration is not None and time.monotonic() - start >= duration):
                    break
                time.sleep(0.04)
            if not loop or (duration is not None and time.monotonic() - start >= duration):
                return self.readout


def load_replay(path) -> tuple[np.ndarray, np.ndarray, np.ndarray | None, str]:
    """Times ``(n,)`` s, poses ``(n, 6)`` SI utn, per-sample saturation ``(n, 6)`` (or None) and the
    platform name (or "") from a ``simulate`` log (``log.npz``/``log.csv``), a ``run`` output
    (``trajectory.csv`` with ``summary.json``) or a folder holding one of them."""
    p = Path(path)
    if p.is_dir():
        for name in ("log.npz", "simulation/log.npz", "trajectory.csv", "log.csv"):
            if (p / name).exists():
                return load_replay(p / name)
        raise ReplayError(ReplayError.EMPTY_FOLDER.format(path=path))
    if not p.exists():
        raise ReplayError(ReplayError.MISSING.format(path=path))
    # read once, bounded (system.input_stream): a FIFO works, /dev/zero stops at the budget
    data = read_input(p, kind="replay log", limit=memory_budget(), missing=ReplayError.MISSING.format(path=path))
    if p.suffix == ".npz":
        try:
            with np.load(io.BytesIO(data), allow_pickle=False) as z:
                return (
                    np.asarray(z["t"], float),
                    np.asarray(z["pose"], float),
                    log_saturating(z["status"]),
                    str(z["platform"]),
                )
        # a truncated or damaged archive: zipfile's BadZipFile, zlib's error, EOFError, ...
        except (KeyError, ValueError, OSError, EOFError, zipfile.BadZipFile, zlib.error) as e:
            raise ReplayError(ReplayError.NOT_LOG.format(path=path, reason=str(e) or type(e).__name__)) from None
    return _load_csv(p, decode_text(data, p, "replay log"))


def _load_csv(p: Path, text: str):
    rows = list(csv.reader(io.StringIO(text, newline="")))
    if not rows:
        raise ReplayError(ReplayError.EMPTY.format(path=p))
    header = rows[0]
    for cols in (
        ["t"] + [f"pose_{c}" for c in ("px", "py", "pz", "ax", "ay", "az")],
        ["t", "px", "py", "pz", "alpha", "beta", "gama"],
    ):
        if all(c in header for c in cols):
            break
    else:
        raise ReplayError(ReplayError.COLUMNS.format(path=p, got=", ".join(header[:8])))
    idx = [header.index(c) for c in cols]
    try:
        data = np.array([[float(r[i]) for i in idx] for r in rows[1:]])
    except (ValueError, IndexError):
        bad = next(k for k, r in enumerate(rows[1:], 2) if len(r) <= max(idx) or not _floats(r, idx))
        raise ReplayError(ReplayError.ROW.format(path=p, line=bad)) from None
    if len(data) == 0:
        raise ReplayError(ReplayError.NO_SAMPLES.format(path=p))
    platform, convention = "", "utn"
    summary = p.parent / "summary.json"
    if cols[1] == "px" and summary.exists():
        meta = json.loads(summary.read_text(encoding="utf-8"))
        platform, convention = str(meta.get("platform", "")), str(meta.get("convention", "utn"))
    poses = data[:, 1:]
    if convention != "utn":  # the viewer's scene takes utn angles
        poses = np.c_[poses[:, :3], angles_from_matrix(rotation_matrix(poses[:, 3:], convention), "utn")]
    return data[:, 0], poses, None, platform


def _floats(row, idx) -> bool:
    try:
        [float(row[i]) for i in idx]
        return True
    except ValueError:
        return False
