"""Parametrised geometry families: a design vector (SI) -> the anchors of a ``Platform``.

``radial-6-6``: base anchors in three pairs centred at 270°, 30°, 150° (half-angle ``base_half_angle``), plate
anchors in three pairs centred at 330°, 90°, 210° (``top_half_angle``); leg 1 joins base 270°+φb to plate
330°−φt, leg 2 base 30°−φb to plate 330°+φt, and so on round the circle (the pairing of the
``gonzalez-dutra-2009`` preset, which is this family at base 0.62485 m, plate 0.392956 m, φb = 6.959°,
φt = 17.2124°). ``utn-3-6``: the UTN hexagon/triangle (``Platform.utn``) with sides b, d, a.
Every family also takes ``home_height`` (m): the box of required poses is relative to it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stewart_drake.core.geometry import LegConfig, Platform, utn_anchors


@dataclass(frozen=True)
class Family:
    """A family's name, its variables in order (lengths m, half-angles rad) and its YAML anchor section."""

    name: str
    variables: tuple


FAMILIES = {
    "radial-6-6": Family(
        "radial-6-6", ("base_radius", "top_radius", "base_half_angle", "top_half_angle", "home_height")
    ),
    "utn-3-6": Family("utn-3-6", ("b", "d", "a", "home_height")),
}
BASE_CENTRES = np.radians([270.0, 30.0, 150.0])
TOP_CENTRES = np.radians([330.0, 90.0, 210.0])


def radial_angles(base_half: float, top_half: float) -> tuple[np.ndarray, np.ndarray]:
    """``(base (6,), top (6,))`` anchor angles (rad) of leg 1..6 of the radial-6-6 family."""
    pb = [BASE_CENTRES[0] + base_half, BASE_CENTRES[1] - base_half, BASE_CENTRES[1] + base_half]
    pb += [BASE_CENTRES[2] - base_half, BASE_CENTRES[2] + base_half, BASE_CENTRES[0] - base_half]
    pt = [TOP_CENTRES[0] - top_half, TOP_CENTRES[0] + top_half, TOP_CENTRES[1] - top_half]
    pt += [TOP_CENTRES[1] + top_half, TOP_CENTRES[2] - top_half, TOP_CENTRES[2] + top_half]
    return np.mod(np.array(pb), 2 * np.pi), np.mod(np.array(pt), 2 * np.pi)


def anchors(family: str, x) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(base (6, 3), top (k, 3), leg_top (6,))`` anchors (m) of the design ``x`` (SI, the family's order)."""
    x = np.asarray(x, dtype=float)
    if family == "radial-6-6":
        rb, rt, hb, ht = x[:4]
        ab, at = radial_angles(hb, ht)
        base = np.stack([rb * np.cos(ab), rb * np.sin(ab), np.zeros(6)], -1)
        top = np.stack([rt * np.cos(at), rt * np.sin(at), np.zeros(6)], -1)
        return base, top, np.arange(6)
    b, d, a = x[:3]
    base, top = utn_anchors(b, d, a)
    return base, top, np.array([0, 0, 1, 1, 2, 2])


def home_height(family: str, x) -> float:
    """The design's home height (m): its last variable."""
    return float(np.asarray(x, dtype=float)[-1])


def base_radius(family: str, x) -> float:
    """The largest base anchor radius (m) of the design."""
    base, _, _ = anchors(family, x)
    return float(np.max(np.hypot(base[:, 0], base[:, 1])))


def design_platform(req, x, stroke, name: str = "synthesised") -> Platform:
    """The ``Platform`` of design ``x`` for requirements ``req``: its stroke ``(2,)`` m, the payload as the
    plate, the actuator's force, speed and stiffness as the legs' limits."""
    base, top, leg_top = anchors(req.family, x)
    legs = LegConfig(max_force=req.max_force, max_speed=req.max_speed, stiffness=req.stiffness)
    return Platform(
        name=name,
        base_anchors=base,
        top_anchors=top,
        leg_top=leg_top,
        stroke=np.asarray(stroke, dtype=float),
        mass=req.mass,
        com=req.com,
        inertia=req.inertia,
        home_height=home_height(req.family, x),
        legs=legs,
        description=f"synthesised from {req.source} ({req.family})",
    )


def design_yaml_fields(req, x) -> dict:
    """The anchor section of the design's platform file, in metres and degrees."""
    x = np.asarray(x, dtype=float)
    if req.family == "radial-6-6":
        ab, at = radial_angles(x[2], x[3])
        return {
            "radial": {
                "base_radius": float(x[0]),
                "base_angles_deg": np.degrees(ab).tolist(),
                "top_radius": float(x[1]),
                "top_angles_deg": np.degrees(at).tolist(),
            }
        }
    return {"utn": {"b": float(x[0]), "d": float(x[1]), "a": float(x[2])}}
