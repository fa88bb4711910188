"""From requirements to a chosen, proven design: search, pick, prove, and the table of requirements met.

``synthesize`` is the Python entry point behind ``stewart-drake optimize``: it returns a
``SynthesisResult`` (``to_dict()`` is the command's ``--json``) holding the search, the chosen design as a
``Platform`` and its proof.
"""

from __future__ import annotations

from dataclasses import dataclass

from stewart_drake.core.geometry import Platform
from stewart_drake.synthesis.evaluate import box_vertices
from stewart_drake.synthesis.families import design_platform
from stewart_drake.synthesis.performance import TIGHTEN_CELLS, PerformanceProof, prove_requirements_performance
from stewart_drake.synthesis.proof import MAX_CELLS, ProofResult, prove_requirements_box
from stewart_drake.synthesis.requirements import Requirements
from stewart_drake.synthesis.search import SearchResult, pick_design, run_search


@dataclass
class SynthesisResult:
    """The search, the chosen row (index into ``search.rows``), the chosen design's ``platform``, its
    ``proof`` (the box's poses within the stroke, cones, clearance), its ``performance`` proof (force, speed,
    frequency, condition over the box) and the ``requirements`` table (see ``requirement_table``); ``ok``: every
    requirement met."""

    search: SearchResult
    chosen: int
    pick: str
    platform: Platform
    proof: ProofResult
    performance: PerformanceProof
    table: list

    @property
    def design(self) -> dict:
        return self.search.rows[self.chosen]

    @property
    def ok(self) -> bool:
        return self.proof.status == "proven" and all(r["met"] for r in self.table)

    def to_dict(self) -> dict:
        return {
            "ok": self.ok,
            "pick": self.pick,
            "design": {k: v for k, v in self.design.items() if k not in ("g", "f")},
            "variables": dict(zip(self.search.requirements.variables, self.design["x"], strict=True)),
            "proof": self.proof.to_dict(),
            "performance_proof": self.performance.to_dict(),
            "requirements": self.table,
            "search": self.search.to_dict(),
        }


SAMPLE_NOTE = "the box's {n} vertices and centre (a sample of the box)"


def requirement_table(req: Requirements, row: dict, proof: ProofResult, performance: PerformanceProof) -> list[dict]:
    """Each requirement: ``required``, ``achieved``, ``margin`` (positive: met with room), ``unit``, ``met`` and
    ``established`` (how: proof, exact, or a sample, said so). Force, speed, frequency and condition carry the
    performance proof's ``status`` and ``bound``; ``met`` only when proven."""
    n = len(box_vertices(req.box_lo, req.box_hi))
    sample = SAMPLE_NOTE.format(n=n - 1)
    perf = performance.results
    cells = performance.cells_examined
    box_left = (  # the box's proof ran out of cells: its rows (workspace, joint cone, leg diameter) say how far
        {"cells_used": proof.cells_examined, "cells_left": proof.unresolved_count, "stopped": proof.stopped}
        if proof.status == "unresolved"
        else {}
    )
    out = [
        {
            "requirement": "workspace: every pose of the box within the stroke, plate above the base",
            "required": "every pose",
            "achieved": proof.status,
            "margin": proof.stroke_margin_m,
            "unit": "m",
            "met": proof.status == "proven",
            "established": f"proof over {proof.cells_examined} cells ({proof.method})"
            if proof.status != "unresolved"
            else not_proven(proof.cells_examined, proof.unresolved_count, proof.stopped),
            **box_left,
        },
        _row(
            "actuator.max_force",
            req.max_force,
            row["peak_force"],
            "N",
            "<=",
            "peak leg force over the motion envelope: the search's exact worst case at " + sample,
            perf["force"],
            cells,
        ),
    ]
    if req.max_speed is not None:
        out.append(
            _row(
                "actuator.max_speed",
                req.max_speed,
                row["peak_speed"],
                "m/s",
                "<=",
                "peak leg speed over the motion envelope: the search's exact worst case at " + sample,
                perf["speed"],
                cells,
            )
        )
    if req.stroke_ratio is not None:
        out.append(
            _row(
                "actuator.stroke_ratio",
                req.stroke_ratio,
                row["stroke_ratio"],
                "",
                "<=",
                "L_max / L_min of the design's stroke (exact)",
            )
        )
    else:
        lo, hi = row["L_needed"]
        out.append(
            _row(
                "actuator.stroke (L_min)",
                req.stroke[0],
                lo - req.stroke_margin,
                "m",
                ">=",
                "leg range: angles sampled, position exact; the proof covers every pose",
            )
        )
        out.append(
            _row(
                "actuator.stroke (L_max)",
                req.stroke[1],
                hi + req.stroke_margin,
                "m",
                "<=",
                "leg range: angles sampled, position exact; the proof covers every pose",
            )
        )
    if req.base_radius_max is not None:
        out.append(
            _row("limits.base_radius_max", req.base_radius_max, row["base_radius"], "m", "<=", "exact (anchor radius)")
        )
    if req.min_frequency_hz is not None:
        out.append(
            _row(
                "limits.min_frequency_hz",
                req.min_frequency_hz,
                row["frequency"],
                "Hz",
                ">=",
                "lowest natural frequency: the search's value at " + sample,
                perf["frequency"],
                cells,
            )
        )
    if req.joint_cone is not None:
        out.append(
            {
                "requirement": "limits.joint_cone: every pose of the box, every joint within the cone",
                "required": float(req.joint_cone),
                "achieved": proof.status,
                "margin": None,
                "unit": "rad",
                "met": proof.status == "proven",
                "established": "the proof (l·e_z and l·n bounded on every cell); the search sampled "
                + f"{float(row['max_joint_angle']):.6f} rad at "
                + sample,
                **box_left,
            }
        )
    if req.leg_diameter is not None:
        out.append(
            {
                "requirement": "limits.leg_diameter: every pose of the box, no two legs closer than it",
                "required": float(req.leg_diameter),
                "achieved": proof.status,
                "margin": None,
                "unit": "m",
                "met": proof.status == "proven",
                "established": "the proof (a separating direction between each pair's hulls on every cell); the search "
                + f"sampled {float(row['min_leg_distance']):.6f} m at "
                + sample,
                **box_left,
            }
        )
    if req.max_condition is not None:
        out.append(
            _row(
                "limits.max_condition",
                req.max_condition,
                row["condition"],
                "",
                "<=",
                "worst condition number: the search's value at " + sample,
                perf["condition"],
                cells,
            )
        )
    return out


