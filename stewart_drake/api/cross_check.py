"""``sd.cross_check``: the platform's kinematics and inverse dynamics in Pinocchio and MuJoCo against the closed
forms (``stewart_drake.engines``; the engines are optional extras, ``pip install 'stewart-drake[engines]'``), and
the float-law loop on Pinocchio against ``sd.simulate``'s (``drake_loop_check``)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from stewart_drake.api.platform import load_platform
from stewart_drake.api.result import Result
from stewart_drake.api.simulation import simulate
from stewart_drake.control.laws import FloatLaw
from stewart_drake.core.geometry import Platform
from stewart_drake.core.trajectory import get_trajectory
from stewart_drake.engines.cross_check import ENGINES, LOOP_DURATION, engine_model, engine_status
from stewart_drake.engines.cross_check import cross_check as run_cross_check
from stewart_drake.engines.dsp_loop import dsp_loop, loop_difference
from stewart_drake.engines.models import modelled_platform
from stewart_drake.errors import EngineError, OptionError, StewartError

__all__ = ["cross_check", "CrossCheck"]

MAX_POSES = 100_000  # each pose is one forward-kinematics pass per engine (~0.1 ms)
MAX_SAMPLES = 10_000  # each sample is two 24 × 24 solves and one inverse dynamics per engine
# m per count: a sensor fine enough that no count flips between two plants a few micrometres apart, so the loops'
# difference is the plants' alone
FINE_SENSOR = 1e-9


@dataclass(repr=False)
class CrossCheck(Result):
    """The engines' verdicts (``cross_check``). ``to_dict()`` is ``stewart-drake cross-check --json`` (SI).

    Attributes:
        platform: the platform's name.
        engines: engine name -> ``{"available", "reason", "version", "kinematics": {"poses",
            "closure_residual_m", "leg_length_error_m", "tolerance_m", "ok"}, "dynamics": {trajectory:
            {"samples", "max_force_n", "max_error_n", "relative_error", "tolerance_relative", "condition", "ok"}},
            "open_loop", "passive_release", "drake_loop" (Pinocchio: ``drake_loop_check``), "ok"}``
            (``engines.cross_check``).
    """

    platform: str
    engines: dict

    @property
    def ok(self) -> bool:
        """Every engine that ran agrees with the closed forms within the derived tolerances (and one ran)."""
        ran = [e for e in self.engines.values() if e["available"]]
        return bool(ran) and all(e["ok"] for e in ran)

    def _fields(self) -> dict:
        return {"platform": self.platform, "engines": self.engines, "ok": self.ok}


def cross_check(
    platform: Platform | str | Path,
    *,
    engines=None,
    poses: int = 1000,
    samples: int = 13,
    seed: int = 0,
    simulate: bool = True,
) -> CrossCheck:
    """Check the platform's closed forms against Pinocchio and MuJoCo.

    Args:
        platform: a ``Platform``, a preset name or a platform YAML file.
        engines: engine names ("pinocchio", "mujoco"); default every installed one.
        poses: seeded poses (``sampling.random_poses``, box region) for the kinematics.
        samples: samples of each trajectory (the seed's sway and a rotation about every axis, 3 s) for the dynamics.
        seed: the poses' seed.
        simulate: also run the forward simulations (the closed-form forces open loop for 0.5 s; the passive
            platform released from home for 0.2 s; MuJoCo at four ``solref`` time constants; Pinocchio's float-law
            loop against ``sd.simulate``'s, ``drake_loop_check``).

    Returns:
        Per engine: the worst closure residual and leg-length error (m) and the worst leg-force error (N, relative)
        per trajectory, each with its tolerance and verdict.

    Raises:
        EngineError: a named engine that is not installed, or none installed.
        OptionError: ``poses`` or ``samples`` below their minimum; ``EngineError`` above their maximum.
    """
    platform = load_platform(platform)
    checks = (("poses", poses, 1, MAX_POSES), ("samples", samples, 2, MAX_SAMPLES), ("seed", seed, 0, 2**63 - 1))
    for option, value, low, high in checks:
        if int(value) != value or value < low:
            raise OptionError(OptionError.AT_LEAST.format(option=option, min=low, value=value))
        if value > high:
            raise EngineError(EngineError.TOO_MANY.format(option=option, value=value, limit=high))
    status = engine_status()
    if engines is None:
        names = [n for n in ENGINES if status[n] is None]
        if not names:
            raise EngineError(EngineError.NONE.format(reasons="; ".join(status.values())))
    else:
        names = list(engines)
        for n in names:
            if n not in ENGINES:
                raise EngineError(EngineError.UNKNOWN.format(value=n, valid=", ".join(ENGINES)))
            if status[n] is not None:
                raise EngineError(EngineError.MISSING.format(name=n, reason=status[n]))
    out = run_cross_check(platform, names, int(poses), int(samples), int(seed), simulate=bool(simulate))
    if simulate and "pinocchio" in names:
        loop = drake_loop_check(platform)
        out["pinocchio"]["drake_loop"] = loop
        out["pinocchio"]["ok"] = bool(out["pinocchio"]["ok"] and loop["ok"] is not False)
    return CrossCheck(platform.name, out)


def _loops(platform: Platform, duration: float, **options) -> tuple:
    """``sd.simulate``'s float-law loop along the seed (fitted to the stroke) with ``options``: its ``Scenario``,
    the same loop on Pinocchio (``engines.dsp_loop``) and their difference (``loop_difference``)."""
    run = simulate(platform, "seed", controller="float", duration=duration, fit=True, **options)
    s = run.plan.scenario
    engine = engine_model("pinocchio", modelled_platform(platform))
    law = FloatLaw(s.platform, s.config)
    mine = dsp_loop(
        engine,
        s.platform,
        get_trajectory(s.trajectory),
        law,
        s.plant_time_step,
        s.duration,
        s.actuators.time_constant,
        s.actuators.max_force,
        s.feedforward,
    )
    return s, mine, loop_difference(s.platform, run.log["pose"], run.log["lengths"], mine)


def drake_loop_check(platform: Platform, duration: float = LOOP_DURATION) -> dict:
    """The float-law loop of ``sd.simulate`` (the seed fitted to the stroke, the machine's defaults) against the
    same loop on Pinocchio (``engines.dsp_loop``: the same law, tick, output delay, actuators and start; only the
    plant differs), plate poses and leg lengths side by side at every plant step.

    Drake's plant step (CENIC at a fixed step, first order) is what legitimately differs; Pinocchio's RK4 is four
    orders closer. With a ``FINE_SENSOR`` (no count flips) the difference at the plant step h is then Drake's
    first-order error: (1) at h/2 it halves, the ratio ½ within ¼ (the second-order share below half the first:
    h is at most half the actuators' lag, the fastest time scale of the forces); (2) it is at most the local
    error ½ h² |a| summed over the run, ½ h T max|a| (a the plate's acceleration, the loop stable so no step's
    error grows). A loop run with other semantics (a start without the legs' rates, no output delay) leaves a
    difference that does not shrink with h. With the machine's sensor the difference is shown, not judged: a
    count that flips in one run and not the other moves the loops apart by about a count.

    Returns ``plant_step_s``, ``duration_s``, ``sensor_resolution_m`` (the machine's), ``position_m``,
    ``angle_rad`` and ``length_m`` (the machine's sensor: the worst plate-origin distance, rotation and leg-length
    difference), ``fine``: ``{"plant_step_s": [h, h/2], "position_m": [...], "angle_rad": [...], "length_m":
    [...]}``, ``step_ratio`` (fine position at h/2 over at h), ``bound_m``, ``ok``; or ``{"ok": None, "reason"}``
    where ``sd.simulate`` refuses the platform (no plate mass, a seed out of stroke)."""
    try:
        scenario, _, machine = _loops(platform, duration)
        h = scenario.plant_time_step
        fine = [_loops(platform, duration, sensor_resolution=FINE_SENSOR, plant_step=step) for step in (h, h / 2)]
    except StewartError as e:
        return {"ok": None, "reason": str(e)}
    p = fine[0][1]["p"]
    a_max = float(np.linalg.norm(np.diff(p, 2, axis=0), axis=-1).max()) / h**2
    bound = 0.5 * h * duration * a_max
    diffs = [d for _, _, d in fine]
    ratio = diffs[1]["position_m"] / diffs[0]["position_m"]
    return {
        "plant_step_s": h,
        "duration_s": duration,
        "sensor_resolution_m": scenario.config.timing.sensor_resolution,
        **machine,
        "fine": {"plant_step_s": [h, h / 2], **{k: [d[k] for d in diffs] for k in diffs[0]}},
        "step_ratio": ratio,
        "bound_m": bound,
        "ok": bool(abs(ratio - 0.5) <= 0.25 and diffs[0]["position_m"] <= bound),
    }
