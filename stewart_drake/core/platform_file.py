"""Writing a ``Platform`` as a platform file (explicit anchors, metres) that ``load_platform`` reads back to the
same platform, and building one from explicit per-leg anchors."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import yaml

from stewart_drake.core.argcheck import as_real_array, check_shape
from stewart_drake.core.geometry import CalibrationRecord, Platform
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


class _Dumper(yaml.SafeDumper):
    """PyYAML's safe dumper writing short lists of numbers in flow style (``[0.1, 0.2, 0.3]``)."""

    def represent_list(self, data):
        flow = bool(data) and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in data)
        return self.represent_sequence("tag:yaml.org,2002:seq", data, flow_style=flow or None)


_Dumper.add_representer(list, _Dumper.represent_list)


def platform_document(platform: Platform, calibration: CalibrationRecord | None = None) -> dict:
    """The platform file's mapping (``length_unit: m``; six base points, or distinct joints + ``leg_base``;
    ``legs.length_offset``/``length_gain`` of a calibrated platform; its ``calibration:`` block if given)."""
    base, leg_base = unique_rows(platform.base_anchors)
    I = platform.inertia
    legs = {k: v for k, v in dataclasses.asdict(platform.legs).items() if v is not None}
    legs = {k: [float(x) for x in v] if isinstance(v, (list, tuple)) else float(v) for k, v in legs.items()}
    if not np.any(platform.length_offset):
        legs.pop("length_offset", None)
    if not platform.has_sensor_gains:
        legs.pop("length_gain", None)
    doc = {"name": platform.name, "description": platform.description, "length_unit": "m"}
    doc["base_anchors"] = base.tolist()
    if len(base) < 6:
        doc["leg_base"] = leg_base.tolist()
    doc |= {
        "top_anchors": platform.top_anchors.tolist(),
        "leg_top": [int(j) for j in platform.leg_top],
        "stroke": platform.stroke.tolist(),
        "home_height": float(platform.home_height),
        "rotation_centre": platform.rotation_centre.tolist(),
        "plate": {
            "mass": float(platform.mass),
            "com": platform.com.tolist(),
            "inertia": [float(v) for v in (I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2])],
        },
        "legs": legs,
        "plate_below_base_allowed": bool(platform.plate_below_base_allowed),
    }
    if calibration is not None:
        doc["calibration"] = dataclasses.asdict(calibration)
    return doc


def platform_yaml(platform: Platform, calibration: CalibrationRecord | None = None, header: str = HEADER) -> str:
    """The YAML text of ``platform_document`` (lists of numbers in flow style, every float as ``repr``, so that
    loading it gives the same arrays bit for bit), after ``header`` (comment lines)."""
    text = yaml.dump(
        platform_document(platform, calibration), Dumper=_Dumper, sort_keys=False, allow_unicode=True, width=120
    )
    return "".join(f"# {line.removeprefix('# ')}\n" for line in header.splitlines()) + text


def write_platform_yaml(platform: Platform, path, overwrite: bool = False) -> Path:
    """Write ``platform`` to ``path`` (a new file unless ``overwrite``)."""
    p = Path(path)
    if p.exists() and not overwrite:
        raise OutputError(API_FILE_EXISTS.format(path=path))
    p.write_text(platform_yaml(platform), encoding="utf-8")
    return p


def platform_from_anchors(base_anchors, top_anchors_per_leg, stroke, name: str = "custom", **kwargs) -> Platform:
    """A ``Platform`` from each leg's base anchor ``(6, 3)`` (in B) and plate anchor ``(6, 3)`` (in T), metres;
    legs that share a plate point share its anchor. ``kwargs``: the other ``Platform`` fields (mass, com,
    inertia default to a massless plate)."""
    top, leg_top = unique_rows(check_shape(top_anchors_per_leg, "top_anchors_per_leg", (6, 3)))
    kwargs.setdefault("mass", 0.0)
    kwargs.setdefault("com", np.zeros(3))
    kwargs.setdefault("inertia", np.zeros((3, 3)))
    return Platform(
        name=name,
        base_anchors=as_real_array(base_anchors, "base_anchors"),
        top_anchors=top,
        leg_top=leg_top,
        stroke=as_real_array(stroke, "stroke"),
        **kwargs,
    )
