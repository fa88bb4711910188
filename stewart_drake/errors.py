"""The project's exceptions. All derive from ValueError so callers can catch bad input in one place.

Messages name the offending thing and value; tests match them, so they live here as templates.
"""

from __future__ import annotations


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
                index=pose_index,
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
