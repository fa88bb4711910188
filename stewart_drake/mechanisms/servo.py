"""RC-servo (rotary, 6-RSS) hexapod of seed 002: arm angles and PWM pulse widths (plain numpy).

Each leg i is a servo whose arm (length ``a``, the seed also writes it ``l_i``) turns about a horizontal
shaft at the base pivot ``b_i`` (p_BBi, z = 0), and a rod of length ``s`` joins the arm tip A_i to the
platform anchor ``p_i`` (p_PPi, in the platform frame P). The arm turns in the vertical plane that makes
the angle ``beta_i`` with the base x axis; ``alpha_i`` is the arm's elevation from the horizontal, so

    p_BAi = b_i + a [cos(alpha) cos(beta), cos(alpha) sin(beta), sin(alpha)]        (seed eqs. 4-6)

(the seed prints y_a with sin(alpha) cos(beta): a typo, the derivation uses cos(alpha) sin(beta)).
Odd and even arms of a pair point away from each other (their ``beta`` differ by pi); with ``beta``
chosen per arm the one equation serves both, as the seed shows.

Pose: ``(..., 6)`` ``[x, y, z, phi, theta, psi]`` in metres and radians, the platform origin T and
R = Rz(psi)·Ry(theta)·Rx(phi) (seed 002's yaw-pitch-roll, ``rotations`` convention ``zyx``).

Equations implemented (seed numbering):
- (9)  alpha = asin(L / sqrt(M² + N²)) - atan(N / M), L = |l|² - (s² - a²), M = 2a(z_q - z_b),
       N = 2a[cos(beta)(x_q - x_b) + sin(beta)(y_q - y_b)], q = T + R p the anchor in the base frame.
       We use atan2(N, M) (the same for M > 0, right in every quadrant).
- (10) h0 = sqrt(s² + a² - (x_p - x_b)² - (y_p - y_b)²) - z_p   (arm and rod at right angles at home).
- (12) alpha0: eq. (9) at the home pose. The seed's eq. (12) names the two terms the other way round
       (its M0 is our N, its N0 our M) and writes atan(M0/N0): the same value.
- (13, 14) W_i = W0_i ± (alpha_i - alpha0) r: "+" for even i, "-" for odd i. The sign is the servo
       mounting: increasing the pulse turns a servo clockwise seen from its horn; two identical servos
       whose arms point away from each other therefore move their arms oppositely. Here the sign is
       derived from each servo's shaft direction (``pulse_signs``) and the preset reproduces the seed's
       odd/even rule (a test checks it).
- r = 400 µs / 45° (≈ 8.89 µs/degree, 509.3 µs/rad; the seed's "1/90 µs/radian" is garbled), travel
  ±45° about the home angle, neutral pulse W0 = 1500 µs adjustable per servo (assembly trims).

Unreachable poses (|L / sqrt(M² + N²)| > 1: the rod cannot reach the anchor) and travel violations are
flagged per servo and never produce NaN: the angle is then the nearest one (arm pointing at / away from
the anchor) and the commanded pulse is clamped to the servo's travel.
"""

# The config dataclasses' field types are read by yamlio (typing.get_type_hints).

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from stewart_drake.core.argcheck import first_index
from stewart_drake.core.geometry import PRESET_FOLDER, check_name, load_yaml_config
from stewart_drake.core.rotations import length_scale, rotation_matrix, wrap_angle
from stewart_drake.errors import SERVO_RESOLUTION, GeometryError, ServoPoseError, StewartError, counted

