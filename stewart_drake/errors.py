"""The project's one error hierarchy and every message template.

Every error derives from ``StewartError`` (itself a ``ValueError``, so callers can catch bad input in one
place); the CLI prints it as one line and exits 2, or 1 for a ``PhysicalLimitError``. Messages name the
offending thing and the value as given; they are templates here, as constants of the class that raises
them (``GeometryError.STROKE``) or as module constants when several classes share one (``SHAPE``), and
tests match them: ``pytest.raises(GeometryError, match=re.escape(GeometryError.STROKE.format(...)))``.
"""

from __future__ import annotations


def counted(index) -> str:
    """A batch index as people count, for messages: ``(0,)`` -> "1", ``(1, 2)`` -> "2,3", ``()`` -> "1"
    (a single sample), an int ``k`` -> "k+1"."""
    if isinstance(index, (int,)) or hasattr(index, "__index__"):
        return str(int(index) + 1)
    index = tuple(index)
    return ",".join(str(int(i) + 1) for i in index) if index else "1"


class StewartError(ValueError):
    """Base class of every error the toolkit raises on bad input or an impossible request."""


class GeometryError(StewartError):
    """A platform description is inconsistent (shapes, values, anchors, limits)."""

    INERTIA_SINGULAR = (
        "platform {name!r}: the plate's mass matrix is not positive definite (plate.mass {mass:g} kg, plate.inertia): "
        "a plate without mass or inertia has no natural frequencies"
    )
    TOP_SHAPE = "top_anchors must have shape (k, 3) with 3 <= k <= 6, got {shape}"
    LEG_TOP = "leg_top must list 6 integer top-anchor indices (one per leg), got {value!r}"
    LEG_TOP_RANGE = "leg_top: leg {leg} refers to top anchor {anchor}, but there are {n} top anchors (0..{last})"
    LEG_TOP_UNUSED = "leg_top: top anchor {anchor} is used by no leg"
    STROKE = "stroke must satisfy 0 < L_min < L_max, got L_min = {lmin} m, L_max = {lmax} m"
    STROKE_PAIR = "stroke must be [L_min, L_max], got {value!r}"
    MASS = "plate mass must be finite and >= 0, got {value} kg"
    INERTIA_SYMMETRIC = "plate inertia must be symmetric, got {value}"
    INERTIA_PHYSICAL = "plate inertia is not physical (principal moments {moments} kg·m²)"
    INERTIA_NUMBERS = "plate inertia must be 6 numbers (Ixx Iyy Izz Ixy Ixz Iyz), got {value!r}"
    HOME_HEIGHT = "home_height must be a positive number of metres, got {value}"
    UTN_DIMENSION = "UTN dimension {name} must be a positive length, got {value}"
    CIRCLE_ANGLES = "{what} angles must be 6 numbers, got shape {shape}"
    CIRCLE_RADIUS = "{what} radius must be a positive length, got {value}"
    NOT_NUMBERS = "{name} must be numbers, got {value!r}"
    SHAPE = "{name} must have shape {shape}, got {got}"
    NOT_FINITE = "{name} must be finite, got {value}"
    FIELD_KIND = "Platform.{name} must be {kind}, got {value!r}"
    LEG_FIELD = "legs.{name} must be {rule}, got {value:g}"
    COINCIDE = "{what} {i} and {j} coincide at {at} m (closer than {limit} m)"
    TOO_WIDE = (
        "platform too wide for its stroke: a leg spans {span:.4f} m horizontally but mid-stroke is "
        "{target:.4f} m; give home_height"
    )
    LENGTH_UNIT = "length_unit: {problem}"
    ANCHOR_DESCRIPTIONS = (
        "platform {name!r}: give exactly one anchor description (utn, radial, or "
        "base_anchors/top_anchors/leg_top), got {given}"
    )
    PLATE_SHEET = (
        "platform {name!r}: plate thickness+density describe a UTN triangle sheet; give both, with utn dimensions"
    )
    IN_FILE = "{path}: {problem}"
    UNKNOWN_PRESET = "unknown preset {name!r}; built-in presets: {presets}"
    UNKNOWN_PLATFORM = "unknown platform {name!r}: not a preset ({presets}) and not a YAML file"
    LEG_LIMIT = "platform {name!r}: legs.{field} must be a positive number, got {value}"
    # shared base joints (6-3 platforms, ``leg_base``)
    BASE_PAIRS = "{problem}; legs may share base joints only in three pairs (6-3), declared with leg_base"
    BASE_COUNT = (
        "base_anchors: {n} points given; give 6 (one per leg), or list each base joint once and give leg_base "
        "(the base joint of each leg)"
    )
    LEG_BASE_RANGE = "leg_base: leg {leg} refers to base anchor {anchor}, but there are {n} base anchors (0..{last})"
    LEG_BASE_UNUSED = "leg_base: base anchor {anchor} is used by no leg"
    BASE_REPEATED = (
        "repeats item {first} (closer than {limit} m); legs sharing a base joint list it once and give "
        "leg_base (the base joint of each leg)"
    )

    # a servo hexapod description (``mechanisms.servo``)
    SERVO_SHAPE = "servo hexapod {name} must have shape {shape}, got {got}"
    SERVO_NOT_FINITE = "servo hexapod {name} has non-finite values: {value}"
    SERVO_NOT_POSITIVE = "servo hexapod {name} must be a positive number, got {value}"
    SERVO_ROD = "rod length s = {s} m must exceed the arm length a = {a} m"
    SERVO_SHAFT = "servo {servo}: shaft direction {shaft} is not perpendicular to its arm plane (beta = {beta:.6g} deg)"
    SERVO_NO_H0 = "servo {servo}: arm and rod cannot be at right angles over its anchor (eq. 10 has no real h0)"
    SERVO_ASYMMETRIC = "eq. 10 gives different home heights per servo ({h_mm} mm): the layout is not symmetric"
    SERVO_FIELD_POSITIVE = "{field} must be a positive number{unit}, got {value!r}"
    SERVO_FIELD_SHAPE = "{field} must be {shape}, got {value!r}"
    SERVO_FIELD_FINITE = "{field} must be finite, got {value!r}"
    SERVO_UNIT = "length_unit must be m or mm, got {value!r}"
    SERVO_TRAVEL = "servo.travel_deg must be below 90 degrees, got {value!r}"
    SERVO_BOTH_LAYOUTS = (
        "servo hexapod {name!r}: give either paired or the explicit layout, not both (also got {given})"
    )
    SERVO_MISSING_LAYOUT = (
        "servo hexapod {name!r}: give paired, or all of base_pivots, arm_directions_deg, "
        "platform_anchors, shaft_directions (missing {missing})"
    )
    SERVO_UNKNOWN_PRESET = "unknown servo hexapod preset {name!r}; available: {presets}"
    SERVO_UNKNOWN = "unknown servo hexapod {name!r}: not a preset ({presets}) and not a YAML file"


class UnreachablePoseError(StewartError):
    """A pose puts a leg outside its stroke (or is otherwise unreachable).

    Attributes: ``pose_index`` (index into the batch, a tuple), ``leg`` (1-based), ``length`` (m),
    ``limit`` (m, the violated bound), ``excess`` (m, positive).
    """

    TEMPLATE = "pose {index}: leg {leg} length {length_mm:.3f} mm is {excess_mm:.3f} mm {side} the stroke {bound} {limit_mm:.3f} mm"

    def __init__(self, pose_index, leg: int, length: float, limit: float, side: str):
        self.pose_index, self.leg, self.length, self.limit = pose_index, leg, length, limit
        self.excess = abs(length - limit)
        super().__init__(
            self.TEMPLATE.format(
                index=counted(pose_index),
                leg=leg,
                length_mm=length * 1e3,
                excess_mm=self.excess * 1e3,
                side="below" if side == "min" else "above",
                bound="minimum" if side == "min" else "maximum",
                limit_mm=limit * 1e3,
            )
        )


class SingularPoseError(StewartError):
    """A pose is on, or too near, a singularity of the platform's Jacobian."""


class ForwardKinematicsError(StewartError):
    """Forward kinematics found no (trustworthy) pose for some leg-length set: Newton did not converge,
    or no assembly exists. The message names the sample, the residual and the reason."""


class SingularityWarning(UserWarning):
    """A pose is near a singularity of the platform's Jacobian: results there are poorly conditioned."""


# ----------------------------------------------------------------------------------------------
# Array arguments (``core.argcheck``): shapes and finite values.


class ShapeError(StewartError):
    """An array argument (poses, lengths, vectors) has the wrong shape."""


class NotFiniteError(StewartError):
    """An array argument holds NaN or an infinity; the message names the first such sample."""


SHAPE = "Expected {name} to have shape {shape}, got {got}"
NOT_FINITE_SAMPLE = "{what} {index} is not finite: {values}"
# The length Jacobian at a trajectory sample is (nearly) singular (``dynamics.solve_leg_forces``).
SINGULAR_SAMPLE = (
    "sample {index}: the length Jacobian J = dL/dq is singular or nearly so (condition number {cond:.3g} > "
    "{limit:.3g}); leg forces are undefined there"
)
# A pose whose scaled J⁻¹ condition number exceeds the limit (``kinematics.require_nonsingular``).
SINGULAR_POSE = "pose {index} is singular or nearly so: Jacobian condition number {cond:.3g} > {limit:.3g}"


# ----------------------------------------------------------------------------------------------
# Mechanisms other than the 6-UPS platform: the 3R leg (``mechanisms.leg3r``) and the RC-servo hexapod
# (``mechanisms.servo``).


