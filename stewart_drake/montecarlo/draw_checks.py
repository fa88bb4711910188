"""Every drawn scenario of a study passes ``simulate``'s sanity checks before any run starts.

A draw is a platform, a controller and actuators as ``simulate`` would build them from options; a draw that
``simulate`` would refuse (a massless plate, a zero sensor count, gains that do not fit the firmware's
words, a period too slow for the plate, a reference that leaves the drawn legs' stroke) is refused here,
naming the run, its seed and the drawn values of the keys the SPEC varies, instead of running and being
reported as "lost tracking" among the results.
"""

from __future__ import annotations

import math

import numpy as np

from stewart_drake.control import counts_per_lsb
from stewart_drake.control.feasibility import infeasible_motion
from stewart_drake.control.gains import FixedGains
from stewart_drake.control.timing import check_timing
from stewart_drake.core.sanity import check_trajectory, require_plate
from stewart_drake.errors import StewartError, StudyError, short_text
from stewart_drake.montecarlo.scenario import draw, nominal_gains, scenario


def _drawn(study, d) -> str:
    """The drawn values of the keys the SPEC varies, as ``column=value`` (SI), for the message."""
    cols = d.columns()
    keys = set(study.spec.laws) | set(study.grid[0] if study.grid else ())
    shown = [f"{c}={v:.6g}" if isinstance(v, float) else f"{c}={v}" for c, v in cols.items() if _of_key(c, keys)]
    return short_text(", ".join(shown), 200)


def _of_key(column: str, keys) -> bool:
    return any(column == k or column.startswith(k + "_") or column.startswith(k) and k == "anchor" for k in keys)


def check_draw(study, index: int, reference, duration: float, gains=None) -> None:
    """``StudyError`` (exit 2) naming run ``index`` when its scenario fails a check ``simulate`` makes."""
    seed, d = draw(study, index)
    try:
        sc = scenario(study, index, reference, gains)[2]
        plant = sc.plant_platform
        require_plate(plant, "montecarlo")
        timing = sc.config.timing.check()
        if not (math.isfinite(d.force_limit) and d.force_limit > 0):
            raise StewartError(f"force_limit must be a positive number of N, got {d.force_limit:.6g}")
        check_timing(plant, timing.sample_period, study.plant_step, d.actuator_lag, timing.output_delay)
        if study.controller == "fixed":
            counts_per_lsb(sc.config)
            FixedGains.from_si(sc.config.gains, timing)
        ticks = np.arange(int(math.floor(duration / timing.sample_period + 1e-9)) + 1) * timing.sample_period
        check_trajectory(plant, ticks, reference.pose(ticks), "utn", f"the {reference.name} reference", False)
        why = infeasible_motion(plant, reference, ticks, timing.sample_period, d.force_limit)
        if why:
            raise StewartError(why)
    except (StewartError, ZeroDivisionError, OverflowError) as e:
        drawn = _drawn(study, d)
        raise StudyError(
            StudyError.DRAW.format(run=index, seed=seed, drawn=drawn, reason=short_text(str(e).splitlines()[0], 300))
        ) from None


def check_draws(study) -> None:
    """``check_draw`` for every run of ``study`` (the reference built once)."""
    reference = study.reference()
    duration = study.run_duration(reference)
    gains = nominal_gains(study, reference)
    for i in range(study.runs):
        check_draw(study, i, reference, duration, gains)
