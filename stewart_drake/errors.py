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
