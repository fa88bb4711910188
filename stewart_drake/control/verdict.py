"""The verdict on one closed-loop run, as ``simulate`` gives it and every Monte Carlo run records it: the
tracking verdict (``simulation_log.tracking_verdict``: lost tracking, a leg saturated too long) and the loop's
own (``chatter.loop_verdict``: chatter, saturation at the reference's ends), joined in one place."""

from __future__ import annotations

from stewart_drake.control.chatter import loop_verdict
from stewart_drake.control.gains import ControllerConfig
from stewart_drake.control.simulation_log import SimulationLog, tracking_verdict
from stewart_drake.core.geometry import Platform
from stewart_drake.core.trajectory import Trajectory


def run_verdict(
    platform: Platform,
    truth: Platform,
    trajectory: Trajectory,
    log: SimulationLog,
    config: ControllerConfig,
    length_error,
    pose_error,
) -> tuple[dict, dict]:
    """``(verdict, loop)`` of a run.

    Args:
        platform: the controller's platform (the quasi-static forces are its inverse dynamics).
        truth: the plant's platform (its stroke bounds the tracking error).
        trajectory: the pose reference.
        log: the run's logs.
        config: the controller's timing and gains.
        length_error: ``(n, 6)`` true leg length − IK of the reference, m.
        pose_error: ``(n, 6)`` measured − reference pose, m and rad.

    Returns:
        ``verdict``: ``tracking_verdict``'s dict with ``"failures"`` holding every failure, the tracking's then
        the loop's; ``loop``: ``loop_verdict``'s measures, ``"chatter"``, ``"end_saturation"`` and its
        ``"warnings"`` (its failures are in ``verdict``).
    """
    verdict = tracking_verdict(truth, length_error, pose_error, log)
    loop = loop_verdict(platform, trajectory, log, config)
    verdict["failures"] += loop.pop("failures")
    return verdict, loop