NEUTRAL_US = 1500.0
RATE_US_PER_RAD = 400.0 / np.radians(45.0)  # 509.295... µs/rad = 8.888... µs/degree
TRAVEL_RAD = np.radians(45.0)
FRAME_RATE_HZ = 50.0
# Typical standard hobby servo (MG996R class at 6 V): no-load speed 0.17 s per 60°, stall torque ~1 N·m.
SERVO_SPEED_RAD_S = np.radians(60.0) / 0.17  # 6.16 rad/s
SERVO_STALL_TORQUE = 1.0
# A digital servo's position loop reaches full torque a couple of degrees from its target.
SERVO_BAND_RAD = np.radians(2.0)
# Home heights of the six legs must agree (the seed: "by symmetry eq. 10 gives the same for every leg").
H0_AGREEMENT_M = 1e-9


@dataclass(frozen=True, eq=False)
class ServoHexapod:
    """An RC-servo hexapod. Arrays are read-only, SI units.

    base_pivots       (6, 3)  p_BBi, the arm pivot (shaft axis ∩ arm plane) in the base frame, m (z = 0)
    arm_directions    (6,)    beta_i, the arm plane's angle from the base x axis, rad
    platform_anchors  (6, 3)  p_PPi, rod ends on the platform, in the platform frame P, m
    arm_length        a, m (pivot to rod joint)
    rod_length        s, m (ball joint to ball joint)
    shaft_directions  (6, 3)  unit vector along each servo shaft pointing out of the servo body towards
                      its horn (perpendicular to the arm plane); an increasing pulse turns the horn
                      clockwise seen from the horn side, i.e. about ``-shaft``
    neutral_us        (6,)    W0_i, the pulse that holds servo i at home (µs), trims included
    rate_us_per_rad   r
    travel_rad        allowed |alpha - alpha0|
    """

    name: str
    base_pivots: np.ndarray
    arm_directions: np.ndarray
    platform_anchors: np.ndarray
    arm_length: float
    rod_length: float
    shaft_directions: np.ndarray
    neutral_us: np.ndarray = field(default_factory=lambda: np.full(6, NEUTRAL_US))
    rate_us_per_rad: float = RATE_US_PER_RAD
    travel_rad: float = TRAVEL_RAD
    description: str = ""
    # Physical data for the Drake model only (kg, N·m, rad/s, rad): see servo_model.servo_gains.
    arm_mass: float = 0.005
    rod_mass: float = 0.005
    platform_mass: float = 0.15
    servo_torque: float = SERVO_STALL_TORQUE  # stall torque
    servo_speed: float = SERVO_SPEED_RAD_S  # no-load speed
    servo_band: float = SERVO_BAND_RAD  # position error at which the servo gives its stall torque

    def __post_init__(self):
        shapes = {
            "base_pivots": (6, 3),
            "arm_directions": (6,),
            "platform_anchors": (6, 3),
            "shaft_directions": (6, 3),
            "neutral_us": (6,),
        }
        for name, shape in shapes.items():
            arr = np.array(getattr(self, name), dtype=float)
            if arr.shape != shape:
                raise GeometryError(GeometryError.SERVO_SHAPE.format(name=name, shape=shape, got=arr.shape))
            if not np.all(np.isfinite(arr)):
                raise GeometryError(GeometryError.SERVO_NOT_FINITE.format(name=name, value=arr.tolist()))
            arr.flags.writeable = False
            object.__setattr__(self, name, arr)
        for name in (
            "arm_length",
            "rod_length",
            "rate_us_per_rad",
            "travel_rad",
            "arm_mass",
            "rod_mass",
            "platform_mass",
            "servo_torque",
            "servo_speed",
            "servo_band",
        ):
            v = getattr(self, name)
            if not np.isfinite(v) or v <= 0:
                raise GeometryError(GeometryError.SERVO_NOT_POSITIVE.format(name=name, value=v))
        if self.rod_length <= self.arm_length:
            raise GeometryError(GeometryError.SERVO_ROD.format(s=self.rod_length, a=self.arm_length))
        n = np.linalg.norm(self.shaft_directions, axis=1)
        k = self.alpha_axes
        for i in range(6):
            if abs(abs(self.shaft_directions[i] @ k[i]) - n[i]) > 1e-9 * max(n[i], 1.0) or n[i] == 0:
                raise GeometryError(
                    GeometryError.SERVO_SHAFT.format(
                        servo=i + 1, shaft=self.shaft_directions[i].tolist(), beta=np.degrees(self.arm_directions[i])
                    )
                )
        object.__setattr__(self, "shaft_directions", _readonly(self.shaft_directions / n[:, None]))
        h = home_heights(self)
        if np.any(~np.isfinite(h)):
            i = int(np.argmax(~np.isfinite(h)))
            raise GeometryError(GeometryError.SERVO_NO_H0.format(servo=i + 1))
        if np.ptp(h) > H0_AGREEMENT_M:
            raise GeometryError(GeometryError.SERVO_ASYMMETRIC.format(h_mm=np.round(h * 1e3, 6).tolist()))

    @property
    def alpha_axes(self) -> np.ndarray:
        """``(6, 3)`` the axis about which a positive change of alpha_i turns arm i (right-hand rule)."""
        b = self.arm_directions
        return np.stack([np.sin(b), -np.cos(b), np.zeros(6)], axis=-1)

    @property
    def pulse_signs(self) -> np.ndarray:
        """``(6,)`` +1 where an increasing pulse raises the arm (alpha grows), -1 where it lowers it."""
        return np.sign(np.einsum("ij,ij->i", self.alpha_axes, -self.shaft_directions))

    @property
    def home_height(self) -> float:
        """h0 (eq. 10), metres: the platform origin's height at home."""
        return float(np.mean(home_heights(self)))

    @property
    def home_angles(self) -> np.ndarray:
        """``(6,)`` alpha0_i (eq. 12), radians."""
        return home_arm_angles(self)

    def home_pose(self) -> np.ndarray:
        """``(6,)`` [0, 0, h0, 0, 0, 0]."""
        return np.array([0.0, 0.0, self.home_height, 0.0, 0.0, 0.0])

    def replace(self, **changes) -> "ServoHexapod":
        """A copy with some fields changed (validated again), e.g. ``neutral_us`` trims."""
        return dataclasses.replace(self, **changes)


