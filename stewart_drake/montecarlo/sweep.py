"""Grid sweeps (e.g. sample period × latency mode × gain scaling) on the Monte Carlo machinery: one run per
grid point, each point's values replacing the draws of those keys (``Study.grid``), run in this process
or on Dask like any study."""

from __future__ import annotations

import itertools

from stewart_drake.core.geometry import Platform
from stewart_drake.drake.integrators import DEFAULT_INTEGRATOR
from stewart_drake.montecarlo.scenario import Study
from stewart_drake.montecarlo.spec import KEYS, SpecError, VarySpec, check_key
from stewart_drake.montecarlo.study import run_study


def sweep_study(
    platform: Platform,
    axes: dict,
    trajectory: str = "seed",
    controller: str = "fixed",
    duration: float | None = None,
    plant_step: float = 1e-3,
    integrator: str = DEFAULT_INTEGRATOR,
    engine: str = "python",
) -> Study:
    """The ``Study`` of the cartesian product of ``axes`` (``{key: [SI values]}``, keys of ``spec.KEYS``;
    the first key varies slowest): point i is run i."""
    for k, values in axes.items():
        check_key(k, "sweep")
        if KEYS[k][1]:
            raise SpecError(SpecError.SWEEP_VECTOR.format(key=k))
        if not len(values):
            raise SpecError(SpecError.SWEEP_EMPTY.format(key=k))
    keys = list(axes)
    grid = tuple(dict(zip(keys, point)) for point in itertools.product(*(axes[k] for k in keys)))
    return Study(
        platform,
        VarySpec({}, "sweep"),
        seed=0,
        runs=len(grid),
        trajectory=trajectory,
        controller=controller,
        duration=duration,
        plant_step=plant_step,
        integrator=integrator,
        engine=engine,
        grid=grid,
    )


def run_sweep(study: Study, workers: int = 0, out=None, progress: bool = False) -> list[dict]:
    """The rows of a sweep, in grid order (``workers`` 0: in this process; ``out``: a folder to resume from)."""
    return run_study(study, out, workers=workers, progress=progress)