class LegError(StewartError):
    """A 3R leg's parameters, joint angles or targets are malformed."""

    LENGTH = "leg length {name} must be a positive number of metres up to {limit:g}, got {value}"
    ALPHA = "ankle angle alpha must be finite, got {value}"
    LIMITS = "{name} must be two finite angles (rad) with lower < upper, got {value}"
    ANGLES_2 = "leg joint angles need 2 numbers (q1, q2), got shape {shape}"
    ANGLES_2_3 = "leg joint angles need 2 numbers (q1, q2) or 3 (q1, q2, q3), got shape {shape}"
    BRANCH = "unknown elbow branch {branch!r}; expected 'a' (knee angle >= 0) or 'b' (<= 0)"
    TARGET = "a leg target needs {n} numbers ({names}), got shape {shape}"
    SEED_FIX = "unknown seed fix {fix!r}; expected some of {valid}"


class UnreachableTargetError(StewartError):
    """A foot target lies outside the leg's reachable annulus.

    Attributes: ``index`` (tuple, into the batch), ``distance`` (m, hip to target, or to the wrist for the
    3R solver), ``r_min``, ``r_max`` (m)."""

    TEMPLATE = (
        "target {index}: {what} is {d_mm:.3f} mm from the hip, outside the reachable range "
        "[{lo_mm:.3f}, {hi_mm:.3f}] mm"
    )

    def __init__(self, index, distance, r_min, r_max, what="the foot"):
        self.index, self.distance, self.r_min, self.r_max = index, distance, r_min, r_max
        super().__init__(
            self.TEMPLATE.format(
                index=counted(index), what=what, d_mm=distance * 1e3, lo_mm=r_min * 1e3, hi_mm=r_max * 1e3
            )
        )


class ServoPoseError(StewartError):
    """A pose given to the servo hexapod is malformed (shape, non-finite numbers)."""

    SHAPE = "a servo hexapod pose needs 6 numbers (x, y, z, phi, theta, psi), got shape {shape}"
    NOT_FINITE = "pose {index} has a non-finite number: {values}"


SERVO_RESOLUTION = "pulse resolution must be > 0 µs, got {value}"


# ----------------------------------------------------------------------------------------------
# Fixed-point arithmetic (``fixedpoint``): values a word cannot hold, operations outside their domain.


class FixedPointError(StewartError):
    """A value does not fit the fixed-point word it is converted to, or an operation is outside its domain."""

    WORD_BITS = "word_bits must be an integer in 8..31, got {value!r}"
    LENGTH_LSB = "length_lsb must be a positive number of metres, got {value!r}"
    TRIG = "trig must be one of {valid}, got {value!r}"
    TFR16_BITS = "trig='tfr16' is the 16-bit DSP library; it needs word_bits=16, got {value}"
    ANGLE = "pose {index}: angle {angle:.6g} rad exceeds ±pi; the DSP takes angles as fractions of pi in [-1, 1]"
    LENGTH_WORD = "{what} {value:.6g} m does not fit a {bits}-bit word of {lsb:g} m (range ±{range_m:.6g} m)"
    NOT_INTEGER_16 = "{name} must hold integers (Word16), got {value!r}"
    NOT_INTEGER_32 = "{name} must hold integers (Word32)"
    RANGE = "{name} = {value} is outside the {bits}-bit range [{lo}, {hi}]"
    FRAC16_NOT_FINITE = "FRAC16 of a non-finite value {value!r}"
    FRAC32_NOT_FINITE = "FRAC32 of a non-finite value"
    DIV_S = "div_s needs 0 <= a <= b and b > 0, got a={a}, b={b}"
    NO_CYCLES = "operation {op!r} has no entry in the cycle table"


class DspPoseError(FixedPointError):
    """A firmware pose (mm and fractions of pi) is malformed or does not fit the DSP's 16-bit words."""

    NOT_FINITE = "{name} is not finite: {values}"
    POSITION = "{name}: position {values} mm does not fit a 16-bit word [-32768, 32767]"
    ANGLES = "{name}: angles {values} (fractions of pi) must lie in [-1, 1]"
    ANGLE_OPTION = "angle {name} = {value:g} {unit} is beyond ±180°; the firmware takes fractions of pi in [-1, 1]"


# ----------------------------------------------------------------------------------------------
# Design studies (``design``): envelopes, payloads, stiffness.


class EnvelopeError(StewartError):
    """An envelope file is malformed or leaves the platform's workspace."""

    NOT_NUMBERS = "{where}: expected numbers, got {value!r}"
    COUNT = "{where}: expected {n} numbers, got {value!r}"
    NOT_FINITE = "{where}: values must be finite, got {value!r}"
    NOT_INTEGERS = "{where}: expected integers, got {value!r}"
    IN_FILE = "{source}: {problem}"
    ONE_OF = "{source}: give exactly one of poses (a list) or box (a grid)"
    STEPS = "{source}: box.steps must be >= 1, got {value!r}"
    BOX_ORDER = "{source}: box.max[{j}] = {hi} is below box.min[{j}] = {lo}"
    BOX_TOO_LARGE = "{source}: box.steps {steps!r} make {n} poses, more than the limit {limit}"
    TOO_MANY_POSES = "{source}: {n} poses, more than the limit {limit}"
    NEGATIVE_BOUND = "{source}: {name}.{part} bounds are magnitudes and must be >= 0, got {value}"
    OUT_OF_STROKE = (
        "{source}: {pose} leaves the workspace: leg {leg} length {length_mm:.3f} mm is {excess_mm:.3f} mm "
        "{side} the stroke"
    )
    SINGULAR = "{source}: {pose} is singular or nearly so (condition number {cond:.3g})"


class PayloadError(StewartError):
    """A payload is not physical (negative or non-finite mass, below the plate)."""

    MASS = "{option}: payload mass must be a finite number >= 0 kg, got {value}"
    COM_NOT_FINITE = "{option}-com: payload centre of mass must be finite, got {value} m"
    COM_BELOW = "{option}-com: z = {z:g} m is below the plate (the plate frame's z >= 0 holds the plate and its load)"

    TOO_HEAVY = "{option}: payload mass {value:g} kg is beyond {limit:g} kg (1000 t); is it in kg?"
    BELOW_PLATE = (
        "{option}: Z = {z:g} {unit} is below the plate (the plate frame's z >= 0 holds the plate and its load)"
    )


class StiffnessError(StewartError):
    """A leg stiffness is missing or not physical."""

    MISSING = "{option}: no leg stiffness given and the platform file has no legs.stiffness"
    NOT_POSITIVE = "{option}: leg stiffness must be a positive number of N/m, got {value}"


SLICE_NODES = "slice of {n} x {n} nodes: need 2 <= n and n² <= {limit}"


# ----------------------------------------------------------------------------------------------
# Workspace requests (``workspace``).


class WorkspaceError(StewartError):
    """A workspace request that cannot be answered (bad resolution, start pose outside the limits, ...)."""

    EXECUTOR = "executor must be a concurrent.futures.Executor (or have submit), got {kind}"
    GRID_TOO_LARGE = (
        "resolution {h:g} m would need {nodes:.1e} grid nodes ({why}); the finest this machine can "
        "hold is ~{h_min_mm:.2g} mm; use a coarser {option}"
    )
    GRID_NODES = "more than the {limit:.0e} nodes one sweep may take"
    EMPTY_STROKE = "the stroke workspace at orientation {orientation} rad is empty (no common point of the legs' reach)"
    RESOLUTION = "resolution must be a positive number of metres, got {value}"
    BOUNDS = "bounds must be [[xmin, xmax], [ymin, ymax], [zmin, zmax]] metres with min < max, got {value}"
    NOTHING_REACHABLE = (
        "no reachable position at orientation {orientation} rad with limits {limits} at resolution {h} m"
    )
    CONE = "Limits.{name} must be an angle in (0, pi] rad, got {value}"
    LEG_DIAMETER = "Limits.leg_diameter must be a positive length in metres, got {value}"
    MAX_CONDITION = "Limits.max_condition must be > 1, got {value}"
    AXES = "Limits.{name} must be six non-zero 3-vectors, shape (6, 3), got {shape}"
    ORIENTATION = "orientation must be 3 finite angles (rad) about X, Y, Z, got {value}"
    PLANE = "plane must be 'xy', 'xz' or 'yz', got {value!r}"
    GRIDS = "grids must be six non-empty 1-D arrays (px, py, pz, a_x, a_y, a_z), got {n}"
    SPACE_DOF = "space_dof (lambda) must be 3 (planar) or 6 (spatial), got {value}"
    JOINTS = "need n_links >= 1 and every joint freedom in 1..{space_dof}, got n = {n}, f = {f}"
    LEG_TYPE = "unknown leg type {kind!r}; expected one of {valid}"
    POSITION = "position must be 3 finite coordinates in metres, got {value}"
    CENTRE = "rotation centre must be 3 finite coordinates in metres (plate frame), got {value}"
    STEP = "step must be in (0, max_angle), got step = {step} rad, max_angle = {max_angle} rad"
    START_OUTSIDE = "start pose {pose} is outside the {limit} limit (margin {margin:.4g} {unit})"
    DEXTERITY_POSES = "the dexterity limit needs the poses themselves"


# ----------------------------------------------------------------------------------------------
# Input/output errors and message templates (files, options, output folders).


