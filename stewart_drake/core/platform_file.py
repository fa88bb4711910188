"""Writing a ``Platform`` as a platform file (explicit anchors, metres) that ``load_platform`` reads back to the
same platform, and building one from explicit per-leg anchors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import yaml

from stewart_drake.core.geometry import LegConfig, Platform
from stewart_drake.errors import API_FILE_EXISTS, OutputError

HEADER = "# stewart-drake platform file (explicit anchors, SI: metres, kilograms), written by Platform.to_yaml\n"


def unique_rows(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(distinct points in first-seen order, index of each row's point)`` of ``(n, 3)`` points (exact)."""
    distinct: list[tuple] = []
    index = []
    for p in map(tuple, np.asarray(points, dtype=float).tolist()):
        if p not in distinct:
            distinct.append(p)
        index.append(distinct.index(p))
    return np.array(distinct), np.array(index)


def platform_document(platform: Platform) -> dict:
    """The platform file's mapping (``length_unit: m``; six base points, or distinct joints + ``leg_base``)."""
    base, leg_base = unique_rows(platform.base_anchors)
    I = platform.inertia
    legs = platform.legs
    doc = {"name": platform.name, "description": platform.description, "length_unit": "m"}
    doc["base_anchors"] = base.tolist()
    if len(base) < 6:
        doc["leg_base"] = leg_base.tolist()
    doc |= {
        "top_anchors": platform.top_anchors.tolist(),
        "leg_top": platform.leg_top.tolist(),
        "stroke": platform.stroke.tolist(),
        "home_height": float(platform.home_height),
        "rotation_centre": platform.rotation_centre.tolist(),
        "plate": {
            "mass": float(platform.mass),
            "com": platform.com.tolist(),
            "inertia": [I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]],
        },
        "legs": {k: getattr(legs, k) for k in LegConfig.__dataclass_fields__ if getattr(legs, k) is not None},
        "plate_below_base_allowed": bool(platform.plate_below_base_allowed),
    }
    doc["plate"]["inertia"] = [float(v) for v in doc["plate"]["inertia"]]
    doc["legs"] = {k: float(v) for k, v in doc["legs"].items()}
    return doc


def write_platform_yaml(platform: Platform, path, overwrite: bool = False) -> Path:
    """Write ``platform`` to ``path`` (a new file unless ``overwrite``); numbers as ``repr`` floats, so that
    loading the file gives the same arrays bit for bit."""
    p = Path(path)
    if p.exists() and not overwrite:
        raise OutputError(API_FILE_EXISTS.format(path=path))
    text = HEADER + yaml.safe_dump(platform_document(platform), sort_keys=False, default_flow_style=None, width=120)
    p.write_text(text, encoding="utf-8")
    return p


def platform_from_anchors(base_anchors, top_anchors_per_leg, stroke, name: str = "custom", **kwargs) -> Platform:
    """A ``Platform`` from each leg's base anchor ``(6, 3)`` (in B) and plate anchor ``(6, 3)`` (in T), metres;
    legs that share a plate point share its anchor. ``kwargs``: the other ``Platform`` fields (mass, com,
    inertia default to a massless plate)."""
    top, leg_top = unique_rows(top_anchors_per_leg)
    kwargs.setdefault("mass", 0.0)
    kwargs.setdefault("com", np.zeros(3))
    kwargs.setdefault("inertia", np.zeros((3, 3)))
    return Platform(
        name=name,
        base_anchors=np.asarray(base_anchors, dtype=float),
        top_anchors=top,
        leg_top=leg_top,
        stroke=np.asarray(stroke, dtype=float),
        **kwargs,
    )