def _readonly(a):
    a = np.array(a, dtype=float)
    a.flags.writeable = False
    return a


def hobby_servo_hexapod(
    base_radius: float = 0.060,
    pair_spacing: float = 0.050,
    platform_radius: float = 0.050,
    anchor_half_angle_deg: float = 10.0,
    arm_length: float = 0.025,
    rod_length: float = 0.110,
    trims_us=None,
) -> ServoHexapod:
    """The paired layout behind the preset ``hobby-servo`` (shipped as ``presets/servo-hobby.yaml``,
    which uses these defaults): a desk-size hexapod of six standard RC servos (MG996R class).

    Dimensions (our documented choice; seed 002 gives none):
    - three servo pairs centred at 0°, 120°, 240°; each servo shaft is radial, its horn faces the
      centre, the arm plane is ``base_radius`` = 60 mm from the centre; the two pivots of a pair are
      ``pair_spacing`` = 50 mm apart and their arms point away from each other, tangentially
      (servo 2k+1 clockwise, 2k+2 counter-clockwise; numbering counter-clockwise);
    - arm (horn hole radius) a = 25 mm, the outer hole of a standard 1" servo horn;
    - rod s = 110 mm (M3 ball links on a threaded rod), joint centre to joint centre;
    - platform anchors in pairs centred between the base pairs (60°, 180°, 300°) at radius 50 mm,
      ±10° apart, on the plate's underside plane (z_p = 0): each rod slants towards the neighbouring pair,
      which keeps the platform stiff in yaw and sideways (rods purely radial or vertical would not be).
    - servo: neutral 1500 µs, 400 µs per 45°, ±45° travel; 1.0 N·m stall torque, 5 g arm, 5 g rod,
      150 g platform (Drake model only).
    This gives h0 ≈ 108.5 mm and alpha0 ≈ 6.2° (arm slightly above horizontal at home).
    """
    c = np.radians([0.0, 0.0, 120.0, 120.0, 240.0, 240.0])
    side = np.array([-1.0, 1.0, -1.0, 1.0, -1.0, 1.0])  # odd: clockwise side, even: counter-clockwise
    u = np.stack([np.cos(c), np.sin(c), np.zeros(6)], -1)
    t = np.stack([-np.sin(c), np.cos(c), np.zeros(6)], -1)
    pivots = base_radius * u + (side * pair_spacing / 2)[:, None] * t
    beta = c + side * np.pi / 2
    # Anchor of servo 2k+2 (pointing counter-clockwise) sits at 60° + 120k - half; servo 2k+3 at 60° + 120k + half.
    ang = np.radians(np.array([-60.0, 60.0, 60.0, 180.0, 180.0, 300.0]) - side * anchor_half_angle_deg)
    anchors = platform_radius * np.stack([np.cos(ang), np.sin(ang), np.zeros(6)], -1)
    trims = np.full(6, NEUTRAL_US) if trims_us is None else np.asarray(trims_us, dtype=float)
    return ServoHexapod(
        name="hobby-servo",
        base_pivots=pivots,
        arm_directions=np.arctan2(np.sin(beta), np.cos(beta)),
        platform_anchors=anchors,
        arm_length=arm_length,
        rod_length=rod_length,
        shaft_directions=-u,  # horns face the centre
        neutral_us=trims,
        description="desk-size RC-servo hexapod (six MG996R-class servos), dimensions documented in servo.hobby_servo_hexapod",
    )