class InputError(StewartError):
    """A file or option the user gave is unreadable or malformed (YAML, CSV, a path)."""

    PROGRAM_MISSING = "program file {path!r} does not exist"
    PROGRAM_NOT_FILE = "program file {path!r} is {what}, not a file"
    PROGRAM_TOO_LARGE = "{path}: larger than the {limit}-byte limit for a program"
    PROGRAM_NOT_TEXT = "{path}: not UTF-8 text (byte {offset})"
    PROGRAM_NUL = "{path}:{line}: a NUL byte; not a program text file"
    INPUT_MISSING = "{kind} file {path!r} does not exist"
    INPUT_FOLDER = "{kind} file {path!r} is a folder, not a file"
    INPUT_UNREADABLE = "{kind} file {path!r}: cannot read it ({reason})"
    INPUT_TOO_LARGE = "{kind} file {path!r}: larger than the {limit}-byte limit for a {kind} file (read that far)"
    INPUT_NOT_TEXT = "{path}:{line}: not UTF-8 text (byte {offset}); not a {kind} file?"


class OutputError(StewartError):
    """An output destination is refused by the output policy (``atomic``) or cannot be written."""

    REFUSED_PLACE = "{option} {typed!r}: refusing to write into {what}; give a new folder name"
    NOT_A_FOLDER = "{option} {typed!r}: {part!r} exists and is not a folder"
    SYMLINK = "{option} {typed!r}: is a symbolic link; give the real folder"
    NOT_OURS = (
        "{option} {typed!r}: the folder {why} (e.g. {example!r}, {count} file(s)); {remedy} "
        "(files not written by stewart-drake are never touched)"
    )
    # what the refused command offers instead: its --force (or the API's force=True), else a folder of its own
    REMEDY_FORCE = "give a new or empty folder, or {force} to write beside them"
    REMEDY_OWN = "give a new or empty folder, or one that `{command}` wrote itself"
    UNWRITABLE = "{option} {typed!r}: cannot write there ({reason})"
    BUSY = "{option} {typed!r}: another stewart-drake run is writing there; wait for it to end or give another folder"
    BAD_PATH = "{option} {typed!r}: not a usable path"
    CLASH = "{option} {typed!r}: {name!r} exists and was not written by stewart-drake; nothing was written"
    CLASH_OTHER = (
        "{option} {typed!r}: {name!r} exists, written by `{other}`; files are written beside another command's, "
        "never over them: nothing was written; give a new or empty folder"
    )
    FILE_IS_FOLDER = "{option} {typed!r}: is a folder; give a file name"
    FILE_NOT_REGULAR = "{option} {typed!r}: exists and is not a regular file"
    FILE_NOT_OURS = (
        "{option} {typed!r}: the file exists and was not written by stewart-drake; "
        "remove it or choose another name (it is never overwritten)"
    )
    MANIFEST_DAMAGED = (
        "{option} {typed!r}: its manifest {manifest} is damaged ({reason}); nothing there can be verified as "
        "written by stewart-drake: give a new folder, or remove the manifest yourself"
    )
    OTHER_COMMAND = (
        "{option} {typed!r}: {name!r} was written by `stewart-drake {other}` ({count} file(s)); `{command}` "
        "replaces only its own files: {remedy}"
    )


class YamlError(GeometryError, InputError):
    """A YAML file is unreadable, too large, too deep, or not in the schema. Messages start with
    ``file:line:`` where known and name the field (``plate.mass``) and the value as written."""

    TOO_LARGE = "{path}: larger than the {limit}-byte limit for a {kind} file"
    SYNTAX = "{path}:{line}: YAML syntax error: {problem}"
    NOT_TEXT = "{path}: not UTF-8 text (byte {offset})"
    TOO_DEEP = "{path}:{line}: nesting deeper than {limit} levels"
    TOO_MANY_NODES = "{path}: more than {limit} values after expanding aliases (an alias bomb?)"
    TAG = "{path}:{line}: tag {tag!r} is not allowed (plain YAML values only)"
    TOP = "{path}: a {kind} file must be a mapping of keys to values, got {got}"
    UNKNOWN_KEY = "{path}:{line}: {field}: unknown key{hint}; valid keys: {valid}"
    DUPLICATE_KEY = "{path}:{line}: {field}: key given twice"
    WRONG_TYPE = "{path}:{line}: {field}: expected {expected}, got {value}"
    BAD_VALUE = "{path}:{line}: {field}: {value} {problem}"
    MISSING = "{kind} file {path!r} does not exist"
    NOT_A_FILE = "{kind} file {path!r} is a folder, not a file"
    UNIT = "{path}:{line}: length_unit: unknown length unit {value!r}; use m or mm"
    RECURSIVE_ALIAS = "{path}:{line}: an alias refers to the value that contains it"


class CsvError(InputError):
    """A CSV file is malformed: messages name the file and the line (counted from 1)."""

    FIELD_TOO_LONG = "{path}:{line}: a field is longer than {limit} characters; not a {kind} file?"
    SYNTAX = "{path}:{line}: {problem}"
    NOT_TEXT = "{path}:{line}: not UTF-8 text"
    NOT_NUMBER = "{path}:{line}: column {column}: not a number: {value!r}"
    WIDTH = "{path}:{line}: expected {expected} values ({columns}), got {got}"
    NOT_FINITE = "{path}:{line}: column {column}: values must be finite, got {value!r}"
    EMPTY = "{path}: no {kind} rows"
    MISSING = "{kind} file {path!r} does not exist"
    IS_FOLDER = "{kind} file {path!r} is a folder, not a file"
    TOO_FEW = "{path}: need at least {need} samples, got {got}"
    TIMES = "{path}: times must increase; sample {k} (t = {t} s) does not follow t = {t_prev} s"
    LINE_TOO_LONG = "{path}:{line}: a line longer than {limit} bytes; not a {kind} file?"
    HEADER_UNKNOWN = (
        "{path}:{line}: the first line is a header (not all numbers), but {name!r} names no column of a {kind} file; "
        "name the columns {columns} (any order) or leave the header out"
    )
    HEADER_REPEATED = "{path}:{line}: the header ({header}) names {name} twice; a {kind} file's columns are {columns}"


class ReportSubjectError(InputError):
    """A machine file the report reads has a field it cannot use (``report.subject``)."""

    FIELD = "{path}: {field}: {problem}"
    MOTION = "{path}: motions item {item}: {value!r} is not seed, rotating, or a .csv or .stw file beside it"


class UsageError(StewartError):
    """Options that contradict each other or are ignored (e.g. ``--json`` without ``--inspect``)."""

    NEEDS = "{option} only applies with {needs}"
    FIRMWARE_OPTIONS = (
        "{file} was generated with other options ({mismatch}): the check would compare it with another module's "
        "emulation; leave the option out to use the recorded one"
    )
    NOT_BOTH = "give {first} or {second}, not both"
    NOT_FINITE = "{option}: must be a finite number, got {value}"
    # argparse prefixes these with "argument --option:" (option values that are not numbers)
    NOT_A_NUMBER = "not a number: {value!r}"
    NOT_FINITE_NUMBER = "must be a finite number, got {value!r}"
    NOT_WHOLE = "not a whole number (at most 18 digits): {value!r}"
    INTERNAL = "internal error ({kind}: {detail}); please report it with the command line"
    LEGS_CORIOLIS = "--legs on computes the complete model; it cannot be combined with --coriolis off"
    ENGINE_C = "--engine c runs the fixed-point controller; --controller is {controller!r}"
    MACHINE_AS_PLATFORM = (
        "--platform {path}: a machine file (payload, controller, firmware, ...); give it as {use} {path}"
    )
    MEASUREMENTS = "--measurements is required: --platform {platform} is not a machine file naming them in calibration:"


class OptionError(UsageError):
    """One option's value is outside the range the command accepts; the message names the option and the
    value as typed."""

    AT_LEAST = "{option} must be >= {min}, got {value}"
    POSITIVE = "{option} must be a positive number of {unit}, got {value}"
    POSITIVE_LENGTH = "{option} must be a positive length, got {value}"
    BETWEEN = "{option} must be between {lo} and {hi}, got {value}"
    GRAVITY = "{option} must be a finite number >= 0 m/s², got {value}"
    UNKNOWN_LIMIT = "{option}: unknown limit {value!r}; choose from {valid}"
    DT = "{dt_name} must be > 0 and {t_end_name} >= 0, got dt = {dt}, t-end = {t_end}"
    TOO_MANY_SAMPLES = "{t_end_name} / {dt_name} = {n} samples, more than {limit}"
    NO_STUDY = "--replay: {out!r} holds no finished study ({file} missing); run the study first"
    NO_RUN = "--replay {run}: the study in {out!r} has runs 0 … {last}"
    BAD_STUDY = "--replay: {path} is not a study written by stewart-drake montecarlo ({reason})"
    REPLAY_OTHER = (
        "--replay {run}: the options describe another study than the one in {out!r} ({diff}); "
        "--replay K --out DIR alone replays the stored study"
    )


class EngineError(UsageError):
    """A cross-check asked of a physics engine that is not installed, or of none (``stewart_drake.engines``)."""

    MISSING = "--engine {name}: {reason}"
    NONE = "no physics engine to cross-check with: {reasons}"
    TOO_MANY = "{option} {value} is more than {limit} (each is one engine evaluation per engine)"
    UNKNOWN = "--engine: unknown engine {value!r}; choose from {valid}"


class ArgumentError(UsageError):
    """An argument of the public API of the wrong kind: text or ``None`` for numbers, complex values, a
    fraction for a count, a name that is not one of the choices, a non-platform for a platform."""

    NOT_NUMBERS = "Expected {name} to be real numbers, got {value}"
    NOT_NUMBER = "Expected {name} to be one real number, got {value}"
    COMPLEX = "Expected {name} to be real numbers, got complex values {value} (the imaginary part is not dropped)"
    NOT_INT = "Expected {name} to be a whole number{bounds}, got {value}"
    CHOICE = "Expected {name} to be one of {choices}, got {value}"
    NOT_BOOL = "Expected {name} to be True or False, got {value}"
    NOT_TEXT = "Expected {name} to be {what} (text), got {value}"
    NOT_PLATFORM = "Expected {name} to be a Platform (see load_platform), got {value}"


