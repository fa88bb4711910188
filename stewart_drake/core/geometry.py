"""Platform geometry: the typed ``Platform``, its YAML form, constructors and presets.

Frames (Drake monogram notation): B is the base frame (origin at the base centre, Z up), T the top
(moving plate) frame. ``base_anchors[i]`` is p_BBi, the base joint of leg i in B; ``top_anchors[j]``
is p_TTj, a plate joint in T; leg i joins base anchor i to top anchor ``leg_top[i]``. All lengths are
metres and masses kilograms inside the library; YAML files may use millimetres (``length_unit: mm``).
"""

# The YAML schema dataclasses' field types are read by yamlio (typing.get_type_hints).

import dataclasses
import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from stewart_drake.core.argcheck import as_real_array
from stewart_drake.core.joints import coincident_groups, first_close_pair
from stewart_drake.core.rotations import length_scale
from stewart_drake.core.sanity import check_home
from stewart_drake.core.yamlio import Rule, check_rules, load_yaml_typed
from stewart_drake.errors import ArgumentError, GeometryError, YamlError

SQRT3 = np.sqrt(3.0)
PRESETS = ("utn-kinematic", "utn-dynamic", "gonzalez-dutra-2009")
# the built-in presets' files: a folder of the installed package (a path, not importlib.resources, whose readers
# import zipfile and tempfile at every command's start)
PRESET_FOLDER = Path(__file__).resolve().parent.parent / "presets"
# Two base anchors closer than this are the same point: a modelling error, not a design.
MIN_ANCHOR_SEPARATION = 1e-6


# ----------------------------------------------------------------------------------------------
# YAML schema (edge units), loaded with the safe, bounded yamlio loader.


@dataclass
class UtnDims:
    """The UTN 3-6 family: base hexagon long side ``b``, short side ``d``; top triangle side ``a``."""

    b: float = 0.0
    d: float = 0.0
    a: float = 0.0


@dataclass
class RadialDims:
    """A 6-6 platform with anchors on two circles (z = 0); angles in degrees from the X axis."""

    base_radius: float = 0.0
    base_angles_deg: list[float] = field(default_factory=list)
    top_radius: float = 0.0
    top_angles_deg: list[float] = field(default_factory=list)


@dataclass
class PlateConfig:
    """The moving plate's mass properties. Either ``mass``/``com``/``inertia`` given directly
    (inertia about the centre of mass, in T: Ixx Iyy Izz Ixy Ixz Iyz, kg·m²), or a uniform
    equilateral triangular sheet (UTN family only) from ``thickness`` and ``density``."""

    mass: float = 0.0
    com: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    inertia: list[float] = field(default_factory=lambda: [0.0] * 6)
    thickness: float | None = None
    density: float | None = None


@dataclass(frozen=True)
class LegConfig:
    """Physical legs for the Drake model: a cylinder on a universal joint at the base and a piston
    on a prismatic joint (lengths in the file's unit, masses kg). Frozen; a ``Platform`` holds a checked copy
    whose ``length_offset`` and ``length_gain`` are tuples, in metres."""

    cylinder_length: float = 0.0  # 0: half of the minimum stroke length
    cylinder_radius: float = 0.0  # 0: 1/40 of the minimum stroke length
    cylinder_mass: float = 0.2
    piston_radius: float = 0.0  # 0: 0.6 x cylinder radius
    piston_mass: float = 0.1
    max_force: float = 1000.0  # N, actuator effort limit
    max_speed: float | None = None  # length unit per s, actuator speed limit (None: not checked)
    max_power: float | None = None  # W, actuator mechanical power limit (None: not checked)
    stiffness: float | None = None  # N per length unit, axial stiffness of a leg (None: unknown)
    # per leg: joint-to-joint length = length_gain[i] × sensor reading + length_offset[i] (length unit; empty:
    # gains 1, offsets 0)
    length_offset: list[float] = field(default_factory=list)
    length_gain: list[float] = field(default_factory=list)


@dataclass
class CalibrationRecord:
    """Where a calibrated platform file came from (``stewart-drake calibrate``): the measurement file and
    its SHA-256, the date, the measurement type, the pose count, the measurement residuals' RMS before and
    after (in ``residual_unit``), the validation RMS (m) and each parameter's σ (m, a gain's in 1; 0: fixed),
    named in order."""

    source: str = ""
    sha256: str = ""
    date: str = ""
    measurement_type: str = ""
    poses: int = 0
    residual_rms_before: float = 0.0
    residual_rms_after: float = 0.0
    residual_unit: str = "m"
    validation_rms_m: float | None = None
    parameters: list[str] = field(default_factory=list)
    sigma: list[float] = field(default_factory=list)


