"""The requirements file of ``stewart-drake optimize``: what the platform must do, in the user's units.

Loaded with the project's safe YAML loader into ``RequirementsConfig`` (edge units), checked field by field
(every message names the file, line and field, and the value as written), then converted to SI in one
``Requirements`` object. The template (``stewart-drake init --requirements-template``) documents every key.

The workspace box is relative to the home pose [0, 0, home_height, 0, 0, 0]: every pose p_home + δ with
δ in the box must be reachable (the proof, ``synthesis.proof``, shows it for the chosen design).
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field

import numpy as np

from stewart_drake.core.geometry import load_yaml_config
from stewart_drake.core.rotations import ANGLE_UNITS, CONVENTIONS, LENGTH_UNITS
from stewart_drake.core.yamlio import field_name
from stewart_drake.errors import SynthesisError
from stewart_drake.synthesis.families import FAMILIES

AXES = ("px", "py", "pz", "a", "b", "g")
OBJECTIVES = {
    # name -> (metric key, sense: +1 minimise, -1 maximise, unit)
    "peak_force": ("peak_force", 1.0, "N"),
    "stroke": ("stroke", 1.0, "m"),
    "base_radius": ("base_radius", 1.0, "m"),
    "frequency": ("frequency", -1.0, "Hz"),
    "condition": ("condition", 1.0, ""),
}
DEFAULT_STROKE_MARGIN_M = 0.002  # the stroke exceeds the sampled leg range by this much at each end
MAX_BOX_ANGLE_RAD = np.radians(80.0)  # |angle| in the box (Euler angles stay far from gimbal lock)


# ----------------------------------------------------------------------------------------------
# YAML schema (edge units).


@dataclass
class VariablesConfig:
    """Each design variable's bounds ``[low, high]`` (``low == high`` fixes it): lengths in the length unit,
    half-angles in the angle unit. ``radial-6-6``: base_radius, top_radius, base_half_angle, top_half_angle,
    home_height; ``utn-3-6``: b, d, a, home_height."""

    base_radius: list[float] | None = None
    top_radius: list[float] | None = None
    base_half_angle: list[float] | None = None
    top_half_angle: list[float] | None = None
    b: list[float] | None = None
    d: list[float] | None = None
    a: list[float] | None = None
    home_height: list[float] | None = None


@dataclass
class BoxConfig:
    """The required box of poses relative to home: ``[low, high]`` per axis (axes left out: [0, 0])."""

    px: list[float] | None = None
    py: list[float] | None = None
    pz: list[float] | None = None
    a: list[float] | None = None
    b: list[float] | None = None
    g: list[float] | None = None


@dataclass
class PayloadConfig:
    """The moving mass (plate and payload): kg, centre of mass (length unit, plate frame), inertia about the
    centre of mass (kg·m² in the file's length unit squared: Ixx Iyy Izz Ixy Ixz Iyz)."""

    mass: float | None = None
    com: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    inertia: list[float] = field(default_factory=lambda: [0.0] * 6)


@dataclass
class RateConfig:
    """Symmetric bounds on every axis: ``linear`` (length unit per s or s²), ``angular`` (angle unit per s or s²)."""

    linear: float = 0.0
    angular: float = 0.0


@dataclass
class MotionConfig:
    velocity: RateConfig = field(default_factory=RateConfig)
    acceleration: RateConfig = field(default_factory=RateConfig)


@dataclass
class ActuatorConfig:
    """The actuator family: force (N), speed (length unit per s), either ``stroke_ratio`` (L_max / L_min the
    family achieves) or a fixed ``stroke: [L_min, L_max]``, axial ``stiffness`` (N per length unit) and the
    ``stroke_margin`` kept beyond the leg lengths the box needs (length unit)."""

    max_force: float | None = None
    max_speed: float | None = None
    stroke_ratio: float | None = None
    stroke: list[float] | None = None
    stiffness: float | None = None
    stroke_margin: float | None = None


@dataclass
class LimitsConfig:
    base_radius_max: float | None = None  # length unit
    min_frequency_hz: float | None = None  # Hz, lowest natural frequency over the box
    max_condition: float | None = None  # worst scaled condition number of J⁻¹ over the box
    joint_cone: float | None = None  # angle unit: largest angle between a leg and the base / plate normal
    leg_diameter: float | None = None  # length unit: legs (as cylinders of this diameter) never touch


@dataclass
class RequirementsConfig:
    name: str = ""
    length_unit: str = ""
    angle_unit: str = ""
    convention: str = "utn"
    family: str = ""
    variables: VariablesConfig | None = None
    workspace: BoxConfig | None = None
    payload: PayloadConfig | None = None
    motion: MotionConfig = field(default_factory=MotionConfig)
    actuator: ActuatorConfig | None = None
    limits: LimitsConfig = field(default_factory=LimitsConfig)
    objectives: list[str] = field(default_factory=lambda: ["peak_force", "stroke"])


# ----------------------------------------------------------------------------------------------
# SI requirements.


@dataclass(frozen=True, eq=False)
class Requirements:
    """Requirements in SI (metres, radians, N, kg). ``lower``/``upper`` (n,) bound the family's variables
    ``variables`` (lengths m, angles rad); ``box_lo``/``box_hi`` (6,) the box relative to home [m; rad];
    ``v_max``/``a_max`` (6,) the motion envelope [m/s, rad/s; m/s², rad/s²]; ``stroke`` (2,) a fixed stroke
    or None (then ``stroke_ratio``); limits None when not required."""

    name: str
    family: str
    variables: tuple
    lower: np.ndarray
    upper: np.ndarray
    box_lo: np.ndarray
    box_hi: np.ndarray
    mass: float
    com: np.ndarray
    inertia: np.ndarray
    v_max: np.ndarray
    a_max: np.ndarray
    max_force: float
    max_speed: float | None
    stroke_ratio: float | None
    stroke: np.ndarray | None
    stiffness: float
    stroke_margin: float
    base_radius_max: float | None
    min_frequency_hz: float | None
    max_condition: float | None
    objectives: tuple
    joint_cone: float | None = None
    leg_diameter: float | None = None
    convention: str = "utn"
    source: str = "requirements"
    units: tuple = ("m", "rad")

    def to_dict(self) -> dict:
        """JSON-able SI form (the key of a search is a hash of it)."""
        out = {}
        for k, v in self.__dict__.items():
            out[k] = v.tolist() if isinstance(v, np.ndarray) else (list(v) if isinstance(v, tuple) else v)
        out.pop("source")
        return out

    def key(self) -> str:
        """A hash of the requirements (not of the file name): searches with the same key share evaluations."""
        return hashlib.sha256(json.dumps(self.to_dict(), sort_keys=True).encode()).hexdigest()[:16]


def _err(where, path, shown, problem, value=None):
    w = where.get(path)
    return SynthesisError(
        SynthesisError.FIELD.format(
            path=shown,
            line=w.line if w else "?",
            field=field_name(path),
            value=(w.text if w else value) if value is None else value,
            problem=problem,
        )
    )


def _pair(values, path, where, shown, positive=False, ordered=True) -> np.ndarray:
    """Two numbers [low, high] (``SynthesisError`` naming ``path`` otherwise)."""
    if values is None:
        return None
    if len(values) != 2:
        raise _err(where, path, shown, "must be [low, high] (2 numbers)", value=values)
    lo, hi = values
    if ordered and lo > hi:
        raise _err(where, path, shown, "is reversed: low must be <= high", value=values)
    if positive and not lo > 0:
        raise _err(where, path, shown, "must be > 0", value=values)
    return np.array([lo, hi], dtype=float)


def _positive(value, path, where, shown, required: str | None = None):
    if value is None:
        if required:
            raise SynthesisError(SynthesisError.MISSING.format(path=shown, field=field_name(path), what=required))
        return None
    if not value > 0:
        raise _err(where, path, shown, "must be > 0")
    return float(value)


def requirements_from_config(cfg: RequirementsConfig, where: dict, shown: str) -> Requirements:
    """Check ``cfg`` (messages name ``shown``, the line and the field) and convert it to SI."""
    for key, units in (("length_unit", LENGTH_UNITS), ("angle_unit", ANGLE_UNITS)):
        value = getattr(cfg, key)
        if not value:
            raise SynthesisError(
                SynthesisError.MISSING.format(path=shown, field=key, what=f"the unit of the file: {', '.join(units)}")
            )
        if value not in units:
            raise _err(where, (key,), shown, f"is not a unit ({', '.join(units)})")
    if cfg.convention not in CONVENTIONS:
        raise _err(where, ("convention",), shown, f"is not a convention ({', '.join(CONVENTIONS)})")
    kl, ka = LENGTH_UNITS[cfg.length_unit], ANGLE_UNITS[cfg.angle_unit]
    if not cfg.family:
        raise SynthesisError(
            SynthesisError.MISSING.format(path=shown, field="family", what=f"one of {', '.join(FAMILIES)}")
        )
    if cfg.family not in FAMILIES:
        w = where.get(("family",))
        raise SynthesisError(
            SynthesisError.FAMILY.format(
                path=shown, line=w.line if w else "?", value=cfg.family, valid=", ".join(FAMILIES)
            )
        )
    fam = FAMILIES[cfg.family]
    if cfg.variables is None:
        raise SynthesisError(
            SynthesisError.MISSING.format(path=shown, field="variables", what="bounds of the family's variables")
        )
    lower, upper = [], []
    for name in VariablesConfig.__dataclass_fields__:
        given = getattr(cfg.variables, name)
        if given is not None and name not in fam.variables:
            w = where.get(("variables", name))
            raise SynthesisError(
                SynthesisError.VARIABLE.format(
                    path=shown,
                    line=w.line if w else "?",
                    name=name,
                    family=cfg.family,
                    valid=", ".join(fam.variables),
                )
            )
    for name in fam.variables:
        given = getattr(cfg.variables, name)
        if given is None:
            raise SynthesisError(SynthesisError.VARIABLE_MISSING.format(path=shown, name=name, family=cfg.family))
        angle = name.endswith("half_angle")
        pair = _pair(given, ("variables", name), where, shown, positive=not angle)
        if angle and (pair[0] < 0 or pair[1] * ka >= np.pi / 3):
            raise _err(where, ("variables", name), shown, "must lie in [0, 60) degrees", value=given)
        pair = pair * (ka if angle else kl)
        lower.append(pair[0])
        upper.append(pair[1])
    if cfg.workspace is None:
        raise SynthesisError(
            SynthesisError.MISSING.format(path=shown, field="workspace", what="the box of poses relative to home")
        )
    box = np.zeros((2, 6))
    given_axes = 0
    for j, axis in enumerate(AXES):
        pair = _pair(getattr(cfg.workspace, axis), ("workspace", axis), where, shown)
        if pair is None:
            continue
        given_axes += 1
        scale = kl if j < 3 else ka
        if j >= 3 and np.max(np.abs(pair)) * scale > MAX_BOX_ANGLE_RAD:
            raise _err(where, ("workspace", axis), shown, "is too large (at most 80 degrees)", value=list(pair))
        if j < 3 and np.max(np.abs(pair)) * scale > 10.0:
            raise _err(where, ("workspace", axis), shown, "is too large (at most 10 m)", value=list(pair))
        box[:, j] = pair * scale
    if given_axes == 0:
        raise SynthesisError(
            SynthesisError.FIELD.format(
                path=shown,
                line=where[("workspace",)].line if ("workspace",) in where else "?",
                field="workspace",
                value="{}",
                problem="is an empty box: give at least one of px, py, pz, a, b, g as [low, high]",
            )
        )
    pay = cfg.payload
    if pay is None:
        raise SynthesisError(SynthesisError.MISSING.format(path=shown, field="payload", what="mass, com, inertia"))
    mass = _positive(pay.mass, ("payload", "mass"), where, shown, "the moving mass in kg")
    if len(pay.com) != 3:
        raise _err(where, ("payload", "com"), shown, "must be 3 numbers", value=pay.com)
    if len(pay.inertia) != 6:
        raise _err(
            where, ("payload", "inertia"), shown, "must be 6 numbers (Ixx Iyy Izz Ixy Ixz Iyz)", value=pay.inertia
        )
    ixx, iyy, izz, ixy, ixz, iyz = pay.inertia
    inertia = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]]) * kl**2
    if np.linalg.eigvalsh(inertia)[0] <= 0:
        raise _err(where, ("payload", "inertia"), shown, "is not positive definite", value=pay.inertia)
    rates = {}
    for part in ("velocity", "acceleration"):
        r = getattr(cfg.motion, part)
        for sub in ("linear", "angular"):
            if getattr(r, sub) < 0:
                raise _err(where, ("motion", part, sub), shown, "is a magnitude and must be >= 0")
        rates[part] = np.r_[np.full(3, r.linear * kl), np.full(3, r.angular * ka)]
    act = cfg.actuator
    if act is None:
        raise SynthesisError(
            SynthesisError.MISSING.format(
                path=shown, field="actuator", what="max_force, stroke_ratio or stroke, stiffness"
            )
        )
    max_force = _positive(act.max_force, ("actuator", "max_force"), where, shown, "the actuator's force in N")
    max_speed = _positive(act.max_speed, ("actuator", "max_speed"), where, shown)
    stiffness = _positive(act.stiffness, ("actuator", "stiffness"), where, shown, "N per length unit")
    if (act.stroke_ratio is None) == (act.stroke is None):
        raise SynthesisError(
            (SynthesisError.STROKE_BOTH if act.stroke is not None else SynthesisError.STROKE_NONE).format(path=shown)
        )
    ratio = None
    if act.stroke_ratio is not None:
        ratio = float(act.stroke_ratio)
        if not ratio > 1:
            raise _err(where, ("actuator", "stroke_ratio"), shown, "must be > 1 (L_max / L_min)")
    stroke = _pair(act.stroke, ("actuator", "stroke"), where, shown, positive=True)
    if stroke is not None:
        if stroke[0] == stroke[1]:
            raise _err(where, ("actuator", "stroke"), shown, "must have L_min < L_max", value=act.stroke)
        stroke = stroke * kl
    margin = DEFAULT_STROKE_MARGIN_M
    if act.stroke_margin is not None:
        if act.stroke_margin < 0:
            raise _err(where, ("actuator", "stroke_margin"), shown, "must be >= 0")
        margin = act.stroke_margin * kl
    lim = cfg.limits
    rmax = _positive(lim.base_radius_max, ("limits", "base_radius_max"), where, shown)
    fmin = _positive(lim.min_frequency_hz, ("limits", "min_frequency_hz"), where, shown)
    cmax = _positive(lim.max_condition, ("limits", "max_condition"), where, shown)
    if cmax is not None and cmax < 1:
        raise _err(where, ("limits", "max_condition"), shown, "must be >= 1 (a condition number)")
    cone = _positive(lim.joint_cone, ("limits", "joint_cone"), where, shown)
    if cone is not None and cone * ka >= np.pi / 2:
        raise _err(where, ("limits", "joint_cone"), shown, "must be below 90 degrees")
    diameter = _positive(lim.leg_diameter, ("limits", "leg_diameter"), where, shown)
    if not cfg.objectives:
        raise _err(where, ("objectives",), shown, "must list at least one objective", value="[]")
    for k, name in enumerate(cfg.objectives):
        if name not in OBJECTIVES:
            w = where.get(("objectives", k))
            raise SynthesisError(
                SynthesisError.OBJECTIVE.format(
                    path=shown, line=w.line if w else "?", k=k + 1, value=name, valid=", ".join(OBJECTIVES)
                )
            )
    if len(set(cfg.objectives)) != len(cfg.objectives):
        raise _err(where, ("objectives",), shown, "lists an objective twice", value=cfg.objectives)
    return Requirements(
        name=cfg.name,
        family=cfg.family,
        variables=tuple(fam.variables),
        lower=np.array(lower),
        upper=np.array(upper),
        box_lo=box[0],
        box_hi=box[1],
        mass=mass,
        com=np.asarray(pay.com, dtype=float) * kl,
        inertia=inertia,
        v_max=rates["velocity"],
        a_max=rates["acceleration"],
        max_force=max_force,
        max_speed=None if max_speed is None else max_speed * kl,
        stroke_ratio=ratio,
        stroke=stroke,
        stiffness=stiffness / kl,
        stroke_margin=margin,
        base_radius_max=None if rmax is None else rmax * kl,
        min_frequency_hz=fmin,
        max_condition=cmax,
        objectives=tuple(cfg.objectives),
        joint_cone=None if cone is None else cone * ka,
        leg_diameter=None if diameter is None else diameter * kl,
        convention=cfg.convention,
        source=shown,
        units=(cfg.length_unit, cfg.angle_unit),
    )


def load_requirements(path) -> Requirements:
    """``Requirements`` from a YAML file; ``SynthesisError``/``YamlError`` with file, line and field."""
    shown = str(path)
    holder = {}

    def keep(cfg, where):
        holder["where"] = where

    cfg = load_yaml_config(path, RequirementsConfig, "requirements", keep)
    return requirements_from_config(cfg, holder["where"], shown)