# motion cueing (``api.cueing``): a drive that is neither a Drive, a shipped drive's name nor a file; a parameter
# file given to the MPC law (its parameters are an ``MpcParams``)
CUE_DRIVE = "{name} {value}: neither a shipped drive ({names}) nor a drive file (.csv, .parquet)"
CUE_PARAMS = "{name} {value}: a parameter file holds classical washout parameters; mpc takes an MpcParams"
CUE_PARAMS_TYPE = "Expected params to be {what} for algorithm {algorithm!r}, got {value}"


# ----------------------------------------------------------------------------------------------
# The motion language (``script``): templates of ``script.errors.ScriptError`` messages, which the
# diagnostics print as ``file:line:column: error: message``.

SCRIPT_SYNTAX = "unexpected {found}; expected {expected}"
SCRIPT_RESERVED = "{word!r} is a reserved word (Modula-2, kept from seed 004's Stewart.g) and cannot be used yet"
SCRIPT_UNDEFINED = "undefined variable {name!r}"
SCRIPT_NEVER_ASSIGNED = "undefined variable {name!r}: it is never assigned in this program"
SCRIPT_MOVE_ARITY = "{kw} takes 6 arguments (x, y, z, alpha, beta, gama), got {n}"
SCRIPT_MOVE_UNKNOWN_ARG = "{kw} has no argument {name!r}; its arguments are x, y, z, alpha, beta, gama"
SCRIPT_MOVE_DUPLICATE_ARG = "{kw}: argument {name!r} given twice"
SCRIPT_MOVE_POSITIONAL_AFTER_KEYWORD = "{kw}: positional argument after a keyword argument"
SCRIPT_FUNC_ARITY = "{name}() takes {expected} argument{s}, got {n}"
SCRIPT_FUNC_UNKNOWN = "unknown function {name!r}; available: {available}"
# (the messages the motion language's parser, checker, interpreter and runtime raise)
SCRIPT_UNREACHABLE = (
    "{what} is out of reach on platform {platform}: leg {leg} would be {excess:.3f} mm "
    "{side} the stroke {bound} {limit:.3f} mm (length {length:.3f} mm at t = {t:.3f} s{where})"
)


SCRIPT_EMIT = "the program cannot be translated to valid Python ({kind}: {problem})"
SCRIPT_TOO_MANY_STEPS = (
    "the program ran more than {limit} steps (statements and loop iterations); does a loop never end?"
)
SCRIPT_LOOP_STEPS = (
    "this FOR loop would run {count} iterations, at least {steps} steps with its body; a program may run "
    "at most {limit} steps (statements and loop iterations)"
)
SCRIPT_LOOP_MOVES = "this FOR loop would make {moves} moves and waits; a program may make at most {limit}"
SCRIPT_NO_FINITE_VALUE = "{name}({args}) has no finite value"
SCRIPT_DIVISION_BY_ZERO = "division by zero ({a} {op} 0)"
SCRIPT_OVERFLOW = "arithmetic overflow: {a} {op} {b} is not finite"
SCRIPT_CANNOT_PARSE = "cannot parse: {problem}"
SCRIPT_EXPRESSION_DEPTH = "expression nested more than {limit} levels deep"
SCRIPT_NUMBER_TOO_LARGE = "number {text} is too large"
SCRIPT_STATEMENT_DEPTH = "statements nested more than {limit} levels deep"
SCRIPT_LOOP_DEPTH = "loops (FOR, WHILE) nested more than {limit} levels deep"
SCRIPT_NOT_A_NUMBER = "{what} must be a number, got {value!r}"
SCRIPT_NOT_FINITE = "{what} must be finite, got {value}"
SCRIPT_UNIT = "units: {name!r} is not a unit; expected {lengths} (length), {angles} (angle)"
SCRIPT_TWO_UNITS = "units: two {kind} units given"
SCRIPT_DURATION = "{keyword} duration must be positive, got {value} s"
SCRIPT_TOO_SHORT = (
    "{keyword} duration {value} s is shorter than the shortest move, {limit} s (no actuator follows a faster one)"
)
SCRIPT_WAIT = "wait duration must be >= 0, got {value} s"
SCRIPT_TOO_MANY_MOVES = (
    "the program makes more than {limit} moves and waits (the limit); shorten it or use longer moves"
)
SCRIPT_SEGMENT_SAMPLES = (
    "{what} lasts {duration} s, more than the {limit} samples a program may have at {rate} Hz ({seconds} s)"
)
SCRIPT_TOO_MANY_SAMPLES = (
    "trajectory too long: {total} samples ({seconds} s at {rate} Hz; the limit is {limit}); lower the "
    "rate or shorten the program"
)
SCRIPT_START_OUT_OF_REACH = (
    "the start pose is out of reach on platform {platform}: leg {leg} length {length_mm:.3f} mm is "
    "outside the stroke [{lo_mm:.3f}, {hi_mm:.3f}] mm"
)
SCRIPT_MORE_UNREACHABLE = "... and {more} more unreachable moves"
SCRIPT_BELOW_BASE = (
    "{what} puts the plate {where} the base on platform {platform}: the plate anchor of leg {leg} "
    "is at z = {z_mm:.3f} mm at t = {t:.3f} s (the base plane is z = 0)"
)
SCRIPT_SINGULAR = (
    "{what}: the platform is singular or nearly so at t = {t:.3f} s (Jacobian condition number "
    "{cond:.3g} > {limit:.3g}); leg forces are undefined there"
)
SCRIPT_FOR_STEP_ZERO = "FOR step is 0: the loop would never end"


# ----------------------------------------------------------------------------------------------
# Physical sanity and bounded work (``sanity``). A ``PhysicalLimitError`` is a result outside the
# platform's physical limits (exit 1); a ``WorkTooLargeError`` is a request too big to run (exit 2).


class PhysicalLimitError(StewartError):
    """A well-formed request whose answer lies outside physical limits (plate below the base, a leg
    out of stroke along a trajectory, lost tracking, a saturated leg): the CLI exits 1."""

    exit_code = 1


class WorkTooLargeError(StewartError):
    """A user-controlled size (resolution, duration, rows, iterations) whose memory or time estimate
    exceeds what the tool allows; raised before anything is allocated."""


BELOW_BASE = (
    "{what}: the plate is {where} the base: plate anchor {anchor} is at z = {z_mm:.3f} mm (the base plane is z = 0); "
    "a platform whose plate may go below its base says so with 'plate_below_base_allowed: true'"
)
FAR_POSITION = (
    "{what}: position {pos_m} m is {ratio:.3g} × the platform's size ({size_m:.3f} m); positions beyond "
    "{limit:g} × are surely a unit mistake (a file in mm read as metres? use {hint})"
)
NOT_FINITE = "{what} must be finite, got {value}"
NOT_POSITIVE = "{what} must be a positive number{unit}, got {value}"
GRAVITY_RANGE = "{option} {value} m/s² is beyond ±100 m/s² (10 g); is it in m/s²?"
FAR_CENTRE = (
    "{option} {centre} m is {ratio:.3g} × the platform's size ({size_m:.3f} m) from the plate; "
    "centres beyond {limit:g} × are surely a unit mistake (the centre is in metres)"
)
SERVO_NEUTRAL = (
    "{what}: servo {servo}'s neutral pulse {value} µs is outside [{lo:.0f}, {hi:.0f}] µs: with its travel of "
    "±{swing:.0f} µs the pulse must stay within an RC servo's {range_lo:.0f}-{range_hi:.0f} µs"
)
OUT_OF_STROKE = (
    "{what} leaves the stroke: first at t = {t:.4f} s, leg {leg} length {length_mm:.3f} mm is {excess_mm:.3f} mm "
    "{side} the stroke {bound} {limit_mm:.3f} mm{hint}"
)
NO_PLATE = (
    "platform {name!r} has no plate mass properties (YAML key 'plate' missing, or its mass is 0): "
    "'{command}' needs plate.mass and plate.inertia (or plate.thickness and plate.density for a utn platform)"
)
PLATE_TOO_LIGHT = (
    "platform {name!r}: the plate's mass {mass:.6g} kg (plate.mass, or plate.thickness x plate.density) is below "
    "{ratio:g} of the legs' moving mass {legs:.6g} kg (6 x (legs.cylinder_mass + legs.piston_mass)): the plant's "
    "ball joints would open instead of carrying the legs; '{command}' needs at least {minimum:.3g} kg"
)
SINGULAR_HOME = (
    "platform {name!r} is singular at its home pose (Jacobian condition number {cond:.3g} > {limit:.0e}): {why}"
)
WORK_UNBOUNDED = "{option} {value} would need unboundedly many {what}{hint}"
WORK_TOO_LARGE = "{option} {value} would need {estimate}; the limit is {limit}{hint}"


# --- control
class TimingError(StewartError):
    """A DSP timing configuration that cannot run (the computation does not fit in the sample period)."""


INFEASIBLE_TIMING = (
    "infeasible DSP timing: one controller tick needs {cycles} cycles = {t_comp_us:.3f} µs at {clock_mhz:g} MHz, "
    "longer than the sample period {period_us:.3f} µs"
)
PLANT_STEP_TOO_LONG = (
    "run.plant_step {step} s is longer than the controller period {period} s; "
    "the plant step must resolve the period (at most one period)"
)
PLANT_STEP_ABOVE_LAG = (
    "run.plant_step {step} s is longer than the actuators' time constant {lag} s, "
    "the platform's fastest modelled dynamics; use a step of at most that"
)
PERIOD_TOO_SLOW = (
    "controller.period {period} s is too slow for platform {name}: its fastest open-loop mode grows at "
    "{lam:.3g}/s, and the leg loops' crossover at this period is at most {w_c:.3g} rad/s (< {margin:g} × "
    "{lam:.3g}); use a period of at most ~{t_max:.3g} s"
)


