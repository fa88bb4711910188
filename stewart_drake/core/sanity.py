"""Physical sanity: the one place that decides whether a pose, a trajectory, a platform or a requested
amount of work makes sense. Plain numpy (no Drake); metres, radians, seconds, newtons.

Every command calls these checks before it computes or prints anything:

- inputs must be finite (``check_finite``);
- positions must lie within ``FAR_FACTOR`` × the platform's size (``platform_size``): farther is a unit
  mistake (a CSV in millimetres read as metres), not a pose;
- the plate must be above its base: every plate anchor strictly above the base plane z = 0 of B
  (``above_base``), unless the platform declares ``plate_below_base_allowed: true``;
- legs must stay within the stroke along a trajectory (``check_trajectory``: the first offending
  time, leg and amount);
- dynamics and simulation need the plate's mass properties (``require_plate``), and the Drake plant a
  plate that is not negligible against the legs it joins (``require_plant_plate``);
- a platform must not be singular at its home pose (``check_home``, called when a platform is loaded);
- user-sized work (grid nodes, samples, steps, rows, iterations) is estimated against a memory and time
  budget before anything is allocated (``check_work``).

Bad input raises ``StewartError`` subclasses (exit 2); results outside physical limits raise
``PhysicalLimitError`` (exit 1).
"""

from __future__ import annotations

import math
import os

import numpy as np

from stewart_drake.core.kinematics import condition_number, leg_lengths, plate_anchors
from stewart_drake.core.rotations import rotation_matrix
from stewart_drake.errors import (
    BELOW_BASE,
    FAR_CENTRE,
    FAR_POSITION,
    GRAVITY_RANGE,
    NO_PLATE,
    NOT_FINITE,
    NOT_POSITIVE,
    OUT_OF_STROKE,
    PLATE_TOO_LIGHT,
    SERVO_NEUTRAL,
    SINGULAR_HOME,
    WORK_TOO_LARGE,
    WORK_UNBOUNDED,
    GeometryError,
    PhysicalLimitError,
    StewartError,
    WorkTooLargeError,
)

# Positions farther than this multiple of the platform's size from the base centre are unit mistakes.
FAR_FACTOR = 10.0
# A platform whose home pose has a scaled Jacobian condition number above this is singular there
# (the value ``kinematics.require_nonsingular`` and the dynamics use).
HOME_MAX_CONDITION = 1e8
# Fraction of the machine's physical memory one command may plan to use.
MEMORY_FRACTION = 0.25
# Fallback when the physical memory cannot be read (bytes).
DEFAULT_MEMORY = 8 * 2**30


# ----------------------------------------------------------------------------------------------
# Values.


def fmt_value(v) -> str:
    """A number as the user would have typed it: ``100``, ``0.001``, ``1e+09``, ``nan``."""
    v = float(v)
    if math.isfinite(v) and v == int(v) and abs(v) < 1e15:
        return str(int(v))
    return f"{v:.6g}"


def check_finite(value, what: str) -> np.ndarray:
    """``value`` as a float array; ``StewartError`` naming ``what`` if any element is NaN or infinite."""
    a = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(a)):
        shown = fmt_value(a) if a.ndim == 0 else "[" + ", ".join(fmt_value(x) for x in a.ravel()[:12]) + "]"
        raise StewartError(NOT_FINITE.format(what=what, value=shown))
    return a


def check_positive(value, what: str, unit: str = "") -> float:
    """A finite, strictly positive float, or ``StewartError`` naming ``what``."""
    v = float(value)
    if not (math.isfinite(v) and v > 0):
        raise StewartError(NOT_POSITIVE.format(what=what, unit=" of " + unit if unit else "", value=fmt_value(v)))
    return v


def check_gravity(g: float, option: str = "--gravity") -> float:
    """Gravity in m/s²: finite and within ±100 m/s² (10 g; larger is a unit mistake)."""
    v = float(g)
    if not math.isfinite(v):
        raise StewartError(NOT_FINITE.format(what=f"{option} (m/s²)", value=fmt_value(v)))
    if abs(v) > 100.0:
        raise StewartError(GRAVITY_RANGE.format(option=option, value=fmt_value(v)))
    return v


# ----------------------------------------------------------------------------------------------
# Poses.