# ----------------------------------------------------------------------------------------------
# YAML (edge units: length_unit m|mm, angles in degrees, pulses in µs), loaded with the safe, bounded yamlio loader.

SERVO_PRESETS = ("hobby-servo",)
_PRESET_FILES = {"hobby-servo": "servo-hobby.yaml"}


@dataclass
class PairedLayoutConfig:
    """Three pairs of servos at 0°, 120°, 240°, horns facing the centre, arms of a pair pointing away
    from each other; anchors in pairs between them (``hobby_servo_hexapod`` documents the layout)."""

    base_radius: float = 0.0  # arm planes' distance from the centre
    pair_spacing: float = 0.0  # pivot to pivot within a pair
    platform_radius: float = 0.0  # anchor circle
    anchor_half_angle_deg: float = 0.0  # anchors of a pair at ±this about 60°, 180°, 300°


@dataclass
class ServoSpecConfig:
    """The servos: pulses (µs), travel and rate, and the dynamics used by the Drake simulation."""

    neutral_us: list[float] = field(default_factory=lambda: [NEUTRAL_US] * 6)  # W0_i, trims included
    rate_us: float = 400.0  # pulse change ...
    rate_deg: float = 45.0  # ... for this turn of the horn (the seed: 400 µs per 45°)
    travel_deg: float = 45.0  # allowed |alpha - alpha0|
    stall_torque: float = SERVO_STALL_TORQUE  # N·m
    speed_s_per_60deg: float = 0.17  # no-load speed, the datasheet's unit
    full_torque_error_deg: float = float(np.degrees(SERVO_BAND_RAD))  # error at which the stall torque is reached


@dataclass
class ServoMassesConfig:
    """Masses for the Drake model, kg."""

    arm: float = 0.005
    rod: float = 0.005
    platform: float = 0.15