# --- remaining modules: rotations, Newton FK, gains, simulation, firmware, command options
class RotationError(StewartError):
    """An unknown rotation convention or unit, or an angle/pose/quaternion array of the wrong shape
    (``core.rotations``)."""

    CONVENTION = "unknown rotation convention {value!r}; expected one of {valid}"
    ANGLE_UNIT = "unknown angle unit {value!r}; expected one of {valid}"
    LENGTH_UNIT = "unknown length unit {value!r}; expected one of {valid}"
    POSE_SHAPE = "a pose needs 6 numbers (px, py, pz, a_x, a_y, a_z), got shape {shape}"
    ANGLES_SHAPE = "angles need 3 numbers (about X, Y, Z), got shape {shape}"
    QUATERNION_SHAPE = "quaternions need 4 numbers (w, x, y, z), got shape {shape}"


class FkInputError(StewartError):
    """Forward kinematics was given malformed lengths, initial poses or solver options (``core.newton_fk``,
    ``core.assembly_modes``, ``drake.program_fk``)."""

    ON_SINGULAR = "on_singular must be 'raise', 'warn' or 'ignore', got {value!r}"
    LENGTHS_SHAPE = "leg lengths must have shape (..., 6), one per leg, got {shape}"
    LENGTH_VALUE = "lengths sample {index}: leg {leg} length {value} m is not a positive finite number"
    POSITIVE = "{name} must be a positive finite number, got {value!r}"
    MAX_ITER = "max_iter must be a positive integer, got {value!r}"
    INITIAL_SHAPE = "initial pose must have shape (6,) or (..., 6), got {shape}"
    INITIAL_NOT_FINITE = "initial pose must be finite, got {value}"
    INITIAL_BROADCAST = "initial poses of shape {shape} do not match lengths of shape {lengths_shape}"
    INITIAL_SIX = "initial pose must be 6 finite numbers, got {value}"
    ONE_SET = "{what} takes one length set of shape (6,), got {shape}"
    ENGINE = "engine must be 'auto', 'c' or 'numpy', got {value!r}"
    NO_COMPILER = "engine 'c' asked for, but no C compiler is available (engine 'auto' runs the numpy path)"
    ROTATION = "unknown rotation parametrisation {value!r}; expected one of {valid}"
    SOLVER = "unknown solver {value!r}; expected one of {valid}"
    POLISH = "polish must be one of {valid} or None, got {value!r}"


class SamplingError(StewartError):
    """A pose-sampling request that names an unknown region or finds too few reachable poses (``core.sampling``)."""

    REGION = "unknown pose region {value!r}; expected one of {valid}"
    TOO_FEW = "platform {name!r}: could not sample {n} reachable poses around home ({region!r} region)"


class GainError(StewartError):
    """Controller gains or their design inputs are not usable (``control.gains``)."""

    PID_NEGATIVE = "the controller's {name} gain must be a finite number >= 0, got {value!r}{hint}"
    PID_FILTER = "the controller's {name} must be in (0, 1], got {value!r}"
    ACTUATOR_LAG = "actuator_lag must be >= 0 s, got {value!r}"
    INERTIA = "platform {name!r}: the leg-space inertia is not positive definite (smallest eigenvalue {m_min:.3g} kg)"
    DESIGN_POSE = "design pose {index} is not finite: {value!r}"
    GAIN = "a gain must be a finite number >= 0, got {value!r}"
    Q15_RANGE = "gain {value!r} is too large for a Q15 mantissa with a 32-bit shift"
    Q15_SCALE = (
        "the {name} gain {value:.4g} (SI) does not fit the firmware's Q15 words with a command range of "
        "{range:.4g} N (legs.max_force), a sensor count of {r:.4g} m and a period of {T:.4g} s; "
        "a command range this small (or a count this large) is not a usable actuator"
    )
    SENSOR_COUNTS = (
        "sensor_resolution {r} m must divide the IK's length LSB {lsb} m into a whole number of counts "
        "for the fixed-point controller"
    )
    COUNTS_PER_LSB = (
        "the IK's length LSB {lsb:g} m (--length-lsb) is {cpl:.4g} sensor counts of {r:g} m (--sensor-resolution): "
        "one LSB step would not fit the firmware's 16-bit error word (at most {limit} counts); use a smaller "
        "--length-lsb or a coarser sensor resolution"
    )


# DspTiming fields (``control.timing``), raised as ``TimingError``.
TIMING_POSITIVE = "the controller's {name} must be a positive number, got {value!r}"
TIMING_LATENCY = "DspTiming.latency must be one of {valid}, got {value!r}"
TIMING_CYCLES = "DspTiming.computation_cycles must be a positive integer, got {value!r}"


class TrajectoryError(InputError):
    """A reference trajectory that cannot be built: unknown name, bad CSV times, a bad design duration
    (``core.trajectory``)."""

    NO_RATES = "trajectory {name!r} has no closed-form rates"
    TIME_ORDER = "{path}:{line}: time {t} s is not after the previous sample's {t_prev} s"
    DESIGN_DURATION = "design duration must be a number of seconds >= 0, got {value!r}"
    UNKNOWN = "unknown trajectory {value!r}: not one of {valid} and not a CSV file"
    QUANTISED = (
        "{path}: column {column} is rounded too coarsely for its motion: steps of {quantum} {qunit} at {rate} "
        "samples/s imply {noise:.3g} {unit} RMS of acceleration noise (step/(√2·h²)) against {motion}; give "
        "{option} TOL (a smoothing spline within TOL RMS of the samples, in the file's units: e.g. its "
        "rounding step) or write more decimals"
    )
    RATE = (
        "{path}: column {column} goes from {a} to {b} (SI) between t = {t0} and {t1} s: its rate is not a finite "
        "number (a value in the wrong unit or a corrupt cell?)"
    )
    SMOOTH_TOL = "{option}: the tolerance must be a finite number > 0 (in the file's units), got {value!r}"


class ResponseError(StewartError):
    """A loop-response request with values outside what it accepts (``api.response``); its ``UNSTABLE``,
    ``GAIN_MARGIN``, ``PHASE_MARGIN`` and ``DISAGREES`` are the verdict's failures (exit 1), not raised."""

    LEG = "leg must be 1 … 6, got {value!r}"
    AMPLITUDE = "amplitude must be a positive number of metres, got {value!r}"
    COUNT = "{name} must be 1 … {limit} frequencies, got {count}"
    FREQUENCY = "{name}: frequency {index} must be in (0, {nyquist:g}) Hz (below the Nyquist frequency), got {value!r}"
    PLANT_STEPS = (
        "run.plant_step {step:g} s must divide controller.period {period:g} s into whole steps for the loop's model"
    )
    MEASURE_WORK = (
        "measure: {count} frequencies need {seconds:.0f} s of closed-loop simulation (the loop settles slowly), "
        "more than {limit:g} s; measure fewer"
    )
    UNSTABLE = "the linearised closed loop is unstable: largest pole |z| = {rho:.6f} >= 1"
    GAIN_MARGIN = "gain margin {value:.2f} dB is below the minimum {minimum:g} dB"
    PHASE_MARGIN = "phase margin {value:.1f} deg is below the minimum {minimum:g} deg"
    DISAGREES = "measured response at {f:g} Hz differs from the linear model by {d:.4f} (per unit), above its tolerance {tol:.4f}"


class TuneError(StewartError):
    """A ``tune`` request with values outside what it accepts (``api.tune``); its ``NO_GAINS``, ``NO_FORMAT``,
    ``RIPPLE`` and ``VERIFY`` are the verdict's failures (exit 1), not raised."""

    MARGIN = "{name} must be a number {rule}, got {value!r}"
    BANDWIDTH = "bandwidth must be a positive frequency below the Nyquist frequency {nyquist:g} Hz, got {value!r}"
    OUT_IS_MACHINE = "out {path} is the machine file itself: the original is never modified; name another file"
    OUT_EXISTS = "out {path} exists; name a new file, or pass --force to replace it"
    OUT_FOLDER = "out {path} is a folder; name the machine file to write"
    PLANT_STEPS = (
        "run.plant_step {step:g} s must divide controller.period {period:g} s into whole steps for the loop's model"
    )
    NO_POSES = "no pose of the workspace box's grid keeps the legs within the stroke of {name}"
    NO_GAINS = (
        "no gains of the {count} tried meet GM >= {gm:g} dB, PM >= {pm:g} deg{bw} at every grid pose; the best: "
        "GM {best_gm:.2f} dB, PM {best_pm:.1f} deg, bandwidth {best_bw}"
    )
    NO_FORMAT = (
        "no length LSB of {bits}-bit words (a whole number of {r:g} m sensor counts) is proven free of saturation"
    )
    RIPPLE = (
        "predicted ripple {rms:.4g} N RMS is above the chatter limit {limit:.4g} N ({fraction:g} % of the command "
        "range) for every feasible gain set; the largest source: {cause}"
    )
    BUDGET = "the certified IK error {error:.3g} mm of the finest proven LSB is above the budget {budget:g} mm"
    VERIFY = "the tuned machine's run failed: {failure}"