@dataclass
class PlatformConfig:
    """One platform as written in YAML. Exactly one anchor description: ``utn``, ``radial`` or
    explicit ``base_anchors`` + ``top_anchors`` + ``leg_top`` (+ ``leg_base`` when legs share base joints)."""

    name: str = ""
    description: str = ""
    length_unit: str = "m"
    utn: UtnDims | None = None
    radial: RadialDims | None = None
    base_anchors: list[list[float]] = field(default_factory=list)
    top_anchors: list[list[float]] = field(default_factory=list)
    leg_top: list[int] = field(default_factory=list)
    leg_base: list[int] = field(default_factory=list)  # empty: leg i at base_anchors[i] (six distinct points)
    stroke: list[float] = field(default_factory=list)
    plate: PlateConfig = field(default_factory=PlateConfig)
    rotation_centre: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    home_height: float | None = None
    legs: LegConfig = field(default_factory=LegConfig)
    plate_below_base_allowed: bool = False
    calibration: CalibrationRecord | None = None


# ----------------------------------------------------------------------------------------------
# The Platform.


@dataclass(frozen=True, eq=False)
class Platform:
    """A Stewart platform, frozen: its arrays are read-only numpy arrays in SI units (views no one can make
    writeable), its ``legs`` a frozen ``LegConfig``. Every construction (a file, ``replace``, the constructors)
    checks the fields as a platform file's are checked (``GeometryError`` naming the field).

    Attributes:
        name: the platform's name, shown in outputs.
        base_anchors: ``(6, 3)`` p_BBi, metres; six distinct points, or three pairs (6-3: two legs per base
            joint).
        top_anchors: ``(k, 3)`` p_TTj, metres, 3 <= k <= 6.
        leg_top: ``(6,)`` index into ``top_anchors`` for each leg.
        stroke: ``(2,)`` L_min, L_max, metres (joint centre to joint centre).
        mass: plate mass, kg.
        com: ``(3,)`` p_TTcm, plate centre of mass in T, metres.
        inertia: ``(3, 3)`` I_Tcm, plate rotational inertia about its centre of mass, in T, kg·m².
        rotation_centre: ``(3,)`` p_TC: the plate point whose position a pose gives (default the T origin).
        home_height: pz of the home pose [0, 0, h, 0, 0, 0], metres.
        legs: the legs' masses, sizes and limits (``LegConfig``, metres).
        description: free text.
        plate_below_base_allowed: poses may put plate anchors at or below the base plane z = 0.
    """

    name: str
    base_anchors: np.ndarray
    top_anchors: np.ndarray
    leg_top: np.ndarray
    stroke: np.ndarray
    mass: float
    com: np.ndarray
    inertia: np.ndarray
    rotation_centre: np.ndarray = field(default_factory=lambda: np.zeros(3))
    home_height: float | None = None
    legs: LegConfig = field(default_factory=LegConfig)
    description: str = ""
    plate_below_base_allowed: bool = False  # poses may put plate anchors at or below z = 0 (sanity.above_base)

    def __post_init__(self):
        _check_kinds(self)
        conv = {
            "base_anchors": (6, 3),
            "top_anchors": None,
            "stroke": (2,),
            "com": (3,),
            "inertia": (3, 3),
            "rotation_centre": (3,),
        }
        for name, shape in conv.items():
            arr = _finite_array(getattr(self, name), name, shape)
            object.__setattr__(self, name, arr)
        top = self.top_anchors
        if top.ndim != 2 or top.shape[1] != 3 or not 3 <= top.shape[0] <= 6:
            raise GeometryError(GeometryError.TOP_SHAPE.format(shape=top.shape))
        leg_top = np.asarray(self.leg_top)
        if leg_top.shape != (6,) or not np.issubdtype(leg_top.dtype, np.integer):
            raise GeometryError(GeometryError.LEG_TOP.format(value=self.leg_top))
        bad = [i + 1 for i, j in enumerate(leg_top) if not 0 <= j < top.shape[0]]
        if bad:
            raise GeometryError(
                GeometryError.LEG_TOP_RANGE.format(
                    leg=bad[0], anchor=leg_top[bad[0] - 1], n=top.shape[0], last=top.shape[0] - 1
                )
            )
        unused = sorted(set(range(top.shape[0])) - set(leg_top.tolist()))
        if unused:
            raise GeometryError(GeometryError.LEG_TOP_UNUSED.format(anchor=unused[0]))
        object.__setattr__(self, "leg_top", _read_only(leg_top.astype(np.intp)))
        check_base_anchors(self.base_anchors)
        _check_distinct(top, "top anchors")
        lmin, lmax = self.stroke
        if not 0 < lmin < lmax:
            raise GeometryError(GeometryError.STROKE.format(lmin=lmin, lmax=lmax))
        object.__setattr__(self, "legs", _checked_legs(self.legs))
        self.length_offset  # noqa: B018 -- validates legs.length_offset: six finite numbers (or none)
        self.length_gain  # noqa: B018 -- validates legs.length_gain: six positive numbers (or none)
        if not np.isfinite(self.mass) or self.mass < 0:
            raise GeometryError(GeometryError.MASS.format(value=self.mass))
        if not np.allclose(self.inertia, self.inertia.T, atol=1e-12):
            raise GeometryError(GeometryError.INERTIA_SYMMETRIC.format(value=self.inertia.tolist()))
        if self.mass > 0:
            eig = np.linalg.eigvalsh(self.inertia)
            tol = 1e-9 * max(1.0, eig.max())
            if eig.min() < -tol or any(eig[i] + eig[j] < eig[k] - tol for i, j, k in [(0, 1, 2), (0, 2, 1), (1, 2, 0)]):
                raise GeometryError(GeometryError.INERTIA_PHYSICAL.format(moments=eig.tolist()))
        if self.home_height is None:
            object.__setattr__(self, "home_height", _mid_stroke_height(self))
        elif not np.isfinite(self.home_height) or self.home_height <= 0:
            raise GeometryError(GeometryError.HOME_HEIGHT.format(value=self.home_height))

    # -- derived quantities -------------------------------------------------------------------
    @property
    def top_anchors_per_leg(self) -> np.ndarray:
        """``(6, 3)`` p_TTi: the plate anchor of each leg, in T (metres)."""
        return self.top_anchors[self.leg_top]

    @property
    def length_offset(self) -> np.ndarray:
        """``(6,)`` o_i, metres: each leg's joint-to-joint length is its sensor reading + o_i
        (``legs.length_offset``; zeros when the file gives none)."""
        o = np.zeros(6) if not self.legs.length_offset else np.asarray(self.legs.length_offset, dtype=float)
        if o.shape != (6,) or not np.all(np.isfinite(o)):
            raise GeometryError(GeometryError.SHAPE.format(name="legs.length_offset", shape=(6,), got=o.shape))
        return o

    @property
    def length_gain(self) -> np.ndarray:
        """``(6,)`` g_i: each leg's joint-to-joint length is g_i × its sensor reading + o_i (``legs.length_gain``;
        ones when the file gives none)."""
        g = np.ones(6) if not self.legs.length_gain else np.asarray(self.legs.length_gain, dtype=float)
        if g.shape != (6,) or not np.all(np.isfinite(g) & (g > 0)):
            raise GeometryError(GeometryError.SHAPE.format(name="legs.length_gain (positive)", shape=(6,), got=g))
        return g

    @property
    def has_sensor_gains(self) -> bool:
        """True when some ``legs.length_gain`` differs from 1."""
        return bool(np.any(self.length_gain != 1.0))

    def readings(self, lengths) -> np.ndarray:
        """``(..., 6)`` sensor readings (m) of joint-to-joint ``lengths`` (m): (L − o) / g."""
        return (np.asarray(lengths, dtype=float) - self.length_offset) / self.length_gain

    def lengths_from_readings(self, readings) -> np.ndarray:
        """``(..., 6)`` joint-to-joint lengths (m) of sensor ``readings`` (m): g r + o."""
        return np.asarray(readings, dtype=float) * self.length_gain + self.length_offset

    @property
    def L_min(self) -> float:
        """The shortest leg length, m (``stroke[0]``)."""
        return float(self.stroke[0])

    @property
    def L_max(self) -> float:
        """The longest leg length, m (``stroke[1]``)."""
        return float(self.stroke[1])

    def home_pose(self) -> np.ndarray:
        """``(6,)`` the home pose [0, 0, home_height, 0, 0, 0] (metres, radians)."""
        return np.array([0.0, 0.0, self.home_height, 0.0, 0.0, 0.0])

    def replace(self, **changes) -> "Platform":
        """A copy with some fields changed (validated again)."""
        return dataclasses.replace(self, **changes)

    def to_yaml(self, path: "str | Path", overwrite: bool = False) -> Path:
        """Write this platform as a platform file (explicit anchors, metres) that ``load_platform`` reads back
        to the same platform.

        Args:
            path: the file to write.
            overwrite: replace an existing file (default: refuse).

        Returns:
            The path written.
        """
        # deferred: the writer imports this module (the Platform type)
        from stewart_drake.core.platform_file import write_platform_yaml

        return write_platform_yaml(self, path, overwrite)

    # -- constructors --------------------------------------------------------------------------
    @classmethod
    def from_anchors(
        cls,
        base_anchors: "ArrayLike",
        top_anchors_per_leg: "ArrayLike",
        stroke: "ArrayLike",
        name: str = "custom",
        **kwargs: object,
    ) -> "Platform":
        """A platform from explicit anchors: each leg's base anchor in B and plate anchor in T.

        Args:
            base_anchors: ``(6, 3)`` metres.
            top_anchors_per_leg: ``(6, 3)`` metres (legs sharing a plate point share its anchor).
            stroke: ``(2,)`` L_min, L_max, metres.
            name: the platform's name.
            **kwargs: the other fields (``mass``, ``com``, ``inertia``, ``home_height``, ``legs``, ...).

        Returns:
            The validated platform (a massless plate unless ``mass``, ``com``, ``inertia`` are given).
        """
        # deferred: the constructor's module imports this one (the Platform type)
        from stewart_drake.core.platform_file import platform_from_anchors

        return platform_from_anchors(base_anchors, top_anchors_per_leg, stroke, name, **kwargs)

    @classmethod
    def utn(cls, b: float, d: float, a: float, **kwargs) -> "Platform":
        """The UTN 3-6 platform: hexagon sides ``b`` (long), ``d`` (short); triangle side ``a``.

        Lengths in metres. Legs 1,2 end at T1; 3,4 at T2; 5,6 at T3.
        """
        base, top = utn_anchors(b, d, a)
        return cls(base_anchors=base, top_anchors=top, leg_top=np.array([0, 0, 1, 1, 2, 2]), **kwargs)

    @classmethod
    def radial(cls, base_radius, base_angles, top_radius, top_angles, **kwargs) -> "Platform":
        """A 6-6 platform with anchors on circles (z = 0); angles in radians; leg i joins base i to top i."""
        return cls(
            base_anchors=_circle_points(base_radius, base_angles, "base"),
            top_anchors=_circle_points(top_radius, top_angles, "top"),
            leg_top=np.arange(6),
            **kwargs,
        )


