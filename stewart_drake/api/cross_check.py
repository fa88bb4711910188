"""``sd.cross_check``: the platform's kinematics and inverse dynamics in Pinocchio and MuJoCo against the closed
forms (``stewart_drake.engines``; the engines are optional extras, ``pip install 'stewart-drake[engines]'``)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from stewart_drake.api.platform import load_platform
from stewart_drake.api.result import Result
from stewart_drake.core.geometry import Platform
from stewart_drake.engines.cross_check import ENGINES, engine_status
from stewart_drake.engines.cross_check import cross_check as run_cross_check
from stewart_drake.errors import EngineError, OptionError

__all__ = ["cross_check", "CrossCheck"]

MAX_POSES = 100_000  # each pose is one forward-kinematics pass per engine (~0.1 ms)
MAX_SAMPLES = 10_000  # each sample is two 24 × 24 solves and one inverse dynamics per engine


@dataclass(repr=False)
class CrossCheck(Result):
    """The engines' verdicts (``cross_check``). ``to_dict()`` is ``stewart-drake cross-check --json`` (SI).

    Attributes:
        platform: the platform's name.
        engines: engine name -> ``{"available", "reason", "version", "kinematics": {"poses",
            "closure_residual_m", "leg_length_error_m", "tolerance_m", "ok"}, "dynamics": {trajectory:
            {"samples", "max_force_n", "max_error_n", "relative_error", "tolerance_relative", "condition", "ok"}},
            "open_loop", "passive_release", "ok"}`` (``engines.cross_check``).
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
            platform released from home for 0.2 s; MuJoCo at four ``solref`` time constants).

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
    return CrossCheck(
        platform.name, run_cross_check(platform, names, int(poses), int(samples), int(seed), simulate=bool(simulate))
    )