class SimulationError(StewartError):
    """A simulation or Drake model request with values outside what it accepts (``drake.simulation``,
    ``drake.systems``, ``drake.*_model``)."""

    MAX_FORCE = "ActuatorModel.max_force must be a positive number of newtons, got {value!r}"
    TIME_CONSTANT = "ActuatorModel.time_constant must be >= 0 s, got {value!r}"
    DURATION = "duration must be a positive number of seconds, got {value!r}"
    PLANT_STEP = "plant_time_step must be a positive number of seconds, got {value!r}"
    LEG = "leg must be 0 … 5, got {value!r}"
    STEP = "step must be a non-zero number of metres, got {value!r}"
    ENGINE = "engine must be 'python' or 'c', got {value!r}"
    FIRMWARE_LAW = "a firmware file runs the fixed-point controller; controller {kind!r} has no firmware"
    CONTROLLER = "controller must be {valid}, got {value!r}"
    DISCRETE_STEP = "time_step must be > 0 (ball constraints need a discrete plant), got {value}"
    TIME_STEP = "time_step must be > 0, got {value}"
    SERVO_POSES = "compare_with_drake needs reachable in-travel poses; pose {index} is not: {why}"
    FRAME_RATE = "servo frame rate must be > 0 Hz, got {value}"
    CLOSED_LOOP_SHAPES = (
        "run_closed_loop needs times (n,) and poses (n, 6) with n >= 2, got {times_shape} and {poses_shape}"
    )
    SPRING = "leg {leg}: static force {force:.6g} N compresses a {k:.6g} N/m spring past zero length"
    SERVO_SPEED = (
        "reference arm speed {rate:.3g} rad/s reaches the servo's no-load speed "
        "{speed:.3g} rad/s: the tracking bound does not apply"
    )
    PORT = "--port {port}: Meshcat could not listen there ({reason})"


class IsolationError(StewartError):
    """User code run in a child process (``system.isolate``) failed: it hung, ended the process, or crashed."""

    HUNG = (
        "{path}: the firmware did not return within {limit:g} s (an endless loop in sd_ik, sd_tick or a "
        "constructor?); stopped"
    )
    EXITED = (
        "{path}: the firmware ended the process (exit status {code}) instead of returning; a firmware must "
        "not call exit() (in sd_ik, sd_tick or a constructor)"
    )
    CRASHED = "{path}: the firmware crashed ({signal}: e.g. a bad pointer or an array index out of range)"
    MEMORY = "{path}: the firmware ran out of its memory limit ({limit} of address space); stopped"


class FirmwareError(StewartError):
    """Generated or user firmware that cannot be built, checked or run (``firmware``, ``drake.firmware_check``)."""

    DESIGN_POSES = (
        "{path}: {reason}; {where} was generated from the Python Trajectory {name!r}, whose design poses (the gains' "
        "reference) it holds: keep it beside the module as generated, or give trajectory= that same Trajectory"
    )

    SENSOR_GAINS = (
        "platform {name!r}: legs.length_gain {gains} is not 1: the controller's sensor path (the firmware, its "
        "emulation, the simulated sensor) adds legs.length_offset but has no gain; calibrate without --gains, or "
        "scale the sensors' resolution"
    )

    POSES = "--poses must be an integer in 1..{limit}, got {value!r}"
    DURATION = "--duration must be in (0, 60] s, got {value!r}"
    NO_IK = "{path}: defines no sd_ik (the firmware ABI: int sd_ik(const sd_word pose[6], sd_word lengths[6]))"
    NO_TICK = "firmware {name} does not define sd_init and sd_tick"
    UNDEFINED = "{path}: {symbol} is used but defined nowhere (the compiled library does not load)"
    FILE_NO_NAME = "{what} {path!r}: give the name of a C file"
    FILE_MISSING = "{what} {path!r} does not exist"
    FILE_FOLDER = "{what} {path!r} is a folder, not a C file"
    FILE_SPECIAL = "{what} {path!r} is not a regular file"
    SENSOR_COUNTS = "measured leg lengths {value} m do not fit the firmware's 32-bit sensor counts"
    ENGINE = "--engine must be one of {valid}, got {value!r}"
    WORD_BITS = "generated C takes word_bits 8..16 (16-bit data words, 32-bit accumulators), got {value}"
    SINE_TABLE = "the quarter-wave sine table does not reproduce the exact trig at angle word {index}"
    TARGET = "--target must be one of {valid}, got {value!r}"
    NO_CROSS = "firmware build --target {target}: {tool} not found on PATH (install {package})"
    CROSS_FAILED = "firmware build --target {target}: {step} failed: {detail}"
    LINK_SILENT = "PIL link: no answer to {what} within {timeout:g} s"
    LINK_REFUSED = (
        "PIL link: the target (link version {version}, format fingerprint {fingerprint}) refused the handshake of "
        "this host (version {our_version}, fingerprint {ours}): rebuild it from the same module and options"
    )
    NO_QEMU = "pil.target {target}: {tool} not found on PATH (install {package})"
    PIL_START = "pil.target {target}: {what} cannot be started or opened: {detail}"
    PIL_LAW = "pil.target {target} runs the fixed-point firmware (controller.law fixed), not the {law} law"
    PIL_GONE = "PIL link: the target closed the link at tick {tick}"


class IntegratorError(StewartError):
    """An unknown integrator name (``drake.integrators``)."""

    UNKNOWN = "integrator must be one of {valid}, got {value!r}"


class ReplayError(StewartError):
    """A replay log that cannot be read (``drake.viewer``)."""

    EMPTY_FOLDER = "--replay {path}: no log.npz, simulation/log.npz, trajectory.csv or log.csv in the folder"
    MISSING = "--replay {path}: no such file"
    NOT_LOG = "--replay {path}: not a simulate log ({reason})"
    EMPTY = "--replay {path}: empty file"
    COLUMNS = "--replay {path}: line 1: expected the columns of a simulate log.csv or a run trajectory.csv, got {got}"
    ROW = "--replay {path}: line {line}: not a row of numbers"
    NO_SAMPLES = "--replay {path}: no samples"


class SpecError(StewartError):
    """A ``--vary`` SPEC that cannot be read: unknown key, bad value, unit or range (``montecarlo.spec``)."""

    NUMBER = "{where}: {key}: cannot read {text!r} as a number with a unit ({allowed})"
    NOT_FINITE = "{where}: {key}: {text!r} is not finite"
    LATENCY = "{where}: latency: {value!r} is not one of {valid}"
    NEGATIVE_PROCESS = "{where}: {key}: {text!r} must be >= 0 (the size of a per-tick random process)"
    PERCENT_OF_ZERO = "{where}: {key}: {text!r}: a percentage of a zero nominal; give ±value with a unit"
    PERCENT_RANGE = "{where}: {key}: {text!r}: the percentage must be in [0, 100)"
    HALF_WIDTH = "{where}: {key}: {text!r}: the half-width must be >= 0"
    RANGE_ORDER = "{where}: {key}: {text!r}: the range's low end is above its high end"
    UNKNOWN_KEY = "{where}: unknown key {key!r}{hint}"
    VECTOR_LAW = "{where}: {key}: give ±tolerance (per component) or a fixed offset, not {text!r}"
    NOT_KEY_VALUE = "{where}: {value!r} is not key=value"
    MISSING_FILE = "{where}: file {path!r} does not exist"
    NOT_YAML = "{path}:{line}: not YAML ({problem})"
    NOT_MAPPING = "{path}: the SPEC must be a mapping of key: value"
    DUPLICATE = "{where}: {key!r} is given twice (first on line {first}); give each key once"
    NOT_SCALAR = "{where}: {key}: the value must be one scalar (e.g. ±0.5mm)"
    KEY_NOT_TEXT = "{where}: a key must be a name (one of the keys), got {key}"
    RENAMED = "{where}: the key {key!r} is no longer read: {why}"
    VECTOR_3 = "{where}: {key}: {text!r}: a fixed vector is three numbers X,Y,Z"
    SWEEP_VECTOR = "sweep: {key} is a per-component key; sweep scalar keys"
    SWEEP_EMPTY = "sweep: {key} has no values"


class QuantityError(StewartError):
    """A quantity that cannot be read (``spec.quantity``: ``0.5mm``, ``±T``, ``±P%``, ``A..B``, ``a|b``, ``X,Y,Z``)."""

    NUMBER = "{where}: cannot read {text!r} as a number with a unit ({allowed})"
    NOT_FINITE = "{where}: {text!r} is not finite"
    CHOICE = "{where}: {text!r} is not one of {valid}"
    VECTOR = "{where}: {text!r}: expected {n} numbers X,Y,Z (or a list of {n})"
    FORM = "{where}: {text!r}: {form} is not allowed here"
    PERCENT_RANGE = "{where}: {text!r}: the percentage must be in [0, 100)"
    HALF_WIDTH = "{where}: {text!r}: the half-width must be >= 0"
    RANGE_ORDER = "{where}: {text!r}: the range's low end is above its high end"


class MachineError(UsageError):
    """A machine file or override that cannot be read or holds a value out of range (``spec.machine``,
    ``spec.load``); messages name the spec path (``controller.period``)."""

    RANGE = "{path} must be {rule}, got {value}"
    UNKNOWN_KEY = "{where}unknown key {path!r}{hint}"
    NOT_MAPPING = "{where}{path} must be a mapping of key: value, got {got}"
    OVERRIDE = "{text!r} is not PATH=VALUE (e.g. controller.period=0.5ms)"
    KEY = "{where}a key must be a name, got {got}"
    MOTION = "{path}: {value!r} is not seed, rotating, a .csv file or a .stw script"
    PLATFORM = "{where}platform must be a preset name, a platform file or an inline mapping, got {got}"
    FIRMWARE_PLATFORM = (
        "{firmware} was generated for platform {recorded} ({recorded_hash}), not for this run's {platform} "
        "({platform_hash}); regenerate it for this platform"
    )
    SOURCE = "load_machine: expected a path, a mapping or a Platform, got {got}"
    WORD_RANGE = (
        "firmware.length_lsb {lsb} m in {bits}-bit words holds lengths up to {range} m, less than the stroke's end "
        "{longest} m: the loop's set-points would clamp; use a coarser firmware.length_lsb or more firmware.word_bits"
    )
    FORMAT_KEYWORD = "unknown firmware format keyword {name!r}; the keywords are {valid}"
    FORMAT_RATE = "rate must be a positive number of Hz up to 1e6, got {value}"