@dataclass
class ServoHexapodConfig:
    """One servo hexapod as written in YAML. Exactly one layout: ``paired``, or explicit
    ``base_pivots`` + ``arm_directions_deg`` + ``platform_anchors`` + ``shaft_directions``."""

    name: str = ""
    description: str = ""
    length_unit: str = "m"
    arm_length: float = 0.0
    rod_length: float = 0.0
    paired: PairedLayoutConfig | None = None
    base_pivots: list[list[float]] = field(default_factory=list)
    arm_directions_deg: list[float] = field(default_factory=list)
    platform_anchors: list[list[float]] = field(default_factory=list)
    shaft_directions: list[list[float]] = field(default_factory=list)
    servo: ServoSpecConfig = field(default_factory=ServoSpecConfig)
    masses: ServoMassesConfig = field(default_factory=ServoMassesConfig)


def _positive(field_name: str, value, unit: str = "") -> float:
    if not (isinstance(value, (int, float)) and np.isfinite(value) and value > 0):
        raise GeometryError(
            GeometryError.SERVO_FIELD_POSITIVE.format(field=field_name, unit=" of " + unit if unit else "", value=value)
        )
    return float(value)


def _rows(field_name: str, value, shape) -> np.ndarray:
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise GeometryError(
            GeometryError.SERVO_FIELD_SHAPE.format(field=field_name, shape=_shape_words(shape), value=value)
        ) from None
    if arr.shape != shape:
        raise GeometryError(
            GeometryError.SERVO_FIELD_SHAPE.format(field=field_name, shape=_shape_words(shape), value=value)
        )
    if not np.all(np.isfinite(arr)):
        raise GeometryError(GeometryError.SERVO_FIELD_FINITE.format(field=field_name, value=value))
    return arr


def _shape_words(shape) -> str:
    return "6 numbers (one per servo)" if len(shape) == 1 else "6 points [x, y, z] (one per servo)"


def servo_hexapod_from_config(cfg: ServoHexapodConfig) -> ServoHexapod:
    """Build a validated ``ServoHexapod`` (SI units) from a parsed ``ServoHexapodConfig``; errors name
    the field and its value."""
    try:
        k = length_scale(cfg.length_unit)
    except ValueError:
        raise GeometryError(GeometryError.SERVO_UNIT.format(value=cfg.length_unit)) from None
    u = cfg.length_unit
    a = _positive("arm_length", cfg.arm_length, u) * k
    s = _positive("rod_length", cfg.rod_length, u) * k
    sv, m = cfg.servo, cfg.masses
    extra = dict(
        neutral_us=_rows("servo.neutral_us", sv.neutral_us, (6,)),
        rate_us_per_rad=_positive("servo.rate_us", sv.rate_us, "µs")
        / np.radians(_positive("servo.rate_deg", sv.rate_deg, "degrees")),
        travel_rad=np.radians(_positive("servo.travel_deg", sv.travel_deg, "degrees")),
        servo_torque=_positive("servo.stall_torque", sv.stall_torque, "N·m"),
        servo_speed=np.radians(60.0) / _positive("servo.speed_s_per_60deg", sv.speed_s_per_60deg, "seconds"),
        servo_band=np.radians(_positive("servo.full_torque_error_deg", sv.full_torque_error_deg, "degrees")),
        arm_mass=_positive("masses.arm", m.arm, "kg"),
        rod_mass=_positive("masses.rod", m.rod, "kg"),
        platform_mass=_positive("masses.platform", m.platform, "kg"),
    )
    if np.degrees(extra["travel_rad"]) >= 90:
        raise GeometryError(GeometryError.SERVO_TRAVEL.format(value=sv.travel_deg))
    explicit = {
        "base_pivots": cfg.base_pivots,
        "arm_directions_deg": cfg.arm_directions_deg,
        "platform_anchors": cfg.platform_anchors,
        "shaft_directions": cfg.shaft_directions,
    }
    given = [n for n, v in explicit.items() if len(v)]
    name = cfg.name or "servo-hexapod"
    if cfg.paired is not None:
        if given:
            raise GeometryError(GeometryError.SERVO_BOTH_LAYOUTS.format(name=name, given=", ".join(given)))
        p = cfg.paired
        h = hobby_servo_hexapod(
            base_radius=_positive("paired.base_radius", p.base_radius, u) * k,
            pair_spacing=_positive("paired.pair_spacing", p.pair_spacing, u) * k,
            platform_radius=_positive("paired.platform_radius", p.platform_radius, u) * k,
            anchor_half_angle_deg=float(p.anchor_half_angle_deg),
            arm_length=a,
            rod_length=s,
        )
        return h.replace(name=name, description=cfg.description, **extra)
    missing = [n for n in explicit if n not in given]
    if missing:
        raise GeometryError(GeometryError.SERVO_MISSING_LAYOUT.format(name=name, missing=", ".join(missing)))
    return ServoHexapod(
        name=name,
        description=cfg.description,
        base_pivots=_rows("base_pivots", cfg.base_pivots, (6, 3)) * k,
        arm_directions=np.radians(_rows("arm_directions_deg", cfg.arm_directions_deg, (6,))),
        platform_anchors=_rows("platform_anchors", cfg.platform_anchors, (6, 3)) * k,
        shaft_directions=_rows("shaft_directions", cfg.shaft_directions, (6, 3)),
        arm_length=a,
        rod_length=s,
        **extra,
    )