def platform_size(platform) -> float:
    """A length scale of ``platform`` (m): the largest of L_max and the anchor radii."""
    r_base = float(np.max(np.linalg.norm(platform.base_anchors, axis=1)))
    r_top = float(np.max(np.linalg.norm(platform.top_anchors - platform.rotation_centre, axis=1)))
    return max(platform.L_max, r_base, r_top)


def servo_hexapod_size(hexapod) -> float:
    """A length scale of an RC-servo hexapod (m): the largest of its pivot and anchor radii, arm plus rod, and
    its home height (the servo counterpart of ``platform_size``)."""
    r_base = float(np.max(np.linalg.norm(hexapod.base_pivots, axis=1)))
    r_top = float(np.max(np.linalg.norm(hexapod.platform_anchors, axis=1)))
    return max(r_base, r_top, hexapod.arm_length + hexapod.rod_length, hexapod.home_height)


def check_servo_pose(hexapod, pose, what: str = "--pose") -> None:
    """``StewartError`` when the position of ``pose`` (6,) (m, rad; finite) lies farther than ``FAR_FACTOR`` ×
    ``servo_hexapod_size`` from the base centre: a unit mistake, as for a platform (``check_poses``), not a
    pose to call unreachable with a 150-digit ratio."""
    size = servo_hexapod_size(hexapod)
    p = np.asarray(pose, dtype=float)[:3]
    r = math.hypot(*p)  # no overflow in the squares (inf only where |p| itself is)
    if r > FAR_FACTOR * size:
        raise StewartError(
            FAR_POSITION.format(
                what=what, pos_m=[float(f"{x:.6g}") for x in p], ratio=r / size, size_m=size, limit=FAR_FACTOR
            )
        )


def plate_anchor_heights(platform, poses, convention: str = "utn") -> np.ndarray:
    """``(..., 6)`` z of each leg's plate anchor in B (m) for ``(..., 6)`` poses."""
    return plate_anchors(platform, poses, convention)[..., 2]


def above_base(platform, poses, convention: str = "utn") -> np.ndarray:
    """``(...)`` True where every plate anchor is strictly above the base plane (z > 0 in B), or the
    platform allows its plate below the base."""
    z = plate_anchor_heights(platform, poses, convention)
    if getattr(platform, "plate_below_base_allowed", False):
        return np.ones(z.shape[:-1], bool)
    return np.all(z > 0.0, axis=-1)


def _label(what: str, index, times) -> str:
    if times is not None:
        return f"{what} at t = {float(times[index]):.4f} s"
    return f"{what} {index + 1}"


def check_poses(
    platform, poses, convention: str = "utn", what: str = "pose", times=None, lines=None, base: bool = True
) -> np.ndarray:
    """``(n, 6)`` poses (SI) after the checks every pose must pass: finite (``StewartError``), within
    ``FAR_FACTOR`` × ``platform_size`` of the base centre (``StewartError``: a unit mistake), plate
    above the base (``PhysicalLimitError``). Errors name the first offending pose as people count
    (``pose 3``), or its time (``times`` (n,) s) or file line (``lines`` (n,) ints, "line 12").
    ``base=False`` skips the plate-above-base check (the caller reports ``above_base`` per pose)."""
    q = np.asarray(poses, dtype=float).reshape(-1, 6)

    def label(i):
        if len(q) == 1 and times is None and lines is None:
            return what
        if lines is not None:
            return f"{what} on line {int(lines[i])}"
        return _label(what, i, times)

    finite = np.all(np.isfinite(q), axis=1)
    if not np.all(finite):
        i = int(np.argmin(finite))
        raise StewartError(NOT_FINITE.format(what=label(i), value="[" + ", ".join(fmt_value(x) for x in q[i]) + "]"))
    size = platform_size(platform)
    with np.errstate(over="ignore"):  # |p| of 1e308 is inf: far, as it should be
        r = np.linalg.norm(q[:, :3], axis=1)
    far = r > FAR_FACTOR * size
    if np.any(far):
        i = int(np.argmax(far))
        raise StewartError(
            FAR_POSITION.format(
                what=label(i),
                pos_m=[float(f"{x:.6g}") for x in q[i, :3]],
                ratio=r[i] / size,
                size_m=size,
                limit=FAR_FACTOR,
            )
        )
    if base and not getattr(platform, "plate_below_base_allowed", False):
        z = plate_anchor_heights(platform, q, convention)
        low = ~np.all(z > 0.0, axis=1)
        if np.any(low):
            i = int(np.argmax(low))
            raise PhysicalLimitError(below_base_message(label(i), z[i]))
    return q