# the verdict's failure of a PIL run whose controller stopped on a link fault (api.simulation.run_plan)
PIL_STOPPED = (
    "PIL link: tick {stopped_at_tick} got no command from the target ({target}) within pil.timeout; "
    "pil.on_fault stop: zero force from then on"
)
# a warning of a run with a firmware (api.simulation.adopt_firmware)
FIRMWARE_FORMAT_ADOPTED = "loop format adopted from the firmware: {what} (the machine said {machine})"


class StudyError(StewartError):
    """A study that cannot start: too large, inconsistent settings, or an output folder that is not its own
    (``montecarlo.study``)."""

    RUNS = "{runs_opt} must be 1 … {limit}, got {value}"
    SEED = "{seed_opt} must be an integer >= 0, got {value}"
    GRID = "a sweep's runs ({runs}) must equal its grid's points ({points})"
    PLANT_STEP = "plant step must be in (0, 0.01] s, got {value}"
    DURATION = "{duration_opt} must be in (0, {limit:g}] s per run, got {value}"
    MOTION_NOT_STORED = (
        "the study was run from a Python Trajectory ({name!r}), which study.json records only by its hash: "
        "--replay cannot rebuild it; run the study again from Python with the same Trajectory"
    )
    TOTAL = "{runs_opt} {runs} × {duration:g} s = {total:g} simulated s is more than the bound {limit:g} s"
    STEPS = (
        "{plant_step_opt} {step:g} s: {duration:g} s per run is {steps:.3g} plant steps, more than the bound "
        "{limit:.3g}; use a longer {plant_step_opt} or a shorter {duration_opt}"
    )
    TOTAL_STEPS = (
        "{runs_opt} {runs} × {steps:.3g} plant steps = {total:.4g} is more than the bound {limit:.4g}; "
        "use a longer {plant_step_opt} or fewer {runs_opt}"
    )
    RESOLUTION_RANGE = (
        "{vary_opt} sensor_resolution: the fixed-point controller needs resolutions that divide its length LSB; "
        "give a value or a|b|c list, not a range"
    )
    RESOLUTION_DIVIDE = (
        "{vary_opt} sensor_resolution: {value:g} m does not divide the fixed-point IK's length LSB "
        "(firmware.length_lsb {lsb:g} m) into whole counts"
    )
    DRAW = "run {run} (seed {seed}) draws a scenario simulate would refuse ({drawn}): {reason}; no run was started"
    DRAW_ADVICE = " — narrow the {vary_opt} ranges"  # appended to DRAW only when the study draws something
    DRAW_NOMINAL = (
        "the study's nominal scenario (nothing drawn) is one simulate would refuse: {reason}; no run was started"
    )
    OUT_NOT_FOLDER = "{out_opt} {out!r} exists and is not a folder"
    OUT_OTHER_STUDY = "{out_opt} {out!r} holds another study (key {old_key}, this one {key}); choose another folder"
    OUT_NOT_OURS = (
        "{out_opt} {out!r} is a folder this tool did not write (no {study_file} or {partial}); refusing to overwrite it"
    )
    OUT_DAMAGED = "{path}: damaged ({reason}); not a study stewart-drake wrote: remove it or choose another {out_opt}"
    OUT_OTHER_PARTIAL = (
        "{out_opt} {out!r} holds a partial study with another key ({old_key}, this one {key}); choose another folder"
    )


# Command-line options checked by the commands (raised as ``OptionError`` or ``UsageError``).
OPTION_RUN_RATE = "--rate must be a positive number of samples per second, got {value}"
OPTION_NEEDS_BRANCHES = "--{option} needs --check-branches"
OPTION_MAX_ITER = "--max-iter must be >= 1, got {value}"
OPTION_BRANCH_SAMPLES = "--branch-samples must be between 2 and {limit}, got {value}"
OPTION_NON_NEGATIVE = "{name} must be a non-negative number, got {value}"
OPTION_SIMULATE_UTN = "--simulate drives the plant with utn-convention poses; use --convention utn"
OPTION_SIMULATE_EMPTY = "--simulate: the program has no moves or waits (its trajectory lasts 0 s)"
OPTION_DURATION_PERIOD = (
    "run.duration {value} s is shorter than one controller.period ({period} s); give at least one period"
)
OPTION_ENGINE_FIXED = (
    "controller.engine c and a firmware run the fixed-point controller; controller.law is {controller!r}"
)
SIMULATION_GAP_WARNING = (
    "the loop closures opened by up to {gap:.3g} m, more than a tenth of the sensor's {count:g} m count: "
    "try run.integrator cenic or a smaller run.plant_step"
)
OPTION_FIRMWARE_ENGINE = "a firmware runs your C, so it cannot run with controller.engine python; drop one of them"
OPTION_VIEW_DURATION = "--duration must be between 0 and 86400 s, got {value!r}"
OPTION_SPEED = "--speed must be a positive number, got {value!r}"
OPTION_PORT = "--port must be in 1024..65535 (Meshcat does not listen on a privileged port), got {value}"
OPTION_LEG_DAMPING = "{name} must be a finite number >= 0 N·s/m, got {value}"
OPTION_SAMPLE_RATE = "{name} must be a positive number of Hz, got {value}"
OPTION_JOINT_ANGLES = "joint angles must be finite, got {value}"
OPTION_JOINT_OVERFLOW = "joint angles {value} {unit}: the foot angle gamma = q1 + q2 + alpha overflows a float"
OPTION_TARGET = "target must be finite, got {value}"
OPTION_SERVO_POSE = "--pose has a non-finite number: {value}"
REPORT_UNKNOWN_ANALYSIS = "unknown analysis {name!r}; available: {available}"
REPORT_ONE_SUBJECT = "report: give a machine or platforms, not both"
# The Python API's own argument errors (stewart_drake.api: what a caller passes that no CLI option can)
API_POSE_SHAPE = "{what}: expected poses of shape (..., 6), got {shape}"
API_FIT_PLATFORM = "fit=True needs the platform to fit the trajectory to"
API_SIZE_SOURCE = "size: give exactly one of trajectory, program, envelope (got {given})"
API_FILE_EXISTS = "{path}: exists; pass overwrite=True to replace it"


class SynthesisError(StewartError):
    """A requirements file (``stewart-drake optimize``) or a workspace proof request is malformed: messages
    name the file, line and field, and the value as written."""

    FIELD = "{path}:{line}: {field}: {value} {problem}"
    MISSING = "{path}: {field} is required ({what})"
    FAMILY = "{path}:{line}: family: unknown family {value!r}; choose from {valid}"
    VARIABLE = "{path}:{line}: variables.{name}: not a variable of family {family!r} (its variables: {valid})"
    VARIABLE_MISSING = "{path}: variables.{name} is required for family {family!r} (bounds [low, high])"
    OBJECTIVE = "{path}:{line}: objectives item {k}: unknown objective {value!r}; choose from {valid}"
    STROKE_BOTH = "{path}: actuator: give stroke_ratio or stroke, not both"
    STROKE_NONE = "{path}: actuator: give stroke_ratio (L_max / L_min) or stroke [min, max]"
    BOX_OPTION = "--require-box {axis} {lo} {hi}: {problem}"
    BOX_OPTION_COUNT = "--require-box needs 12 numbers (px py pz a b g, each low high), got {n}"
    PICK = "--pick {value!r}: give knee, an objective ({valid}) or a row of the front (1..{n})"
    OUT_OTHER = (
        "--out {out}: holds a search with other requirements or seed (key {old} here, {new} now); give another folder"
    )
    OUT_NOT_OURS = "--out {out}: holds files that are not a search's ({name}); give another folder"
    BUDGET = "--budget must be between {lo} and {hi} design evaluations, got {value}"


class JournalError(StewartError):
    """A resume journal (``evaluations.jsonl``, ``montecarlo.partial.jsonl``; ``system.journal``) whose lines do not
    verify: edited, cut, or not written for this search or study. Nothing is resumed from it."""

    HEADER = "{path}:1: not a stewart-drake journal header ({text}); remove the file to start again"
    OTHER = "{path}:1: a journal of another search or study (key {old}, this one {new}); give another folder"
    LINE = (
        "{path}:{line}: does not verify ({text}): the journal was edited, cut or not written for this run; "
        "nothing was resumed from it: remove the file to start again, or give another folder"
    )
    ROW = (
        "{path}:{line}: {problem}; nothing was resumed from it: remove the file to start again, or give another folder"
    )
    # the problems of a row checked against what it can be recomputed from
    ROW_SHAPE = "not a design of {n} variables"
    ROW_BOUND = "variable {name} = {value!r} is outside its bounds [{lo:g}, {hi:g}]"
    ROW_METRICS = "its objectives or constraints are not those of its metrics"
    ROW_NO_METRICS = "a design row without its metrics"
    ROW_DRAW = "run {run}: {column} = {value!r} is not the study's draw for that run ({drawn!r})"


class InfeasibleRequirementsError(PhysicalLimitError):
    """No design the search evaluated meets every requirement (exit 1: a result, not bad input)."""

    NO_FEASIBLE = (
        "no design among {n} evaluated meets every requirement (least violated: {worst}); "
        "widen the bounds or raise --budget"
    )


