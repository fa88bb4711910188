"""The public API of design synthesis (``sd.load_requirements``, ``sd.optimize``, ``sd.prove_workspace``). It sits
in the synthesis layer (above ``api``, like ``montecarlo.api``) because it calls the search and the proof; the
checks of ``optimize`` and ``workspace --require-box --prove`` live here, once."""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from contextlib import nullcontext
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from stewart_drake.api.platform import load_platform
from stewart_drake.api.result import Result
from stewart_drake.core.argcheck import check_path, check_shape, param
from stewart_drake.core.geometry import Platform
from stewart_drake.core.leg_bodies import leg_dimensions
from stewart_drake.core.rotations import to_radians
from stewart_drake.core.sanity import check_finite, check_work
from stewart_drake.errors import OptionError, SynthesisError
from stewart_drake.synthesis.outputs import METRIC_COLUMNS
from stewart_drake.synthesis.proof import MAX_CELLS, ProofResult, prove_requirements_box
from stewart_drake.synthesis.requirements import Requirements
from stewart_drake.synthesis.requirements import load_requirements as read_requirements
from stewart_drake.synthesis.search import DEFAULT_POP
from stewart_drake.synthesis.synthesize import SynthesisResult, synthesize
from stewart_drake.system.output_folder import run_lock

BOX_AXES = ("px", "py", "pz", "a", "b", "g")
PROOF_LIMITS = ("stroke", "joints", "collision")
MAX_PROOF_CELLS = 10_000_000


def load_requirements(path: str | Path) -> Requirements:
    """The requirements of a design synthesis from a YAML file (``stewart-drake init --requirements-template``),
    checked: every bad field is named with its file and line.

    Args:
        path: the requirements file.

    Returns:
        The requirements (SI units): variables and their bounds, the box, payload, rates, actuator, limits.

    Raises:
        StewartError: a missing or invalid file (file, line and field named).
    """
    path = check_path(path, "path")
    return read_requirements(path)


@dataclass(repr=False)
class OptimizeResult(Result):
    """A design synthesis (``optimize``).

    Attributes:
        platform: the chosen design (write it with ``Platform.to_yaml``).
        synthesis: the search (every design evaluated, the Pareto front), the chosen row, its proof and the
            requirements table.
    """

    platform: Platform
    synthesis: SynthesisResult

    @property
    def ok(self) -> bool:
        """Every requirement met and the box proven on the chosen design."""
        return bool(self.synthesis.ok)

    @property
    def proof(self) -> ProofResult:
        """The proof of the requirements' box on the chosen design."""
        return self.synthesis.proof

    @property
    def pareto(self) -> dict:
        """The Pareto front, one entry per design (by the first objective): ``variables`` (names), ``x``
        ``(n, k)`` (m, rad), each metric ``(n,)`` in SI (``peak_force`` N, ``L_min`` m, ``frequency`` Hz, ...)
        and ``chosen`` ``(n,)`` bool."""
        s = self.synthesis.search
        rows = s.front_rows()
        out: dict = {
            "variables": list(s.requirements.variables),
            "x": np.array([r["x"] for r in rows], dtype=float).reshape(len(rows), -1),
        }
        for key in METRIC_COLUMNS:
            out[key] = np.array([float(r[key]) for r in rows])
        out["chosen"] = np.array([i == self.synthesis.chosen for i in s.front], dtype=bool)
        return out

    def _fields(self) -> dict:
        return self.synthesis.to_dict()


def optimize(
    requirements: str | Path | Requirements,
    *,
    budget: int = 480,
    seed: int = 0,
    workers: int = 0,
    scheduler: str | None = None,
    pick: str = "knee",
    pop_size: int = DEFAULT_POP,
    max_cells: int = MAX_CELLS,
    cache: str | Path | None = None,
    progress: bool = False,
) -> OptimizeResult:
    """Design synthesis: the geometry with the smallest actuators that meets the requirements (NSGA-II, on Dask
    when ``workers`` > 0 or ``scheduler``), a design picked from the Pareto front, the requirements' box proven
    on it (interval cover) and every requirement tabulated.

    Args:
        requirements: a requirements file (see ``load_requirements``) or loaded requirements.
        budget: design evaluations (whole generations).
        seed: search seed (the result is the same at any worker count).
        workers: LocalCluster worker processes (0: in this process, no Dask).
        scheduler: the address of an existing Dask scheduler instead (``tcp://HOST:PORT``).
        pick: the design chosen: ``"knee"``, the best of an objective, or a row of the front.
        pop_size: NSGA-II population.
        max_cells: the most cells each proof may examine (the box's, and the force, speed, frequency and condition
            one's): a proof starts with 200,000 and doubles its budget up to this while the volume left unproven
            shrinks; a proof that runs out is ``unresolved`` (not proven yet), with the cells used and left.
        cache: a folder whose evaluations (of the same requirements and seed) are reused and extended; its journal
            is verified line by line, and the folder is held (locked) while the search runs.
        progress: show a progress bar.

    Returns:
        The chosen platform, the Pareto front and the proof; ``ok`` when every requirement is met.

    Raises:
        StewartError: an invalid requirements file or option, a ``cache`` journal that does not verify
            (``JournalError``, naming the file and line) or a ``cache`` folder another run holds (``OutputError``).
    """
    req = requirements if isinstance(requirements, Requirements) else read_requirements(requirements)
    if workers is not None and workers < 0:
        raise OptionError(OptionError.AT_LEAST.format(option="--workers", min=0, value=workers))
    if workers:
        check_work("--workers", str(workers), workers, "worker processes", 150e6, max_count=4 * (os.cpu_count() or 1))
    if pop_size < 2:
        raise OptionError(OptionError.AT_LEAST.format(option="--pop-size", min=2, value=pop_size))
    if not 1 <= max_cells <= MAX_PROOF_CELLS:
        raise OptionError(OptionError.BETWEEN.format(option="--max-cells", lo=1, hi=MAX_PROOF_CELLS, value=max_cells))
    if seed < 0:
        raise OptionError(OptionError.AT_LEAST.format(option="--seed", min=0, value=seed))
    held = nullcontext() if cache is None else run_lock(cache, option="cache", typed=str(cache))
    with held:  # one search at a time appends to a folder's journal
        result = synthesize(
            req,
            None if cache is None else Path(cache),
            budget,
            seed,
            workers or 0,
            scheduler,
            pick,
            progress=progress,
            max_cells=max_cells,
            pop_size=pop_size,
        )
    return OptimizeResult(result.platform, result)