def below_base_message(what: str, z) -> str:
    """``BELOW_BASE`` for one pose whose plate anchors are at heights ``z`` (6,) m."""
    k = int(np.argmin(z))
    return BELOW_BASE.format(what=what, where="in" if z[k] == 0 else "below", anchor=f"of leg {k + 1}", z_mm=z[k] * 1e3)


# ----------------------------------------------------------------------------------------------
# Trajectories.


def first_stroke_violation(platform, lengths, times=None) -> dict | None:
    """The first sample (in time order) where a leg leaves the stroke, and its worst leg there:
    ``{"index", "t_s", "leg" (1-based), "length_m", "limit_m", "excess_m", "side" ("min"|"max")}``;
    None when every ``(n, 6)`` length is within [L_min, L_max]."""
    L = np.asarray(lengths, dtype=float).reshape(-1, 6)
    below = platform.L_min - L
    above = L - platform.L_max
    excess = np.maximum(below, above)
    bad = np.any(excess > 0, axis=1)
    if not np.any(bad):
        return None
    i = int(np.argmax(bad))
    leg = int(np.argmax(excess[i]))
    side = "min" if below[i, leg] > 0 else "max"
    return {
        "index": i,
        "t_s": None if times is None else float(times[i]),
        "leg": leg + 1,
        "length_m": float(L[i, leg]),
        "limit_m": platform.L_min if side == "min" else platform.L_max,
        "excess_m": float(excess[i, leg]),
        "side": side,
    }


def stroke_message(v: dict, what: str = "the trajectory", hint: str = "") -> str:
    """``OUT_OF_STROKE`` filled from a ``first_stroke_violation`` dict."""
    return OUT_OF_STROKE.format(
        what=what,
        t=v["t_s"] if v["t_s"] is not None else float(v["index"]),
        leg=v["leg"],
        length_mm=v["length_m"] * 1e3,
        excess_mm=v["excess_m"] * 1e3,
        side="below" if v["side"] == "min" else "above",
        bound="minimum" if v["side"] == "min" else "maximum",
        limit_mm=v["limit_m"] * 1e3,
        hint=hint,
    )


def check_trajectory(
    platform, times, poses, convention: str = "utn", what: str = "the trajectory", allow_out_of_stroke: bool = False
) -> list[str]:
    """Check a sampled trajectory (``times`` (n,) s, ``poses`` (n, 6) SI): every pose passes
    ``check_poses`` (labelled by its time) and every leg stays within the stroke. A stroke violation
    raises ``PhysicalLimitError`` naming the first offending time, leg and amount, unless
    ``allow_out_of_stroke``: then its message is returned as a warning (a list of 0 or 1 strings)."""
    t = np.asarray(times, dtype=float).reshape(-1)
    q = check_poses(platform, poses, convention, what=what, times=t)
    v = first_stroke_violation(platform, leg_lengths(platform, q, convention), t)
    if v is None:
        return []
    if not allow_out_of_stroke:
        raise PhysicalLimitError(stroke_message(v, what, "; allow_out_of_stroke=True runs it anyway, with a warning"))
    return [stroke_message(v, what)]


# ----------------------------------------------------------------------------------------------
# Platforms.


def has_plate(platform) -> bool:
    """True when the plate has a positive mass and a positive definite inertia."""
    if not platform.mass > 0:
        return False
    return bool(np.linalg.eigvalsh(np.asarray(platform.inertia)).min() > 0)


def require_plate(platform, command: str) -> None:
    """``GeometryError`` naming the missing YAML key when ``command`` needs the plate's mass properties
    (dynamics, simulation) and the platform has none (a massless plate makes every force 0)."""
    if not has_plate(platform):
        raise GeometryError(NO_PLATE.format(name=platform.name, command=command))