def _row(name, required, achieved, unit, sense, how, proven: dict | None = None, cells: int = 0) -> dict:
    """A table row; with ``proven`` (a performance proof's entry) the row's ``status``, ``bound`` (the proven
    worst over the box), ``witness`` and ``met`` come from the proof, ``achieved`` stays the search's sample."""
    margin = required - achieved if sense == "<=" else achieved - required
    out = {
        "requirement": name,
        "required": float(required),
        "achieved": float(achieved),
        "margin": float(margin),
        "unit": unit,
        "met": bool(margin >= 0),
        "established": how,
    }
    if proven is not None:
        out.update(status=proven["status"], bound=proven["bound"], met=proven["status"] == "proven")
        if proven["status"] == "proven":
            out["established"] = (
                f"proof over every pose of the box ({cells} cells, synthesis.performance): "
                f"{'at most' if sense == '<=' else 'at least'} {proven['bound']:.6g} {unit}".rstrip()
                + f"; {how}"
            )
        elif proven["status"] == "violated":
            out["witness"] = proven["witness"]
            out["established"] = f"violated at a witness pose (the toolkit's value {proven['witness']['value']:.6g})"
        else:
            left = proven.get("unresolved_count", 0)
            out.update(cells_used=cells, cells_left=left, stopped=proven.get("stopped"))
            out["established"] = f"{not_proven(cells, left, proven.get('stopped'))}; {how}"
    return out


STOPPED = {
    "cap": "the cell cap (--max-cells) was reached",
    "stalled": "the volume of the cells left stopped shrinking",
    None: "the cell budget ran out",
}


def cells_note(used: int, left: int, stopped: str | None) -> str:
    """``(N cells used, M left; why)`` of a proof that ran out of cells."""
    return f"({used} cells used, {left} left; {STOPPED[stopped]})"


def not_proven(used: int, left: int, stopped: str | None) -> str:
    """The verdict of a proof that ran out of cells: ``not proven yet (N cells used, M left; why)``."""
    return f"not proven yet {cells_note(used, left, stopped)}"


def chosen_platform(req: Requirements, row: dict, name: str = "synthesised") -> Platform:
    """The ``Platform`` of an evaluated row: its variables and its stroke."""
    return design_platform(req, row["x"], [row["L_min"], row["L_max"]], name)


def synthesize(
    req: Requirements,
    out=None,
    budget: int = 480,
    seed: int = 0,
    workers: int = 0,
    scheduler: str | None = None,
    pick: str = "knee",
    progress: bool = False,
    max_cells: int = MAX_CELLS,
    pop_size: int | None = None,
    tighten_cells: int = TIGHTEN_CELLS,
) -> SynthesisResult:
    """Search (``search.run_search``), pick a design of the front (``search.pick_design``), prove the box on it
    (``proof.prove_requirements_box``) and tabulate the requirements."""
    kw = {} if pop_size is None else {"pop_size": pop_size}
    result = run_search(req, out, budget, seed, workers, scheduler, progress=progress, **kw)
    k = pick_design(result, pick)
    row = result.rows[k]
    platform = chosen_platform(req, row, req.name or "synthesised")
    proof = prove_requirements_box(
        platform,
        req.box_lo,
        req.box_hi,
        req.convention,
        max_cells=max_cells,
        joint_cone=req.joint_cone,
        leg_diameter=req.leg_diameter,
    )
    performance = prove_requirements_performance(platform, req, max_cells=max_cells, tighten_cells=tighten_cells)
    return SynthesisResult(
        result, k, pick, platform, proof, performance, requirement_table(req, row, proof, performance)
    )
