"""Grid sweeps (e.g. sample period × latency mode × gain scaling) on the Monte Carlo machinery: one run per
grid point, each point's values replacing the draws of those keys (``Study.grid``), run in this process
or on Dask like any study."""

from __future__ import annotations

import itertools

from stewart_drake.core.geometry import Platform
from stewart_drake.montecarlo.scenario import Study
from stewart_drake.montecarlo.spec import KEYS, SpecError, VarySpec, check_key
from stewart_drake.montecarlo.study import run_study
from stewart_drake.spec import Machine


def sweep_study(machine: Machine | Platform, axes: dict, trajectory: str | None = None, **keywords) -> Study:
    """The ``Study`` of ``machine`` (a ``Platform``: a machine with defaults) over the cartesian product of
    ``axes`` (``{key: [SI values]}``, keys of ``spec.KEYS``; the first key varies slowest): point i is run i.
    ``keywords``: ``Study``'s (``duration``, ``plant_step``, ``engine``, ...: they set their spec paths)."""
    for k, values in axes.items():
        check_key(k, "sweep")
        if KEYS[k].length:
            raise SpecError(SpecError.SWEEP_VECTOR.format(key=k))
        if not len(values):
            raise SpecError(SpecError.SWEEP_EMPTY.format(key=k))
    keys = list(axes)
    grid = tuple(dict(zip(keys, point)) for point in itertools.product(*(axes[k] for k in keys)))
    return Study(machine, VarySpec({}, "sweep"), 0, len(grid), trajectory, grid=grid, **keywords)


def run_sweep(study: Study, workers: int = 0, out=None, progress: bool = False) -> list[dict]:
    """The rows of a sweep, in grid order (``workers`` 0: in this process; ``out``: a folder to resume from)."""
    return run_study(study, out, workers=workers, progress=progress)
