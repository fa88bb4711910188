"""The project's exceptions. All derive from ValueError so callers can catch bad input in one place.

Messages name the offending thing and value; tests match them, so they live here as templates.
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
# Input/output errors and message templates (files, options, output folders).


class InputError(StewartError):
    """A file or option the user gave is unreadable or malformed (YAML, CSV, a path)."""


class OutputError(StewartError):
    """An output destination is refused by the output policy (``atomic``) or cannot be written."""

    REFUSED_PLACE = "{option} {typed!r}: refusing to write into {what}; give a new folder name"
    NOT_A_FOLDER = "{option} {typed!r}: {part!r} exists and is not a folder"
    SYMLINK = "{option} {typed!r}: is a symbolic link; give the real folder"
    NOT_OURS = ("{option} {typed!r}: the folder {why} (e.g. {example!r}, {count} file(s)); give a new or empty "
                "folder, or --force to write beside them (files not written by stewart-drake are never touched)")
    UNWRITABLE = "{option} {typed!r}: cannot write there ({reason})"
    BAD_PATH = "{option} {typed!r}: not a usable path"
    CLASH = "{option} {typed!r}: {name!r} exists and was not written by stewart-drake; nothing was written"
    FILE_IS_FOLDER = "{option} {typed!r}: is a folder; give a file name"
    FILE_NOT_REGULAR = "{option} {typed!r}: exists and is not a regular file"
    FILE_NOT_OURS = ("{option} {typed!r}: the file exists and was not written by stewart-drake; "
                     "remove it or choose another name (it is never overwritten)")


class YamlError(GeometryError, InputError):
    """A YAML file is unreadable, too large, too deep, or not in the schema. Messages start with
    ``file:line:`` where known and name the field (``plate.mass``) and the value as written."""

    TOO_LARGE = "{path}: {size} bytes is larger than the {limit}-byte limit for a {kind} file"
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


class CsvError(InputError):
    """A CSV file is malformed: messages name the file and the line (counted from 1)."""

    FIELD_TOO_LONG = "{path}:{line}: a field is longer than {limit} characters; not a {kind} file?"
    NOT_TEXT = "{path}:{line}: not UTF-8 text"
    NOT_NUMBER = "{path}:{line}: column {column}: not a number: {value!r}"
    WIDTH = "{path}:{line}: expected {expected} values ({columns}), got {got}"
    NOT_FINITE = "{path}:{line}: column {column}: values must be finite, got {value!r}"
    EMPTY = "{path}: no {kind} rows"
    MISSING = "{kind} file {path!r} does not exist"
    IS_FOLDER = "{kind} file {path!r} is a folder, not a file"


class UsageError(StewartError):
    """Options that contradict each other or are ignored (e.g. ``--json`` without ``--inspect``)."""

    NEEDS = "{option} only applies with {needs}"
    NOT_FINITE = "{option}: must be a finite number, got {value}"
    INTERNAL = "internal error ({kind}: {detail}); please report it with the command line"


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
    "{limit:g} × are surely a unit mistake (a file in mm read as metres? use --length-unit mm)"
)
NOT_FINITE = "{what} must be finite, got {value}"
OUT_OF_STROKE = (
    "{what} leaves the stroke: first at t = {t:.4f} s, leg {leg} length {length_mm:.3f} mm is {excess_mm:.3f} mm "
    "{side} the stroke {bound} {limit_mm:.3f} mm{hint}"
)
NO_PLATE = (
    "platform {name!r} has no plate mass properties (YAML key 'plate' missing, or its mass is 0): "
    "'{command}' needs plate.mass and plate.inertia (or plate.thickness and plate.density for a utn platform)"
)
SINGULAR_HOME = "platform {name!r} is singular at its home pose (Jacobian condition number {cond:.3g} > {limit:.0e}): {why}"
WORK_TOO_LARGE = "{option} {value} would need {estimate}; the limit is {limit}{hint}"


# --- control
class TimingError(StewartError):
    """A DSP timing configuration that cannot run (the computation does not fit in the sample period)."""


INFEASIBLE_TIMING = (
    "infeasible DSP timing: one controller tick needs {cycles} cycles = {t_comp_us:.3f} µs at {clock_mhz:g} MHz, "
    "longer than the sample period {period_us:.3f} µs"
)
PLANT_STEP_TOO_LONG = ("--plant-step {step} s is longer than the controller period {period} s; "
                       "the plant step must resolve the period (at most one period)")
PLANT_STEP_ABOVE_LAG = ("--plant-step {step} s is longer than the actuators' time constant {lag} s, "
                        "the platform's fastest modelled dynamics; use a step of at most that")
PERIOD_TOO_SLOW = (
    "--period {period} s is too slow for platform {name}: its fastest open-loop mode grows at "
    "{lam:.3g}/s, and the leg loops' crossover at this period is at most {w_c:.3g} rad/s (< {margin:g} × "
    "{lam:.3g}); use a period of at most ~{t_max:.3g} s"
)