def load_servo_yaml(path) -> ServoHexapod:
    """Load a servo hexapod from a YAML file (schema: ``ServoHexapodConfig``)."""
    return servo_hexapod_from_config(
        load_yaml_config(
            path, ServoHexapodConfig, "servo hexapod", lambda cfg, where: check_name(cfg, where, str(path))
        )
    )


def servo_preset_path(name: str) -> Path:
    """The YAML file of a built-in servo hexapod preset."""
    if name not in _PRESET_FILES:
        raise GeometryError(GeometryError.SERVO_UNKNOWN_PRESET.format(name=name, presets=", ".join(SERVO_PRESETS)))
    return PRESET_FOLDER / _PRESET_FILES[name]


def load_servo_preset(name: str) -> ServoHexapod:
    """A built-in servo hexapod preset by name (``SERVO_PRESETS``), read from its YAML file."""
    return load_servo_yaml(servo_preset_path(name))


def load_servo_hexapod(name_or_path) -> ServoHexapod:
    """A preset name or a path to a servo hexapod YAML file."""
    if isinstance(name_or_path, ServoHexapod):
        return name_or_path
    text = str(name_or_path)
    if text in SERVO_PRESETS:
        return load_servo_preset(text)
    if text.endswith((".yaml", ".yml")) or Path(text).exists():
        return load_servo_yaml(text)
    raise GeometryError(GeometryError.SERVO_UNKNOWN.format(name=text, presets=", ".join(SERVO_PRESETS)))


# ----------------------------------------------------------------------------------------------
# The seed's equations.


def home_heights(hexapod: ServoHexapod) -> np.ndarray:
    """``(6,)`` h0 from eq. 10 for each servo (metres); NaN where s² + a² is too short to reach."""
    d = hexapod.platform_anchors[:, :2] - hexapod.base_pivots[:, :2]
    h2 = hexapod.rod_length**2 + hexapod.arm_length**2 - np.sum(d**2, axis=1)
    return np.sqrt(np.where(h2 > 0, h2, np.nan)) - hexapod.platform_anchors[:, 2] + hexapod.base_pivots[:, 2]


def _lmn(hexapod: ServoHexapod, q):
    """L, M, N of eq. 9 for anchor positions ``q`` (..., 6, 3) in the base frame."""
    a, s = hexapod.arm_length, hexapod.rod_length
    d = q - hexapod.base_pivots
    beta = hexapod.arm_directions
    L = np.sum(d**2, axis=-1) - (s**2 - a**2)
    M = 2 * a * d[..., 2]
    N = 2 * a * (np.cos(beta) * d[..., 0] + np.sin(beta) * d[..., 1])
    return L, M, N


