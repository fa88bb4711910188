"""The calibrated platform file: explicit anchors, ``legs.length_offset`` and a ``calibration:`` block, in
metres, that ``load_platform`` reads like any platform file (every number written with full precision)."""

from __future__ import annotations

import dataclasses

import numpy as np
import yaml

from stewart_drake.core.geometry import CalibrationRecord, Platform, base_joints


class _Dumper(yaml.SafeDumper):
    """PyYAML's safe dumper writing short lists of numbers in flow style (``[0.1, 0.2, 0.3]``)."""

    def represent_list(self, data):
        flow = bool(data) and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in data)
        return self.represent_sequence("tag:yaml.org,2002:seq", data, flow_style=flow or None)


_Dumper.add_representer(list, _Dumper.represent_list)


def _floats(a) -> list:
    return np.asarray(a, dtype=float).tolist()


def platform_document(platform: Platform, calibration: CalibrationRecord | None = None) -> dict:
    """The platform file's mapping (``PlatformConfig`` keys, metres): explicit anchors (shared base joints
    listed once with ``leg_base``), plate mass properties, stroke, legs with ``length_offset``."""
    first, leg_joint = base_joints(platform)
    I = platform.inertia
    legs = {k: v for k, v in dataclasses.asdict(platform.legs).items() if v is not None}
    legs["length_offset"] = _floats(platform.length_offset)
    if platform.has_sensor_gains:
        legs["length_gain"] = _floats(platform.length_gain)
    else:
        legs.pop("length_gain", None)
    doc = {
        "name": platform.name,
        "description": platform.description,
        "length_unit": "m",
        "base_anchors": _floats(platform.base_anchors[first]),
        "top_anchors": _floats(platform.top_anchors),
        "leg_top": [int(j) for j in platform.leg_top],
    }
    if len(first) < 6:
        doc["leg_base"] = [int(j) for j in leg_joint]
    doc.update(
        {
            "stroke": _floats(platform.stroke),
            "plate": {
                "mass": float(platform.mass),
                "com": _floats(platform.com),
                "inertia": [
                    float(I[0, 0]),
                    float(I[1, 1]),
                    float(I[2, 2]),
                    float(I[0, 1]),
                    float(I[0, 2]),
                    float(I[1, 2]),
                ],
            },
            "rotation_centre": _floats(platform.rotation_centre),
            "home_height": float(platform.home_height),
            "legs": legs,
            "plate_below_base_allowed": bool(platform.plate_below_base_allowed),
        }
    )
    if calibration is not None:
        doc["calibration"] = dataclasses.asdict(calibration)
    return doc


def platform_yaml(platform: Platform, calibration: CalibrationRecord | None = None, header: str = "") -> str:
    """The YAML text of ``platform_document`` (lists of numbers in flow style), after ``header`` comment lines."""
    text = yaml.dump(
        platform_document(platform, calibration), Dumper=_Dumper, sort_keys=False, allow_unicode=True, width=120
    )
    comments = "".join(f"# {line}\n" for line in header.splitlines())
    return comments + text
