"""Validation: how well a platform model predicts measurements it was not fitted to, and (for synthetic
data) how far it is from the true machine.

``validation_errors`` compares a model with measurements: the forward kinematics of the model at the
readings against what was measured (plate position and orientation for ``pose`` data, target positions for
``points``, tilts for ``inclinometer``) and, for ``pose`` data, the leg lengths the model predicts at the
measured pose against the readings. The measured side carries its noise, so these errors include it.
``truth_errors`` compares a model with the true machine at given poses, noise-free.
"""

from __future__ import annotations

import numpy as np

from stewart_drake.calibration.measurements import Measurements
from stewart_drake.calibration.model import rotation_angle, solve_poses, tilts
from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.newton_fk import forward_kinematics
from stewart_drake.core.rotations import rotation_matrix


def _stats(x: np.ndarray, unit: str) -> dict:
    x = np.abs(np.asarray(x, dtype=float))
    return {"rms": float(np.sqrt(np.mean(x**2))), "max": float(x.max()), "unit": unit, "count": int(x.size)}


def _fk(platform: Platform, readings, initial, convention: str):
    r = forward_kinematics(
        platform, platform.lengths_from_readings(readings), initial, convention, check_singularity=False, max_iter=60
    )
    r.raise_if_failed()
    return r.iterate[..., :3], r.rotation


def validation_errors(platform: Platform, targets, data: Measurements, convention: str = "utn") -> dict:
    """``{"leg_length": {rms, max, unit}, "position": ..., "angle": ...}`` (``pose``), ``{"target": ...}``
    (``points``, with ``(K, 3)`` plate-frame ``targets``) or ``{"tilt": ...}`` (``inclinometer``): the model's
    errors against the measurements ``data`` (m, rad; RMS over poses of the 3-D distance or angle). The forward
    kinematics starts from the measured pose (``pose``) or from home (``model.solve_poses``); the poses where it
    does not converge (the model admits no assembly at those readings) are left out of the forward-kinematics
    statistics and listed as ``"unsolved": {"count", "lines"}``; with none solved those statistics are absent."""
    p, R, solved = solve_poses(platform, data.readings, data.poses if data.kind == "pose" else None, convention)
    out = {}
    if data.kind == "pose":
        L = leg_lengths(platform, data.poses, convention)
        out["leg_length"] = _stats(platform.readings(L) - data.readings, "m")
        if solved.any():
            Rm = rotation_matrix(data.poses[solved, 3:], convention)
            out["position"] = _stats(np.linalg.norm(p[solved] - data.poses[solved, :3], axis=-1), "m")
            out["angle"] = _stats(rotation_angle(R[solved], Rm), "rad")
    elif solved.any() and data.kind == "points":
        y = p[solved, None, :] + np.einsum("nij,kj->nki", R[solved], np.asarray(targets) - platform.rotation_centre)
        out["target"] = _stats(np.linalg.norm(y - data.targets[solved], axis=-1).ravel(), "m")
    elif solved.any():
        out["tilt"] = _stats((tilts(R[solved]) - data.tilts[solved]).ravel(), "rad")
    if not solved.all():
        out["unsolved"] = {"count": int((~solved).sum()), "lines": [int(v) for v in data.lines[~solved]]}
    return out


def truth_errors(truth: Platform, model: Platform, poses, convention: str = "utn") -> dict:
    """The model's errors against the true machine at ``(n, 6)`` true poses, noise-free: ``leg_length``
    (the reading the model predicts at the true pose minus the true reading) and ``position``/``angle`` (the
    model's forward kinematics of the true readings against the true pose); m and rad."""
    q = np.asarray(poses, dtype=float)
    r_true = truth.readings(leg_lengths(truth, q, convention))
    p, R = _fk(model, r_true, q, convention)
    return {
        "leg_length": _stats(model.readings(leg_lengths(model, q, convention)) - r_true, "m"),
        "position": _stats(np.linalg.norm(p - q[:, :3], axis=-1), "m"),
        "angle": _stats(rotation_angle(R, rotation_matrix(q[:, 3:], convention)), "rad"),
    }