def _alpha(L, M, N):
    """Eq. 9 with atan2; returns (alpha, ratio) and never NaN (ratio clipped, flagged by the caller)."""
    c = np.hypot(M, N)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(c > 0, L / np.where(c > 0, c, 1.0), np.copysign(np.inf, L))
    alpha = np.arcsin(np.clip(ratio, -1.0, 1.0)) - np.arctan2(N, M)
    return wrap_angle(alpha), ratio


def home_arm_angles(hexapod: ServoHexapod) -> np.ndarray:
    """``(6,)`` alpha0 (eq. 12): the arm angles at the home pose, radians (L0 = 2a² there)."""
    q = hexapod.platform_anchors + [0.0, 0.0, hexapod.home_height]
    return _alpha(*_lmn(hexapod, q))[0]


def anchor_positions(hexapod: ServoHexapod, poses) -> np.ndarray:
    """``(..., 6, 3)`` q_i = T + R p_i (eq. 2), the rod ends on the platform in the base frame, metres."""
    poses = check_poses(poses)
    R = rotation_matrix(poses[..., 3:], "zyx")
    return poses[..., None, :3] + np.einsum("...jk,ik->...ij", R, hexapod.platform_anchors)


def arm_tips(hexapod: ServoHexapod, alpha) -> np.ndarray:
    """``(..., 6, 3)`` p_BAi for arm angles ``alpha`` (..., 6) (eqs. 4-6), metres."""
    alpha = np.asarray(alpha, dtype=float)
    beta = hexapod.arm_directions
    u = np.stack([np.cos(alpha) * np.cos(beta), np.cos(alpha) * np.sin(beta), np.sin(alpha)], axis=-1)
    return hexapod.base_pivots + hexapod.arm_length * u


def check_poses(poses) -> np.ndarray:
    """``poses`` as a float array ``(..., 6)``; raise ``ServoPoseError`` naming a bad shape or pose."""
    poses = np.asarray(poses, dtype=float)
    if poses.shape[-1:] != (6,):
        raise ServoPoseError(ServoPoseError.SHAPE.format(shape=poses.shape))
    idx = first_index(~np.all(np.isfinite(poses), axis=-1))
    if idx is not None:
        raise ServoPoseError(ServoPoseError.NOT_FINITE.format(index=counted(idx), values=poses[idx].tolist()))
    return poses


@dataclass(frozen=True)
class ServoSolution:
    """Arm angles and pulse widths for a batch of poses. Arrays ``(..., 6)``.

    angles      alpha_i, radians (eq. 9; the nearest angle where unreachable)
    ratio       L / sqrt(M² + N²): |ratio| > 1 means the rod cannot reach the anchor
    delta       alpha_i - alpha0_i wrapped to (-pi, pi], radians
    pulse_raw   eqs. 13-14 without the travel limit, µs
    pulse       the commanded pulse: ``pulse_raw`` clamped to the ±travel range, µs
    """

    hexapod: ServoHexapod
    angles: np.ndarray
    ratio: np.ndarray
    delta: np.ndarray
    pulse_raw: np.ndarray
    pulse: np.ndarray

    @property
    def reachable(self) -> np.ndarray:
        return np.abs(self.ratio) <= 1.0

    @property
    def within_travel(self) -> np.ndarray:
        return np.abs(self.delta) <= self.hexapod.travel_rad * (1 + 1e-12)

    @property
    def ok(self) -> np.ndarray:
        """``(...)`` True where every servo reaches and stays within its travel."""
        return np.all(self.reachable & self.within_travel, axis=-1)

    def violations(self) -> list[dict]:
        """Every problem as ``{"pose": index, "servo": 1..6, "kind": "unreachable"|"travel", ...}``.

        ``unreachable``: ``ratio`` (|ratio| > 1); ``travel``: ``angle_deg`` (alpha - alpha0, degrees),
        ``limit_deg`` and ``excess_deg``. An unreachable servo is not also reported for travel.
        """
        out = []
        reach = self.reachable
        for idx in np.argwhere(~reach):
            idx = tuple(int(i) for i in idx)
            out.append(
                {"pose": list(idx[:-1]), "servo": idx[-1] + 1, "kind": "unreachable", "ratio": float(self.ratio[idx])}
            )
        lim = np.degrees(self.hexapod.travel_rad)
        for idx in np.argwhere(reach & ~self.within_travel):
            idx = tuple(int(i) for i in idx)
            d = float(np.degrees(self.delta[idx]))
            out.append(
                {
                    "pose": list(idx[:-1]),
                    "servo": idx[-1] + 1,
                    "kind": "travel",
                    "angle_deg": d,
                    "limit_deg": float(np.copysign(lim, d)),
                    "excess_deg": abs(d) - lim,
                }
            )
        out.sort(key=lambda v: (v["pose"], v["servo"]))
        return out