def utn_anchors(b: float, d: float, a: float) -> tuple[np.ndarray, np.ndarray]:
    """The UTN 3-6 anchors: ``(6, 3)`` base anchors and ``(3, 3)`` top anchors, same unit as b, d, a."""
    for name, value in (("b", b), ("d", d), ("a", a)):
        value = _number(value, name)
        if not np.isfinite(value) or value <= 0:
            raise GeometryError(GeometryError.UTN_DIMENSION.format(name=name, value=value))
    b, d, a = (_number(v, n) for v, n in ((b, "b"), (d, "d"), (a, "a")))
    s = SQRT3 / 6
    base = np.array(
        [
            [s * (2 * b + d), d / 2, 0],
            [-s * (b - d), (b + d) / 2, 0],
            [-s * (b + 2 * d), b / 2, 0],
            [-s * (b + 2 * d), -b / 2, 0],
            [-s * (b - d), -(b + d) / 2, 0],
            [s * (2 * b + d), -d / 2, 0],
        ]
    )
    top = np.array([[s * a, a / 2, 0], [-SQRT3 / 3 * a, 0, 0], [s * a, -a / 2, 0]])
    return base, top


def triangular_plate(side: float, thickness: float, density: float) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass properties of a uniform equilateral-triangle sheet occupying 0 <= z <= thickness, centred
    on the T origin (the triangle's centroid): ``(mass kg, com (3,) m, inertia about com (3, 3) kg·m²)``.

    Closed form: an equilateral lamina of side a has I_xx = I_yy = m a²/24 and I_zz = m a²/12 about its
    centroid; the thickness adds m t²/12 to the in-plane axes.
    """
    area = SQRT3 / 4 * side**2
    m = density * area * thickness
    Ixx = m * side**2 / 24 + m * thickness**2 / 12
    return m, np.array([0.0, 0.0, thickness / 2]), np.diag([Ixx, Ixx, m * side**2 / 12])


def _circle_points(radius, angles, what) -> np.ndarray:
    angles = _real_array(angles, f"{what}_angles")
    if angles.shape != (6,):
        raise GeometryError(GeometryError.CIRCLE_ANGLES.format(what=what, shape=angles.shape))
    radius = _number(radius, f"{what}_radius")
    if not np.isfinite(radius) or radius <= 0:
        raise GeometryError(GeometryError.CIRCLE_RADIUS.format(what=what, value=radius))
    return np.stack([radius * np.cos(angles), radius * np.sin(angles), np.zeros(6)], -1)


def _real_array(value, name) -> np.ndarray:
    """``value`` as a new float array; ``GeometryError`` for what is not real numbers (text, None, complex)."""
    try:
        return np.array(as_real_array(value, name), dtype=float)
    except ArgumentError:
        raise GeometryError(GeometryError.NOT_NUMBERS.format(name=name, value=value)) from None


def _number(value, name) -> float:
    """One real number (not checked for being finite); ``GeometryError`` naming ``name`` otherwise."""
    arr = _real_array(value, name)
    if arr.shape != () or isinstance(value, (bool, np.bool_)):
        raise GeometryError(GeometryError.NOT_NUMBERS.format(name=name, value=value))
    return float(arr)


def _read_only(arr: np.ndarray) -> np.ndarray:
    """A view of ``arr`` that no one can make writeable again (its base is read-only)."""
    arr.flags.writeable = False
    view = arr.view()
    view.flags.writeable = False
    return view


def _finite_array(value, name, shape) -> np.ndarray:
    arr = _real_array(value, name)
    if shape is not None and arr.shape != shape:
        raise GeometryError(GeometryError.SHAPE.format(name=name, shape=shape, got=arr.shape))
    if not np.all(np.isfinite(arr)):
        raise GeometryError(GeometryError.NOT_FINITE.format(name=name, value=arr.tolist()))
    return _read_only(arr)


# legs.<field>: (sign, largest magnitude in SI): the platform file's rules (PLATFORM_RULES) for a Platform built
# in code. Length-valued fields are bounded by their file rule's metres only through the file; a leg mass may be
# 0 in code (massless legs: the seed's rigid-body model), never negative.
_LEG_RULES = {
    "cylinder_length": ("nonneg", math.inf),
    "cylinder_radius": ("nonneg", math.inf),
    "piston_radius": ("nonneg", math.inf),
    "cylinder_mass": ("nonneg", 1e4),
    "piston_mass": ("nonneg", 1e4),
    "max_force": ("pos", 1e8),
    "max_speed": ("pos", math.inf),
    "max_power": ("pos", 1e9),
    "stiffness": ("pos", math.inf),
}


def _check_kinds(p: "Platform") -> None:
    """The non-array fields of a ``Platform`` are of their types (``GeometryError`` naming the field)."""
    kinds = (
        ("name", str, "text"),
        ("description", str, "text"),
        ("plate_below_base_allowed", (bool, np.bool_), "a bool"),
    )
    for name, kind, shown in kinds:
        if not isinstance(getattr(p, name), kind):
            raise GeometryError(GeometryError.FIELD_KIND.format(name=name, kind=shown, value=getattr(p, name)))
    object.__setattr__(p, "plate_below_base_allowed", bool(p.plate_below_base_allowed))
    if not isinstance(p.legs, LegConfig):
        raise GeometryError(GeometryError.FIELD_KIND.format(name="legs", kind="a LegConfig", value=p.legs))
    object.__setattr__(p, "mass", _number(p.mass, "mass"))
    if p.home_height is not None:
        object.__setattr__(p, "home_height", _number(p.home_height, "home_height"))


def _checked_legs(legs: LegConfig) -> LegConfig:
    """``legs`` checked as a platform file's ``legs:`` block is (finite numbers, signs, magnitudes), with its
    per-leg lists as tuples."""
    values = {}
    for name, (sign, largest) in _LEG_RULES.items():
        v = getattr(legs, name)
        if v is None and name in ("max_speed", "max_power", "stiffness"):
            continue
        v = _number(v, f"legs.{name}")
        ok = math.isfinite(v) and (v > 0 if sign == "pos" else v >= 0) and abs(v) <= largest
        if not ok:
            rule = ("a positive number" if sign == "pos" else "a number >= 0") + (
                f" up to {largest:g}" if math.isfinite(largest) else ""
            )
            raise GeometryError(GeometryError.LEG_FIELD.format(name=name, rule=rule, value=v))
        values[name] = v
    for name in ("length_offset", "length_gain"):
        values[name] = tuple(float(x) for x in _real_array(getattr(legs, name), f"legs.{name}").reshape(-1))
    return dataclasses.replace(legs, **values)


def _check_distinct(points: np.ndarray, what: str) -> None:
    pair = first_close_pair(points, MIN_ANCHOR_SEPARATION)
    if pair is not None:
        i, j = pair
        raise GeometryError(
            GeometryError.COINCIDE.format(
                what=what, i=i + 1, j=j + 1, at=points[i].tolist(), limit=MIN_ANCHOR_SEPARATION
            )
        )


def _mid_stroke_height(p: Platform) -> float:
    """pz at which the mean leg length of the zero-orientation pose is mid-stroke."""
    target = p.stroke.mean()
    d_xy = p.top_anchors_per_leg[:, :2] - p.rotation_centre[:2] - p.base_anchors[:, :2]
    d_z = p.top_anchors_per_leg[:, 2] - p.rotation_centre[2] - p.base_anchors[:, 2]
    r2 = np.sum(d_xy**2, axis=1)
    if np.any(r2 >= target**2):
        raise GeometryError(GeometryError.TOO_WIDE.format(span=np.sqrt(r2.max()), target=target))
    return float(np.mean(np.sqrt(target**2 - r2) - d_z))


# ----------------------------------------------------------------------------------------------
# YAML and presets.


def platform_from_config(cfg: PlatformConfig) -> Platform:
    """Build a validated ``Platform`` (SI units) from a parsed YAML ``PlatformConfig``."""
    try:
        k = length_scale(cfg.length_unit)
    except ValueError as e:
        raise GeometryError(GeometryError.LENGTH_UNIT.format(problem=e)) from None
    given = [n for n, v in (("utn", cfg.utn), ("radial", cfg.radial), ("base_anchors", cfg.base_anchors or None)) if v]
    if len(given) != 1:
        raise GeometryError(GeometryError.ANCHOR_DESCRIPTIONS.format(name=cfg.name, given=given or "none"))
    plate = cfg.plate
    if plate.thickness is not None or plate.density is not None:
        if cfg.utn is None or plate.thickness is None or plate.density is None:
            raise GeometryError(GeometryError.PLATE_SHEET.format(name=cfg.name))
        mass, com, inertia = triangular_plate(cfg.utn.a * k, plate.thickness * k, plate.density)
    else:
        if len(plate.inertia) != 6:
            raise GeometryError(GeometryError.INERTIA_NUMBERS.format(value=plate.inertia))
        ixx, iyy, izz, ixy, ixz, iyz = plate.inertia
        mass, com = plate.mass, np.asarray(plate.com, dtype=float) * k
        inertia = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]], dtype=float) * k**2
    if len(cfg.stroke) != 2:
        raise GeometryError(GeometryError.STROKE_PAIR.format(value=cfg.stroke))
    legs = dataclasses.replace(
        cfg.legs,
        cylinder_length=cfg.legs.cylinder_length * k,
        cylinder_radius=cfg.legs.cylinder_radius * k,
        piston_radius=cfg.legs.piston_radius * k,
        max_speed=None if cfg.legs.max_speed is None else cfg.legs.max_speed * k,
        stiffness=None if cfg.legs.stiffness is None else cfg.legs.stiffness / k,
        length_offset=[v * k for v in cfg.legs.length_offset],
    )
    common = dict(
        name=cfg.name,
        description=cfg.description,
        stroke=np.asarray(cfg.stroke, dtype=float) * k,
        mass=mass,
        com=com,
        inertia=inertia,
        rotation_centre=np.asarray(cfg.rotation_centre, dtype=float) * k,
        home_height=None if cfg.home_height is None else cfg.home_height * k,
        legs=legs,
        plate_below_base_allowed=bool(cfg.plate_below_base_allowed),
    )
    if cfg.utn is not None:
        return Platform.utn(cfg.utn.b * k, cfg.utn.d * k, cfg.utn.a * k, **common)
    if cfg.radial is not None:
        r = cfg.radial
        return Platform.radial(
            r.base_radius * k, np.radians(r.base_angles_deg), r.top_radius * k, np.radians(r.top_angles_deg), **common
        )
    return Platform(
        base_anchors=base_anchors_per_leg(cfg) * k,
        top_anchors=np.asarray(cfg.top_anchors, dtype=float) * k,
        leg_top=np.asarray(cfg.leg_top),
        **common,
    )


# Field rules of a platform file (yamlio.Rule): sign, unit and largest magnitude; list sizes.
PLATFORM_RULES = {
    **{f"utn.{k}": Rule("pos", "length") for k in "bda"},
    "radial.base_radius": Rule("pos", "length"),
    "radial.top_radius": Rule("pos", "length"),
    "radial.base_angles_deg[*]": Rule("any", "deg", 1e4),
    "radial.top_angles_deg[*]": Rule("any", "deg", 1e4),
    "base_anchors[*][*]": Rule("any", "length"),
    "top_anchors[*][*]": Rule("any", "length"),
    "leg_top[*]": Rule("nonneg", "", 5),
    "leg_base[*]": Rule("nonneg", "", 5),
    "stroke[*]": Rule("pos", "length"),
    "plate.mass": Rule("nonneg", "kg", 1e5),
    "plate.com[*]": Rule("any", "length"),
    "plate.inertia[*]": Rule("any", "kg·m² (file unit)", 1e12),
    "plate.thickness": Rule("pos", "length"),
    "plate.density": Rule("pos", "kg/m³", 1e5),
    "rotation_centre[*]": Rule("any", "length"),
    "home_height": Rule("pos", "length"),
    "legs.cylinder_length": Rule("nonneg", "length"),
    "legs.cylinder_radius": Rule("nonneg", "length"),
    "legs.piston_radius": Rule("nonneg", "length"),
    "legs.cylinder_mass": Rule("pos", "kg", 1e4),
    "legs.piston_mass": Rule("pos", "kg", 1e4),
    "legs.max_force": Rule("pos", "N", 1e8),
    "legs.max_speed": Rule("pos", "length"),
    "legs.max_power": Rule("pos", "W", 1e9),
    "legs.stiffness": Rule("pos", "N per length unit", 1e15),
    "legs.length_offset[*]": Rule("any", "length"),
    "legs.length_gain[*]": Rule("pos", "", 10.0),
}
PLATFORM_SHAPES = {
    "radial.base_angles_deg": (6, 6),
    "radial.top_angles_deg": (6, 6),
    "base_anchors": (3, 6),
    "base_anchors[*]": (3, 3),
    "top_anchors": (3, 6),
    "top_anchors[*]": (3, 3),
    "leg_top": (6, 6),
    "leg_base": (6, 6),
    "stroke": (2, 2),
    "plate.com": (3, 3),
    "plate.inertia": (6, 6),
    "rotation_centre": (3, 3),
    "legs.length_offset": (6, 6),
    "legs.length_gain": (6, 6),
}
MAX_NAME_CHARS = 200


def check_name(cfg, where: dict, shown: str) -> None:
    """``name``/``description``: printable text (no control characters), ``name`` at most
    ``MAX_NAME_CHARS`` long; it is used in file names and XML only through safe derivations."""
    for key, limit in (("name", MAX_NAME_CHARS), ("description", 2000)):
        text = getattr(cfg, key)
        w = where.get((key,))
        line = w.line if w else "?"
        if len(text) > limit:
            raise YamlError(
                YamlError.BAD_VALUE.format(
                    path=shown,
                    line=line,
                    field=key,
                    value=f"({len(text)} characters)",
                    problem=f"is longer than {limit} characters",
                )
            )
        bad = next((c for c in text if not c.isprintable()), None)
        if bad is not None:
            raise YamlError(
                YamlError.BAD_VALUE.format(
                    path=shown,
                    line=line,
                    field=key,
                    value=repr(text[:60]),
                    problem=f"contains the control character {bad!r}",
                )
            )


def check_length_unit(cfg, where: dict, shown: str) -> float:
    """The metres per file unit of ``length_unit`` (m or mm)."""
    if cfg.length_unit not in ("m", "mm"):
        w = where.get(("length_unit",))
        raise YamlError(YamlError.UNIT.format(path=shown, line=w.line if w else "?", value=cfg.length_unit))
    return length_scale(cfg.length_unit)


def check_base_anchors(points: np.ndarray) -> None:
    """``(6, 3)`` per-leg base anchors p_BBi: six distinct points, or exactly three disjoint coincident
    pairs (a 6-3 platform: three base joints, each shared by two legs). Any other coincidence (one or
    two pairs, three legs on one point) is refused as a modelling error, naming the first pair."""
    if np.all(np.bincount(coincident_groups(points, MIN_ANCHOR_SEPARATION)[1]) == 2):  # three separate pairs
        return
    try:
        _check_distinct(points, "base anchors")
    except GeometryError as e:
        raise GeometryError(GeometryError.BASE_PAIRS.format(problem=e)) from None


def base_joints(platform: Platform) -> tuple[np.ndarray, np.ndarray]:
    """The platform's physical base joints: ``(first (m,), leg_joint (6,))``, the leg that first stands on
    each joint and each leg's joint (0..m-1, numbered in leg order). Legs whose base anchors coincide
    (closer than ``MIN_ANCHOR_SEPARATION``, the rule ``check_base_anchors`` accepts 6-3 pairs by) share one
    joint: m = 3 on a 6-3 platform, 6 (``first`` = ``leg_joint`` = 0..5) when the six anchors are distinct."""
    return coincident_groups(platform.base_anchors, MIN_ANCHOR_SEPARATION)


def base_anchors_per_leg(cfg: PlatformConfig) -> np.ndarray:
    """``(6, 3)`` the base anchor of each leg (file unit) of an explicit-anchor config: ``base_anchors``
    itself, or ``base_anchors[leg_base]`` when ``leg_base`` lists each leg's base joint."""
    pts = np.asarray(cfg.base_anchors, dtype=float).reshape(-1, 3)
    if not cfg.leg_base:
        if len(pts) != 6:
            raise GeometryError(GeometryError.BASE_COUNT.format(n=len(pts)))
        return pts
    idx = np.asarray(cfg.leg_base)
    bad = [i for i, j in enumerate(idx) if not 0 <= j < len(pts)]
    if bad:
        raise GeometryError(
            GeometryError.LEG_BASE_RANGE.format(leg=bad[0] + 1, anchor=idx[bad[0]], n=len(pts), last=len(pts) - 1)
        )
    unused = sorted(set(range(len(pts))) - set(idx.tolist()))
    if unused:
        raise GeometryError(GeometryError.LEG_BASE_UNUSED.format(anchor=unused[0]))
    return pts[idx]


def check_shared_base(cfg: PlatformConfig, where: dict, shown: str, k: float) -> None:
    """The points listed in ``base_anchors`` are distinct (a repeated point is a typing mistake: legs
    sharing a base joint list it once and name it in ``leg_base``); ``k`` metres per file unit."""
    pts = np.asarray(cfg.base_anchors, dtype=float).reshape(-1, 3) * k
    pair = first_close_pair(pts, MIN_ANCHOR_SEPARATION)
    if pair is not None:
        a, b = pair
        w = where.get(("base_anchors", b, 0))
        raise YamlError(
            YamlError.BAD_VALUE.format(
                path=shown,
                line=w.line if w else "?",
                field=f"base_anchors item {b + 1}",
                value=cfg.base_anchors[b],
                problem=GeometryError.BASE_REPEATED.format(first=a + 1, limit=MIN_ANCHOR_SEPARATION),
            )
        )


def check_platform_fields(shown: str):
    """The checks of a platform's fields in a file ``shown`` (name, length unit, each field's rule, shared base
    joints), as a ``check(cfg, where)`` for the typed YAML loaders."""

    def check(cfg, where):
        check_name(cfg, where, shown)
        k = check_length_unit(cfg, where, shown)
        check_rules(where, PLATFORM_RULES, PLATFORM_SHAPES, cfg, shown, k, cfg.length_unit)
        check_shared_base(cfg, where, shown, k)

    return check


def load_yaml_config(path, schema, kind: str, check=None):
    """Parse a YAML file into the dataclass ``schema`` with the safe, bounded loader
    (``yamlio.load_yaml_typed``); errors name the file, line and field (``kind`` says what the file
    should hold). A config with an empty ``name`` takes the file's stem."""
    cfg = load_yaml_typed(path, schema, kind, check)
    if not cfg.name:
        cfg.name = Path(path).stem
    return cfg


def load_platform_yaml(path) -> Platform:
    """Load one platform from a YAML file (schema: ``PlatformConfig``); every field is checked
    (type, finite, sign, magnitude, list sizes) with the file's line numbers before it is used."""
    cfg = load_yaml_config(path, PlatformConfig, "platform", check_platform_fields(str(path)))
    return platform_from_file_config(cfg, path)


def platform_from_file_config(cfg: PlatformConfig, shown) -> Platform:
    """The ``Platform`` of a checked ``cfg`` read from ``shown`` (a file): a geometry error names the file, and a
    platform singular at its home pose is refused (``check_home``)."""
    try:
        platform = platform_from_config(cfg)
    except GeometryError as e:
        raise GeometryError(GeometryError.IN_FILE.format(path=shown, problem=e)) from None
    check_home(platform)
    return platform


def preset_path(name: str) -> Path:
    """The YAML file of a built-in preset."""
    if name not in PRESETS:
        raise GeometryError(GeometryError.UNKNOWN_PRESET.format(name=name, presets=", ".join(PRESETS)))
    return PRESET_FOLDER / f"{name}.yaml"


def load_preset(name: str) -> Platform:
    """One of the built-in presets (``PRESETS``)."""
    return load_platform_yaml(preset_path(name))


def check_platform(value, name: str = "platform") -> Platform:
    """``value`` when it is a ``Platform``; ``ArgumentError`` naming ``name`` otherwise (a preset name or a file
    is loaded by ``load_platform``, not here)."""
    if not isinstance(value, Platform):
        shown = repr(value)
        raise ArgumentError(
            ArgumentError.NOT_PLATFORM.format(name=name, value=shown if len(shown) <= 80 else shown[:77] + "...")
        )
    return value


def load_platform(name_or_path) -> Platform:
    """A preset name or a path to a YAML file."""
    if isinstance(name_or_path, Platform):
        return name_or_path
    if not isinstance(name_or_path, (str, os.PathLike)):
        check_platform(name_or_path, "name_or_path")
    s = os.fspath(name_or_path)
    if not isinstance(s, str) or "\0" in s:
        raise GeometryError(GeometryError.UNKNOWN_PLATFORM.format(name=repr(s), presets=", ".join(PRESETS)))
    if s in PRESETS:
        return load_preset(s)
    if s.endswith((".yaml", ".yml")) or Path(s).exists():
        return load_platform_yaml(s)
    raise GeometryError(GeometryError.UNKNOWN_PLATFORM.format(name=s, presets=", ".join(PRESETS)))