# The Drake plant's plate must weigh at least this fraction of the legs' moving mass (six cylinders and
# pistons). Why: the plate closes the six loops through ball joints that Drake solves as near-rigid
# constraints, whose compliance is set from the mass they join: with a plate much lighter than the legs, a
# joint opens by about K·m_legs·h²/m_plate (h the plant step) under the legs' own weight and inertia, which
# the plate then carries. Measured (utn-dynamic, m_legs 1.8 kg, h = 1 ms, float controller, 1 s): the
# largest joint gap was 3.0e-8 m at the seed's 1.36 kg, 5.9e-8 m at 10 g, 4.5e-6 m at 0.1 g and 5.0e-4 m
# at 1 mg and below (the joints open until the plate hangs in them; the Monte Carlo leg error tripled):
# K ≈ 2.5e-4 m/s². At 1/1000 of the legs' mass the gap is ~0.25 µm at a 1 ms step, a fortieth of the
# 10 µm sensor count the controller reads; a lighter plate is not the platform any more (a longer plant
# step opens the joints as h², which ``max_constraint_gap_m`` reports).
MIN_PLATE_TO_LEGS = 1e-3


def legs_moving_mass(platform) -> float:
    """The six legs' moving mass, kg: cylinders (turning on their base joints) and pistons."""
    return 6.0 * (float(platform.legs.cylinder_mass) + float(platform.legs.piston_mass))


def require_plant_plate(platform, command: str) -> None:
    """``require_plate``, and ``GeometryError`` when the plate is lighter than ``MIN_PLATE_TO_LEGS`` of the
    legs' moving mass (the Drake plant's ball joints would open: see ``MIN_PLATE_TO_LEGS``)."""
    require_plate(platform, command)
    legs = legs_moving_mass(platform)
    minimum = MIN_PLATE_TO_LEGS * legs
    if platform.mass < minimum:
        raise GeometryError(
            PLATE_TOO_LIGHT.format(
                name=platform.name,
                mass=platform.mass,
                ratio=MIN_PLATE_TO_LEGS,
                legs=legs,
                command=command,
                minimum=minimum,
            )
        )


def _collinear(points: np.ndarray, tol: float) -> bool:
    c = points - points.mean(axis=0)
    s = np.linalg.svd(c, compute_uv=False)
    return bool(s[1] <= tol * max(s[0], 1e-300))


def check_home(platform) -> None:
    """``GeometryError`` when ``platform`` is singular at its home pose: its legs cannot hold the plate
    there (the Jacobian loses rank). Names the anchors when they are collinear (the usual cause)."""
    home = platform.home_pose()
    cond = float(condition_number(platform, home))
    if cond <= HOME_MAX_CONDITION:
        return
    tol = 1e-9
    if _collinear(platform.base_anchors, tol):
        why = "base anchors 1-6 are collinear (every leg meets one line, so the plate can turn about it)"
    elif _collinear(platform.top_anchors, tol):
        n = len(platform.top_anchors)
        why = f"top anchors 1-{n} are collinear (every leg meets one line, so the plate can turn about it)"
    else:
        why = "the six legs' lines are linearly dependent there; move an anchor or give another home_height"
    raise GeometryError(SINGULAR_HOME.format(name=platform.name, cond=cond, limit=HOME_MAX_CONDITION, why=why))


# ----------------------------------------------------------------------------------------------
# Bounded work.


def memory_budget() -> int:
    """Bytes one command may plan to use: ``MEMORY_FRACTION`` of the machine's physical memory."""
    try:
        total = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        total = DEFAULT_MEMORY
    return int(MEMORY_FRACTION * total)


def human_bytes(n: float) -> str:
    """``512 MB``, ``3.4 GB``, ``~10^19 GB`` for absurd sizes."""
    n = float(n)
    if n >= 1e15:
        return f"~10^{int(math.floor(math.log10(n / 1e9)))} GB"
    for unit, k in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n >= k:
            return f"~{n / k:.3g} {unit}"
    return f"{n:.0f} B"


def human_seconds(s: float) -> str:
    """A duration in seconds as people read it (s, min, h, days or years), for work estimates."""
    s = float(s)
    if s >= 86400 * 365:
        return f"~{s / (86400 * 365):.2g} years"
    if s >= 3600:
        return f"~{s / 3600:.2g} h"
    if s >= 60:
        return f"~{s / 60:.2g} min"
    return f"~{s:.2g} s"