@dataclass(repr=False)
class WorkspaceProof(Result):
    """The proof that every pose of a box is reachable (``prove_workspace``).

    Attributes:
        platform: the platform's name.
        convention: Euler convention of the box's angles.
        proof: ``status`` (``"proven"``, ``"violated"`` with a ``witness`` pose, ``"unresolved"``), the cells
            examined, the proven leg-length range and least stroke margin.
        joint_cone: the joints' cone half-angle checked, rad (None: joints not checked).
        leg_diameter: the legs' diameter checked for collision, m (None: not checked).
    """

    platform: str
    convention: str
    proof: ProofResult
    joint_cone: float | None = None
    leg_diameter: float | None = None

    @property
    def proven(self) -> bool:
        """Every pose of the box is proven within the limits."""
        return self.proof.status == "proven"

    def _fields(self) -> dict:
        return {"platform": self.platform, "convention": self.convention, **self.proof.to_dict()}


def prove_workspace(
    platform: str | Path | Platform,
    box_lo: ArrayLike,
    box_hi: ArrayLike,
    *,
    limits: str | Sequence[str] = "stroke",
    angle_unit: str = "rad",
    joint_cone: float | None = None,
    leg_diameter: float | None = None,
    convention: str = "utn",
    max_cells: int = MAX_CELLS,
) -> WorkspaceProof:
    """Prove (interval cover, rigorous) that every pose of a box relative to home keeps each leg within its
    stroke and the plate above the base, and optionally within the joints' cones and with the legs apart; or
    find a violating pose (checked by the IK), or say what is left unresolved within ``max_cells``.

    Args:
        platform: a preset name, a platform file or a ``Platform``.
        box_lo: ``(6,)`` the box's low corner relative to home: px py pz (m), a b g (``angle_unit``).
        box_hi: ``(6,)`` its high corner.
        limits: ``"stroke"`` (always), ``"joints"``, ``"collision"`` (a comma-separated string or a list).
        angle_unit: unit of the box's angles and of ``joint_cone``.
        joint_cone: the joints' cone half-angle (``"joints"``; default 45°).
        leg_diameter: the legs' diameter, m (``"collision"``; default the model's cylinder).
        convention: Euler convention of the box's angles.
        max_cells: the most cells the proof may examine (1 to 10⁷): it starts with 200,000 and doubles its budget
            up to this while the volume left unproven shrinks.

    Returns:
        The proof; ``proven`` when every pose of the box is within the limits.

    Raises:
        StewartError: a box with low above high or angles beyond 80°, an unknown limit, a bad budget.
    """
    names = [n.strip() for n in limits.split(",") if n.strip()] if isinstance(limits, str) else list(limits)
    other = [n for n in names if n not in PROOF_LIMITS]
    if other:
        raise OptionError(
            OptionError.UNKNOWN_LIMIT.format(
                option="--limits (with --prove)", value=other[0], valid=", ".join(PROOF_LIMITS)
            )
        )
    p = load_platform(platform)
    box = np.stack([check_shape(box_lo, param("box_lo"), (6,)), check_shape(box_hi, param("box_hi"), (6,))], axis=1)
    check_finite(box, param("box"))
    for j, (lo, hi) in enumerate(box):
        if lo > hi:
            raise OptionError(
                SynthesisError.BOX_OPTION.format(axis=BOX_AXES[j], lo=lo, hi=hi, problem="low is above high")
            )
    if not 1 <= max_cells <= MAX_PROOF_CELLS:
        raise OptionError(OptionError.BETWEEN.format(option="--max-cells", lo=1, hi=MAX_PROOF_CELLS, value=max_cells))
    box[3:] = to_radians(box[3:], angle_unit)
    if np.any(np.abs(box[3:]) > np.radians(80.0)):
        raise OptionError(SynthesisError.BOX_OPTION.format(axis="a/b/g", lo="", hi="", problem="angles beyond 80 deg"))
    cone = None
    if "joints" in names:
        cone = math.radians(45.0) if joint_cone is None else float(to_radians(joint_cone, angle_unit))
    diameter = None
    if "collision" in names:
        diameter = leg_diameter if leg_diameter is not None else 2 * leg_dimensions(p)["cylinder_radius"]
        if not (math.isfinite(diameter) and diameter > 0):
            raise OptionError(OptionError.POSITIVE.format(option="--leg-diameter", unit="metres", value=diameter))
    proof = prove_requirements_box(
        p, box[:, 0], box[:, 1], convention, max_cells=max_cells, joint_cone=cone, leg_diameter=diameter
    )
    return WorkspaceProof(p.name, convention, proof, cone, diameter)
