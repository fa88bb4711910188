"""Classical washout tuned for a set of drives on a platform, and washout parameters as YAML files.

The tuning minimises the perceived error of the guarded washout: for each drive, the classical poses are guarded
(``guard.WorkspaceGuard``: so every candidate, and the result, has no sample outside the stroke, leg speed or
acceleration limits), felt on the platform (``platform_motion``) and perceived (``vestibular``); the cost is the
mean over drives of the perceived specific-force RMSE over the vehicle's perceived specific-force RMS (rest
removed) plus, at a fifth of the weight, the same for the angular velocity (the aim is the specific force; the
rotation term keeps the rotational channel from drifting where it costs the specific force nothing). The
optimiser is scipy's differential evolution over ``TUNED`` (the gains and corner frequencies; the damping ratios,
the tilt limits and its perception-threshold rate stay as in ``start``), bounded by ``BOUNDS``, with a fixed seed
and a budget of evaluations; ``start`` is one member of the first population, so the result is never worse than it.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from scipy.optimize import differential_evolution

from stewart_drake.control.cueing.classical import ClassicalParams, classical
from stewart_drake.control.cueing.drive import GRAVITY, Drive
from stewart_drake.control.cueing.guard import WorkspaceGuard
from stewart_drake.control.cueing.platform_motion import platform_drive
from stewart_drake.control.cueing.vestibular import perceive
from stewart_drake.core.geometry import Platform
from stewart_drake.core.yamlio import compose, load_yaml_typed, read_yaml_text
from stewart_drake.errors import CueingError
from stewart_drake.system.output_folder import write_output_file

TUNED = ("scale_xy", "scale_z", "scale_rot", "hp_xy", "hp_z", "hp_break", "tilt_lp", "hp_rot")
BOUNDS = {
    "scale_xy": (0.05, 1.0),
    "scale_z": (0.05, 1.0),
    "scale_rot": (0.05, 1.0),
    "hp_xy": (0.2, 6.0),
    "hp_z": (0.2, 8.0),
    "hp_break": (0.0, 2.0),
    "tilt_lp": (0.3, 8.0),
    "hp_rot": (0.2, 6.0),
}
ROTATION_WEIGHT = 0.2
POPULATION = 8  # per tuned parameter (scipy's popsize)
MAX_BUDGET = 100_000
PARAMS_KIND = "washout parameters"


class _Objective:
    """The tuning's cost of a parameter vector (a picklable callable: scipy may evaluate it in workers)."""

    def __init__(self, drives: list[Drive], guard: WorkspaceGuard, start: ClassicalParams):
        self.drives, self.guard, self.start = drives, guard, start
        rest = np.array([0.0, 0.0, GRAVITY])
        self.perceived = [perceive(d) for d in drives]
        self.refs = [
            (
                max(float(np.sqrt(np.mean(np.sum((pv.specific_force - rest) ** 2, axis=1)))), 1e-3),
                max(float(np.sqrt(np.mean(np.sum(pv.angular_velocity**2, axis=1)))), 1e-4),
            )
            for pv in self.perceived
        ]

    def params(self, x) -> ClassicalParams:
        return dataclasses.replace(self.start, **dict(zip(TUNED, map(float, x))))

    def __call__(self, x) -> float:
        params = self.params(x)
        cost = 0.0
        for d, pv, (rf, rw) in zip(self.drives, self.perceived, self.refs):
            q = self.guard.guard(classical(d, params, self.guard.home), d.t)
            pp = perceive(platform_drive(q, d.t, self.guard.home))
            ef = np.sqrt(np.mean(np.sum((pp.specific_force - pv.specific_force) ** 2, axis=1)))
            ew = np.sqrt(np.mean(np.sum((pp.angular_velocity - pv.angular_velocity) ** 2, axis=1)))
            cost += ef / rf + ROTATION_WEIGHT * ew / rw
        return cost / len(self.drives)


def tune_classical(
    drives: list[Drive],
    platform: Platform,
    guard: WorkspaceGuard | None = None,
    start: ClassicalParams = ClassicalParams(),
    budget: int = 400,
    seed: int = 0,
) -> ClassicalParams:
    """The classical washout parameters that minimise the perceived error of ``drives`` on ``platform`` through
    ``guard`` (default ``WorkspaceGuard.for_platform(platform)``), starting from ``start``, within about
    ``budget`` cost evaluations (whole generations of differential evolution; each one runs every drive once),
    seeded by ``seed``."""
    drives = list(drives)
    if not drives:
        raise CueingError(CueingError.NO_DRIVES)
    if isinstance(budget, bool) or not isinstance(budget, int) or not 1 <= budget <= MAX_BUDGET:
        raise CueingError(
            CueingError.PARAM.format(name="budget", rule=f"a whole number in 1..{MAX_BUDGET}", value=budget)
        )
    guard = guard or WorkspaceGuard.for_platform(platform)
    objective = _Objective(drives, guard, start)
    bounds = [BOUNDS[n] for n in TUNED]
    x0 = np.clip([getattr(start, n) for n in TUNED], [b[0] for b in bounds], [b[1] for b in bounds])
    population = POPULATION * len(TUNED)
    generations = max(0, budget // population - 1)
    result = differential_evolution(
        objective, bounds, x0=x0, popsize=POPULATION, maxiter=generations, seed=seed, polish=False, tol=0.0
    )
    best = result.x if result.fun <= objective(x0) else x0
    return objective.params(best)


def tuning_cost(drives: list[Drive], guard: WorkspaceGuard, params: ClassicalParams) -> float:
    """The tuning's cost of ``params`` on ``drives`` through ``guard`` (see the module)."""
    objective = _Objective(list(drives), guard, params)
    return objective([getattr(params, n) for n in TUNED])


def save_params(params: ClassicalParams, path):
    """Write ``params`` to the YAML file ``path`` (SI: rad/s, rad; a file that exists is replaced only when this
    program wrote it); returns the path."""
    lines = ["# classical washout parameters (stewart-drake): gains 1, frequencies rad/s, angles rad, rates rad/s"]
    lines += [f"{f.name}: {getattr(params, f.name)!r}" for f in dataclasses.fields(params)]
    return write_output_file(str(path), "\n".join(lines) + "\n", option="path")


def load_params(path) -> ClassicalParams:
    """The ``ClassicalParams`` of the YAML file ``path`` (keys missing keep their defaults). Errors name the file,
    the line and the key (``YamlError`` for a malformed file, ``CueingError`` for a value out of range)."""
    try:
        return load_yaml_typed(path, ClassicalParams, PARAMS_KIND)
    except CueingError as e:
        field = getattr(e, "field", None)
        if field is None:
            raise
        text, shown = read_yaml_text(path, PARAMS_KIND)
        line, value = next(
            ((k.start_mark.line + 1, v.value) for k, v in compose(text, shown).value if k.value == field), (1, e.value)
        )
        raise CueingError(
            CueingError.PARAMS_FILE.format(path=shown, line=line, field=field, value=value, rule=e.rule)
        ) from None