def check_work(
    option: str,
    value: str,
    count: float,
    what: str,
    bytes_per: float = 0.0,
    max_count: float | None = None,
    seconds_per: float = 0.0,
    max_seconds: float | None = None,
    hint: str = "",
) -> None:
    """Refuse (``WorkTooLargeError``) a request of ``count`` items (``what``: "grid nodes", "samples")
    whose memory (``bytes_per`` each) exceeds ``memory_budget``, whose count exceeds ``max_count``, or
    whose time (``seconds_per`` each) exceeds ``max_seconds``. ``option``/``value`` name the user's
    option as typed; ``hint`` ends the message (e.g. "; use a coarser --resolution")."""
    count = float(count)
    if not math.isfinite(count):
        raise WorkTooLargeError(WORK_UNBOUNDED.format(option=option, value=value, what=what, hint=hint))
    need = count * bytes_per
    budget = memory_budget()
    if bytes_per and need > budget:
        raise WorkTooLargeError(
            WORK_TOO_LARGE.format(
                option=option,
                value=value,
                estimate=f"{count:.2g} {what} ({human_bytes(need)})",
                limit=f"{human_bytes(budget).lstrip('~')} on this machine",
                hint=hint,
            )
        )
    if max_count is not None and count > max_count:
        raise WorkTooLargeError(
            WORK_TOO_LARGE.format(
                option=option, value=value, estimate=f"{count:.2g} {what}", limit=f"{max_count:.2g} {what}", hint=hint
            )
        )
    if seconds_per and max_seconds is not None and count * seconds_per > max_seconds:
        raise WorkTooLargeError(
            WORK_TOO_LARGE.format(
                option=option,
                value=value,
                estimate=f"{count:.2g} {what} ({human_seconds(count * seconds_per)})",
                limit=human_seconds(max_seconds),
                hint=hint,
            )
        )


def check_centre(platform, centre, option: str = "--centre") -> np.ndarray:
    """A rotation centre ``(3,)`` (m, plate frame): finite and within ``FAR_FACTOR`` × ``platform_size``
    of the plate's origin (farther is a unit mistake), else ``StewartError``."""
    c = check_finite(centre, f"{option} (m)")
    size = platform_size(platform)
    r = float(np.linalg.norm(c))
    if r > FAR_FACTOR * size:
        raise StewartError(
            FAR_CENTRE.format(
                option=option, centre=" ".join(fmt_value(x) for x in c), ratio=r / size, size_m=size, limit=FAR_FACTOR
            )
        )
    return c


# ----------------------------------------------------------------------------------------------
# RC servos.

# The pulse widths an RC servo's PWM input accepts (µs): the 50 Hz frame's extreme range that hobby
# servos take (1000-2000 µs nominal, 500-2500 µs extended); wider pulses are not servo commands.
SERVO_PULSE_RANGE_US = (500.0, 2500.0)


def check_servo_neutrals(hexapod, what: str = "--trim") -> None:
    """``StewartError`` unless every neutral pulse W0_i (µs) is finite and leaves room for the full travel:
    W0_i ± travel·rate within ``SERVO_PULSE_RANGE_US``."""
    w0 = np.asarray(hexapod.neutral_us, dtype=float)
    check_finite(w0, f"{what} (µs)")
    swing = float(hexapod.travel_rad * hexapod.rate_us_per_rad)
    lo, hi = SERVO_PULSE_RANGE_US[0] + swing, SERVO_PULSE_RANGE_US[1] - swing
    bad = (w0 < lo) | (w0 > hi)
    if np.any(bad):
        i = int(np.argmax(bad))
        raise StewartError(
            SERVO_NEUTRAL.format(
                what=what,
                servo=i + 1,
                value=fmt_value(w0[i]),
                lo=lo,
                hi=hi,
                swing=swing,
                range_lo=SERVO_PULSE_RANGE_US[0],
                range_hi=SERVO_PULSE_RANGE_US[1],
            )
        )


def plate_floor(platform, orientation, convention: str = "utn") -> float:
    """The height (m) the rotation centre must exceed, at ``orientation`` (3,) rad, for every plate
    anchor to be above the base plane: max_i −(R_BT (p_TTi − p_TC))_z; −inf when the platform allows
    its plate below the base. Positions above it form the half-space a workspace may count."""
    if getattr(platform, "plate_below_base_allowed", False):
        return -math.inf
    R = rotation_matrix(np.asarray(orientation, dtype=float), convention)
    r = (platform.top_anchors_per_leg - platform.rotation_centre) @ R.T
    return float(np.max(-r[:, 2]))
