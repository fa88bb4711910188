"""Every drawn scenario of a study passes ``simulate``'s sanity checks before any run starts.

A draw is a platform, a controller and actuators as ``simulate`` would build them from options; a draw that
``simulate`` would refuse (a massless plate or one negligible against the legs, a zero sensor count, gains that do not fit the firmware's
words, a period too slow for the plate, a reference that leaves the drawn legs' stroke) is refused here,
naming the run, its seed and the drawn values of the keys the SPEC varies, instead of running and being
reported as "lost tracking" among the results.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from stewart_drake.api.simulation import BYTES_PER_STEP, MAX_RUN_SECONDS, SECONDS_PER_STEP
from stewart_drake.control import counts_per_lsb
from stewart_drake.control.feasibility import infeasible_motion
from stewart_drake.control.gains import FixedGains
from stewart_drake.control.timing import check_timing
from stewart_drake.core.sanity import check_positive, check_trajectory, check_work, require_plant_plate
from stewart_drake.errors import StewartError, StudyError, short_text
from stewart_drake.montecarlo.scenario import draw, nominal_gains, scenario
from stewart_drake.montecarlo.spec import VarySpec


def _drawn(study, d) -> str:
    """The drawn values of the keys the SPEC varies, as ``column=value`` (SI), for the message."""
    cols = d.columns()
    keys = set(study.spec.laws) | set(study.grid[0] if study.grid else ())
    shown = [f"{c}={v:.6g}" if isinstance(v, float) else f"{c}={v}" for c, v in cols.items() if _of_key(c, keys)]
    return short_text(", ".join(shown), 200)


def _of_key(column: str, keys) -> bool:
    return any(column == k or column.startswith(k + "_") or column.startswith(k) and k == "anchor" for k in keys)


def check_draw(study, index: int, reference, duration: float, gains=None, infeasible=None, vary="vary") -> None:
    """``StudyError`` (exit 2) naming run ``index`` when its scenario fails a check ``simulate`` makes;
    ``infeasible(force_limit, period)``: the motion's feasibility (``nominal_feasibility``), or None; ``vary``:
    how messages name what the study varies."""
    found = draw_refusal(study, index, reference, duration, gains, infeasible, vary)
    if found:
        seed, d, reason = found
        advice = StudyError.DRAW_ADVICE.format(vary_opt=vary) if study.spec.laws else ""
        raise StudyError(StudyError.DRAW.format(run=index, seed=seed, drawn=_drawn(study, d), reason=reason) + advice)


def draw_refusal(study, index: int, reference, duration: float, gains=None, infeasible=None, vary="vary"):
    """``(run seed, Draw, reason)`` when run ``index``'s scenario fails a check ``simulate`` makes, else None."""
    seed, d = draw(study, index)
    try:
        # the period, then the run's size, before any of it is allocated (a period of 1e-123 s: 1e121 ticks)
        check_positive(d.sample_period, f"{vary} sample_period", "seconds")
        step = min(d.sample_period, study.plant_step)
        check_work(
            f"{vary} sample_period",
            f"{d.sample_period:.6g} s",
            duration / step,
            f"steps of {step:.6g} s in its {duration:.6g} s",
            BYTES_PER_STEP,
            seconds_per=SECONDS_PER_STEP,
            max_seconds=MAX_RUN_SECONDS,
            hint="; draw a longer sample_period",
        )
        sc = scenario(study, index, reference, gains)[2]
        plant = sc.plant_platform
        require_plant_plate(plant, "montecarlo")
        timing = sc.config.timing.check()
        if not (math.isfinite(d.force_limit) and d.force_limit > 0):
            raise StewartError(f"force_limit must be a positive number of N, got {d.force_limit:.6g}")
        check_timing(plant, timing.sample_period, study.plant_step, d.actuator_lag, timing.output_delay)
        if study.controller == "fixed":
            counts_per_lsb(sc.config)
            FixedGains.from_si(sc.config.gains, timing)
        ticks = np.arange(int(math.floor(duration / timing.sample_period + 1e-9)) + 1) * timing.sample_period
        # the stroke violation as a message (simulate's --allow-out-of-stroke hint is no option of a study)
        why = check_trajectory(plant, ticks, reference.pose(ticks), "utn", f"the {reference.name} reference", True)
        why = why[0] if why else infeasible(d.force_limit, timing.sample_period) if infeasible else None
        if why:
            raise StewartError(why)
    except (StewartError, ZeroDivisionError, OverflowError) as e:
        return seed, d, short_text(str(e).splitlines()[0], 300)
    return None


def nominal_feasibility(study, reference, duration: float):
    """``f(force_limit, period) -> reason or None``: ``feasibility.infeasible_motion`` of the reference on the
    nominal platform, computed once per (limit, period) a study draws. The drawn plants' forces differ from the
    nominal by their mass and geometry tolerances; checking each plant would cost as much as the feed-forward
    table of its run again (~15 % of a study's time), and a draw near the limit shows as saturation in its run."""
    cache: dict = {}

    def f(force_limit: float, period: float):
        key = (force_limit, period)
        if key not in cache:
            ticks = np.arange(int(math.floor(duration / period + 1e-9)) + 1) * period
            cache[key] = infeasible_motion(study.machine.loaded_platform, reference, ticks, period, force_limit)
        return cache[key]

    return f


def check_draws(study, names: dict | None = None) -> None:
    """``check_draw`` for every run of ``study`` (the reference, the nominal gains and the motion's
    feasibility computed once; ``names``: how messages name the settings, ``study.NAMES``)."""
    vary = (names or {}).get("vary", "vary")
    reference = study.reference()
    duration = study.run_duration(reference)
    gains = nominal_gains(study, reference)
    infeasible = nominal_feasibility(study, reference, duration)
    for i in range(study.runs):
        if draw_refusal(study, i, reference, duration, gains, infeasible, vary) is None:
            continue
        # refused: when the nominal scenario is too, the study's settings are at fault (no narrower --vary mends it)
        nominal = replace(study, spec=VarySpec(), grid=None, runs=1)
        found = draw_refusal(nominal, 0, reference, duration, gains, infeasible, vary)
        if found:
            raise StudyError(StudyError.DRAW_NOMINAL.format(reason=found[2]))
        check_draw(study, i, reference, duration, gains, infeasible, vary)