class CalibrationError(InputError):
    """A calibration input is unusable (measurement file, noise or error SPEC, options): one line naming it."""

    COLUMNS = (
        "{path}:{line}: a {kind} measurement file needs the columns {need}; missing {missing} "
        "(header: {header}; --type {kind})"
    )
    UNKNOWN_COLUMN = "{path}:{line}: unknown column {name!r} for --type {kind} (columns: {need}, optional w)"
    NO_HEADER = "{path}:1: a measurement file starts with a header row naming its columns ({need}), got {row}"
    NOT_NUMBER = "{path}:{line}: column {column}: not a number: {value!r}"
    NOT_FINITE = "{path}:{line}: column {column}: values must be finite, got {value!r}"
    WIDTH = "{path}:{line}: expected {expected} values (one per header column), got {got}"
    WEIGHT = "{path}:{line}: column w: a weight must be > 0, got {value!r}"
    EMPTY = "{path}: no measurement rows"
    TOO_MANY = "{path}: more than {limit} measurement rows; a calibration needs tens"
    TOO_FEW = (
        "{path}: {n} poses give {equations} equations for {unknowns} unknowns ({parameters} parameters"
        "{nuisance}); give at least {need} poses"
    )
    TOO_FEW_DISTINCT = (
        "{path}: {rows} rows hold only {n} distinct poses ({copies} exact copies counted once; readings all within "
        "{tol} of another row's are one pose): {n} poses give {equations} equations for {unknowns} unknowns "
        "({parameters} parameters{nuisance}); give at least {need} distinct poses"
    )
    STROKE = (
        "{path}:{line}: leg {leg} reads {value} {unit}, so its length {length:.6g} m lies outside the stroke "
        "[{lmin:g}, {lmax:g}] m of platform {name!r}{hint}"
    )
    UNIT_HINT = " (are the readings in {guess}? give --length-unit {guess})"
    ANGLE = "{path}:{line}: column {column}: {value} {unit} is beyond ±{limit} {unit}{hint}"
    ANGLE_HINT = " (are the angles in degrees? give --angle-unit deg)"
    TYPE = "{path}: --type {kind} given, but the header names the columns of a {found} file ({header})"
    TARGETS = "{path}:1: target columns must be tK_x,tK_y,tK_z for K = 1, 2, ... in order, got {names}"
    NOISE_WORD = "{name}: {word!r} is not key=value (keys: {keys})"
    NOISE_KEY = "{name}: unknown key {key!r} (keys: {keys})"
    NOISE_VALUE = "{name}: {key}={text}: expected a number >= 0 with a unit ({units})"
    NOISE_TYPE = "{name}: expected key=value words (a string or a list of strings), got {value}"
    ERRORS_KEY = "{name}: key {key!r} is not a geometric error (keys: anchor, leg_offset)"
    HOLDOUT = "--holdout {value}: give a fraction in (0, 0.5] of the poses to hold out for validation"
    HOLDOUT_TOO_FEW = "--holdout {value}: holding out {held} of {n} poses leaves {left}, fewer than the {need} needed"
    POSES = "{name} {value}: give between {lo} and {hi} poses"
    CANDIDATES = (
        "platform {name!r}: only {got} of {want} candidate poses drawn in {box} lie within the stroke, above the "
        "base and away from singularities; give a smaller --workspace or more --candidates"
    )
    PLAN_TOO_FEW = (
        "--poses {value}: a {kind} measurement needs at least {need} poses on platform {name!r} ({unknowns} unknowns, "
        "{per} equations per pose)"
    )
    POSE_STROKE = "{path}:{line}: leg {leg} length {length:.6g} m lies outside the stroke [{lmin:g}, {lmax:g}] m"
    TRUTH_STROKE = (
        "--errors {errors}: the machine drawn (seed {seed}) cannot reach {path}:{line}: its leg {leg} would be "
        "{length:.6g} m long, outside the stroke [{lmin:g}, {lmax:g}] m ({count} of {n} poses out of reach); errors "
        "this large are not a built {name!r}, or the pose lies at the stroke's edge"
    )
    POSE_UNIT = (
        "{path}: the measured poses (px,py,pz,a,b,g) put the plate outside the workspace{hint}; the readings "
        "l1..l6 and the positions px,py,pz share --length-unit: write them in one unit"
    )
    WORKSPACE = (
        "--workspace {value}: give four numbers X Y Z ROT: ±X ±Y ±Z {unit} about home and ±ROT {angle}, each > 0"
    )
    MISSING = "measurement file {path!r} does not exist"
    NOT_A_FILE = "measurement file {path!r} is not a file"
    NOT_TEXT = "{path}: not UTF-8 text (byte {offset})"
    TARGET_COUNT = "{name} {value}: give 1 to 8 targets"
    POSE_COUNT = "{path}: more than {limit} poses"
    CANDIDATE_COUNT = "{name} {value}: give between {lo} and {hi} (twice {poses} at least)"
    VALIDATE_TARGETS = "{path}: {got} targets, but {fit} has {want}"


class CalibrationLimitError(PhysicalLimitError):
    """An identification that does not converge, or data that fix too little: the CLI exits 1, result shown."""

    NOT_CONVERGED = "the identification did not converge: {reason}; nothing written"
    NOT_USABLE = "the calibration is not usable: {reason}; calibration.json written, no calibrated.yaml"


class CertifyError(UsageError):
    """A pose box or budget the firmware certificate cannot take (``firmware certify`` / ``optimize``)."""

    BOX_WORD = "box {value!r}: expected KEY=LO..HI with KEY one of px py pz a b g, e.g. pz=120..250"
    BOX_TWICE = "box {value!r}: {key} is given twice"
    BOX_ORDER = "box {value!r}: LO and HI must be finite numbers with LO <= HI"
    BOX_ANGLE = "box {value!r}: an angle beyond ±180°"
    BOX_WORDS = "box {key} = {value} does not fit the {bits}-bit pose word at this length LSB (range ±{range_mm:g} mm)"
    CELLS = "max_cells must be in {lo}..{hi}, got {value}"
    BUDGET = "error_budget must be a positive length such as 0.5mm, got {value!r}"
    IMPLEMENTATION = (
        "implementation=tp17 certifies the seed's DSP firmware, whose platform is utn-kinematic; got platform={value}"
    )


# ----------------------------------------------------------------------------------------------
# Values echoed in messages: shortened the same way everywhere (a 1e300 length is not 300 digits).

MAX_ECHO = 60


def short_number(v, decimals: int = 3) -> str:
    """A number for a message: ``decimals`` places while it is below 1e9 in size, else 6 significant
    digits (``1e+300``, not 301 digits); ``nan``/``inf`` as such."""
    v = float(v)
    return f"{v:.{decimals}f}" if abs(v) < 1e9 else f"{v:.6g}"


def short_text(value, limit: int = MAX_ECHO) -> str:
    """``value`` as text for a message, cut to ``limit`` characters with an ellipsis."""
    s = value if isinstance(value, str) else repr(value)
    return s if len(s) <= limit else s[: limit - 1] + "…"


OPTION_LEG_DAMPING_RESOLVE = (
    "{name} {value:g} N·s/m gives damping ratios of ~{zeta:.3g}, beyond {limit:g}: the modes of a platform "
    "this overdamped are not resolved in double precision (one root per mode runs to ~0, the other to ~infinity)"
)


# ----------------------------------------------------------------------------------------------
# Motion cueing (``control/cueing``): vehicle-motion files, generators, washout and tuning parameters.


class DriveError(InputError):
    """A vehicle-motion ("drive") file or value is malformed: messages name the file, line and column."""

    PARQUET = "{path}: cannot read it as Parquet ({reason})"
    PARQUET_COLUMN = "{path}: column {column!r} is missing; a drive's columns are {columns}"
    PARQUET_VALUE = "{path}: row {row}, column {column!r}: values must be finite numbers, got {value}"
    TOO_FEW = "{path}: a drive needs at least {need} samples, got {got}"
    TOO_MANY = "{path}: {got} rows; a drive holds at most {limit} samples (split it or lower its rate)"
    STEP = (
        "{path}:{line}: column t: samples must be evenly spaced; t = {t} s follows t = {t_prev} s, a step of "
        "{step} s where its first step is {expected} s"
    )
    SHAPE = "drive {name!r}: {field} must have shape {shape}, got {got}"
    NOT_FINITE = "drive {name!r}: {field} must be finite; sample {index} is {value}"
    TIMES = "drive {name!r}: t must increase in equal steps; sample {index} steps {step} s, the first {expected} s"
    UNKNOWN = "unknown drive {name!r}; the shipped drives are {names}"
    MANOEUVRE = "unknown {vehicle} manoeuvre {name!r}; expected one of {valid}"
    SEA_STATE = "sea_state must be one of {valid}, got {value!r}"
    DURATION = "{name} must be a positive number of seconds of at most {limit} s, got {value!r}"
    RATE = "rate must be between {low} and {high} Hz, got {value!r}"
    FORMAT = "{path}: a drive file ends in .csv or .parquet"


class CueingError(StewartError):
    """A washout, guard or tuning request that cannot be met (a bad parameter, a mismatched drive)."""

    PARAM = "{name} must be {rule}, got {value!r}"
    PARAMS_FILE = "{path}:{line}: {field}: {value} must be {rule}"
    POSES_TIMES = "poses ({n} rows) and t ({m} samples) must have one row per sample"
    SAME_TIMES = "the vehicle drive ({n} samples, step {dt} s) and the platform drive ({m}, step {dt2} s) must share t"
    HOME_OUTSIDE = (
        "the home pose {home} is outside the guard's limits (the stroke less {margin} m at each end, joint cones)"
    )
    NO_DRIVES = "tune_classical needs at least one drive"