def arm_angles(hexapod: ServoHexapod, poses) -> tuple[np.ndarray, np.ndarray]:
    """Eq. 9 for ``(..., 6)`` poses: arm angles ``(..., 6)`` (radians) and the ratio L/sqrt(M²+N²)."""
    return _alpha(*_lmn(hexapod, anchor_positions(hexapod, poses)))


def pulse_widths(hexapod: ServoHexapod, alpha) -> np.ndarray:
    """Eqs. 13-14: ``(..., 6)`` pulse widths (µs) for arm angles ``alpha`` (..., 6), without limits."""
    delta = wrap_angle(np.asarray(alpha, dtype=float) - hexapod.home_angles)
    return hexapod.neutral_us + hexapod.pulse_signs * delta * hexapod.rate_us_per_rad


def angles_from_pulses(hexapod: ServoHexapod, pulse_us) -> np.ndarray:
    """The inverse of eqs. 13-14: arm angles ``(..., 6)`` (radians) for pulse widths (µs)."""
    pulse_us = np.asarray(pulse_us, dtype=float)
    return hexapod.home_angles + hexapod.pulse_signs * (pulse_us - hexapod.neutral_us) / hexapod.rate_us_per_rad


def solve(hexapod: ServoHexapod, poses) -> ServoSolution:
    """The seed's control step for ``(..., 6)`` poses: arm angles, pulse widths, per-servo checks."""
    alpha, ratio = arm_angles(hexapod, poses)
    delta = wrap_angle(alpha - hexapod.home_angles)
    raw = hexapod.neutral_us + hexapod.pulse_signs * delta * hexapod.rate_us_per_rad
    lim = hexapod.travel_rad
    pulse = hexapod.neutral_us + hexapod.pulse_signs * np.clip(delta, -lim, lim) * hexapod.rate_us_per_rad
    return ServoSolution(hexapod, alpha, ratio, delta, raw, pulse)


def quantise_pulses(pulse_us, resolution_us: float = 1.0) -> np.ndarray:
    """Pulse widths rounded to the driver's resolution (µs), half away from zero like a C ``lround``."""
    if not resolution_us > 0:
        raise StewartError(SERVO_RESOLUTION.format(value=resolution_us))
    p = np.asarray(pulse_us, dtype=float) / resolution_us
    return np.copysign(np.floor(np.abs(p) + 0.5), p) * resolution_us


def pose_jacobian(hexapod: ServoHexapod, poses, eps: float = 1e-7) -> np.ndarray:
    """``(..., 6, 6)`` d alpha_i / d pose_k (rad per m or rad) by central differences of eq. 9;
    truncation error ~eps² relative, far below anything it is used for (error propagation)."""
    poses = check_poses(poses)
    d = np.eye(6) * eps
    plus = arm_angles(hexapod, poses[..., None, :] + d)[0]
    minus = arm_angles(hexapod, poses[..., None, :] - d)[0]
    return np.swapaxes((plus - minus) / (2 * eps), -1, -2)
