"""Synthetic measurements: a "true" machine drawn around the nominal, measured with noise.

The errors are drawn with the laws of the Monte Carlo ``--vary`` grammar (``montecarlo.spec``: the command
parses them; here a law is any object with ``kind`` and ``values``): ``anchor`` moves every physical base
joint and plate joint per axis (legs sharing a joint keep sharing it), ``leg_offset`` is what each sensor
reads beyond the joint-to-joint length, as in a Monte Carlo study (the sensor reads L + leg_offset, so the
true machine's ``legs.length_offset`` is the nominal's minus it). The measured side: readings + N(0, σ_l),
positions + N(0, σ_p) per axis, orientations rotated by N(0, σ_a) per axis, tilts + N(0, σ_a).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stewart_drake.calibration.measurements import Measurements
from stewart_drake.calibration.model import Layout, Noise, exp_so3, measure, poses_from_frames
from stewart_drake.core.geometry import Platform, base_joints
from stewart_drake.core.kinematics import anchor_radius


def _draw(rng, law, shape) -> np.ndarray:
    """Offsets of ``shape`` from a law around a zero nominal (None: zeros)."""
    if law is None:
        return np.zeros(shape)
    if law.kind == "fixed":
        return np.full(shape, float(law.values[0]))
    if law.kind == "plusminus":
        return rng.uniform(-law.values[0], law.values[0], size=shape)
    if law.kind == "uniform":
        return rng.uniform(*law.values, size=shape)
    if law.kind == "choice":
        return np.asarray(law.values, float)[rng.integers(len(law.values), size=shape)]
    raise ValueError(f"law {law.kind!r} has no zero-nominal form")  # internal: the spec refuses ±P% of zero


@dataclass(frozen=True, eq=False)
class Truth:
    """The drawn machine: ``platform`` (the nominal with the drawn joints and offsets), the draws
    (``base_offset`` (m, 3) per physical base joint, ``top_offset`` (k, 3), ``leg_offset`` (6,): what each
    sensor reads beyond the joint-to-joint length), the plate-frame ``targets`` (K, 3) and the true ``poses``."""

    platform: Platform
    base_offset: np.ndarray
    top_offset: np.ndarray
    leg_offset: np.ndarray
    targets: np.ndarray
    poses: np.ndarray

    def to_dict(self) -> dict:
        return {
            "base_joint_offset_m": self.base_offset.tolist(),
            "plate_joint_offset_m": self.top_offset.tolist(),
            "leg_offset_m": self.leg_offset.tolist(),
            "length_offset_m": self.platform.length_offset.tolist(),
            "targets_m": self.targets.tolist(),
            "poses": self.poses.tolist(),
        }


def draw_machine(nominal: Platform, laws: dict, rng: np.random.Generator) -> tuple[Platform, dict]:
    """``(true platform, draws)`` with the ``anchor`` and ``leg_offset`` laws of ``laws`` (other keys
    ignored here; the command refuses them). The stream matches a Monte Carlo draw's: (6, 3) base rows
    (a shared joint takes its first leg's), (k, 3) plate rows, then (6,) offsets."""
    first, leg_joint = base_joints(nominal)
    k = len(nominal.top_anchors)
    base = _draw(rng, laws.get("anchor"), (6, 3))[first]
    top = _draw(rng, laws.get("anchor"), (k, 3))
    leg = _draw(rng, laws.get("leg_offset"), (6,))
    legs = type(nominal.legs)(**{**vars(nominal.legs), "length_offset": (nominal.length_offset - leg).tolist()})
    truth = nominal.replace(
        base_anchors=nominal.base_anchors + base[leg_joint],
        top_anchors=nominal.top_anchors + top,
        legs=legs,
        name=f"{nominal.name}-true",
    )
    return truth, {"base": base, "top": top, "leg": leg}


def default_targets(platform: Platform, n: int) -> np.ndarray:
    """``(n, 3)`` plate-frame target positions: evenly around the rotation centre at 0.8 × the anchor
    radius, 20 mm above the plate (where a tracker's reflectors would sit)."""
    ang = np.pi / 2 + 2 * np.pi * np.arange(n) / n
    r = 0.8 * anchor_radius(platform)
    return platform.rotation_centre + np.stack([r * np.cos(ang), r * np.sin(ang), np.full(n, 0.02)], -1)


def simulate_measurements(
    nominal: Platform,
    laws: dict,
    poses,
    kind: str = "pose",
    noise: Noise = Noise(),
    seed: int = 0,
    convention: str = "utn",
    n_targets: int = 3,
    truth: Platform | None = None,
) -> tuple[Measurements, Truth]:
    """Measure a machine drawn from ``laws`` (or the given ``truth``) at ``(n, 6)`` poses (m, rad) with
    ``noise``; seeded. Returns the measurements (file-free: lines 2..n+1 as if written with a header)
    and the ``Truth``."""
    rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(25,)))
    if truth is None:
        truth, d = draw_machine(nominal, laws, rng)
    else:
        Lay = Layout(nominal, "pose")
        dt = Lay.split(Lay.theta(truth) - Lay.theta(nominal))
        d = {"base": dt[0], "top": dt[1], "leg": nominal.length_offset - truth.length_offset}
    q = np.asarray(poses, dtype=float).reshape(-1, 6)
    n = len(q)
    targets = default_targets(nominal, n_targets) if kind == "points" else np.zeros((0, 3))
    clean = measure(truth, q, convention, targets if kind == "points" else None)
    readings = clean["readings"] + rng.normal(0, noise.length, (n, 6))
    poses_m = tg = tl = None
    if kind == "pose":
        R = exp_so3(rng.normal(0, noise.angle, (n, 3))) @ clean["R"]
        poses_m = poses_from_frames(q[:, :3] + rng.normal(0, noise.position, (n, 3)), R, convention)
    elif kind == "points":
        tg = clean["targets"] + rng.normal(0, noise.position, clean["targets"].shape)
    else:
        tl = clean["tilts"] + rng.normal(0, noise.angle, (n, 2))
    data = Measurements(kind, readings, poses_m, tg, tl, np.ones(n), np.arange(2, n + 2))
    return data, Truth(truth, d["base"], d["top"], d["leg"], targets, q)
