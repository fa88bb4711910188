"""The files of a synthesis: ``pareto.parquet``/``pareto.csv`` (the front), ``pareto.png``, ``design.yaml``
(an ordinary platform file), ``requirements.json`` (each requirement: required, achieved, margin, how
established; the proof) and ``evaluations.jsonl`` (every evaluated design, for resume)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import yaml

from stewart_drake.synthesis.families import design_yaml_fields
from stewart_drake.synthesis.requirements import OBJECTIVES
from stewart_drake.synthesis.search import CACHE
from stewart_drake.system.jsonout import dumps_strict

METRIC_COLUMNS = {
    "peak_force": "peak_force_N",
    "peak_speed": "peak_speed_m_s",
    "L_min": "L_min_m",
    "L_max": "L_max_m",
    "stroke": "stroke_m",
    "stroke_ratio": "stroke_ratio",
    "base_radius": "base_radius_m",
    "frequency": "frequency_hz",
    "condition": "condition",
    "max_joint_angle": "max_joint_angle_rad",
    "min_leg_distance": "min_leg_distance_m",
}


def front_table(result) -> dict:
    """Columns of the front (one row per design, by the first objective): the variables (m, deg), the
    metrics (SI) and ``chosen``."""
    req = result.search.requirements
    rows = result.search.front_rows()
    cols: dict = {"row": list(range(1, len(rows) + 1))}
    for j, name in enumerate(req.variables):
        angle = name.endswith("half_angle")
        cols[f"x_{name}_{'deg' if angle else 'm'}"] = [
            float(np.degrees(r["x"][j])) if angle else float(r["x"][j]) for r in rows
        ]
    for key, col in METRIC_COLUMNS.items():
        cols[col] = [float(r[key]) for r in rows]
    cols["chosen"] = [i == result.chosen for i in result.search.front]
    return cols


def design_yaml(result, source: str) -> str:
    """The chosen design as a platform file (metres): anchors, stroke, home height, the payload as the plate,
    the actuator's limits as the legs'."""
    req, row, p = result.search.requirements, result.design, result.platform
    I = p.inertia
    legs = {"max_force": float(req.max_force), "stiffness": float(req.stiffness)}
    if req.max_speed is not None:
        legs["max_speed"] = float(req.max_speed)
    doc = {
        "name": p.name,
        "description": f"synthesised by stewart-drake optimize from {source} (family {req.family}, seed {result.search.seed})",
        "length_unit": "m",
        **design_yaml_fields(req, row["x"]),
        "stroke": [float(row["L_min"]), float(row["L_max"])],
        "home_height": float(p.home_height),
        "plate": {
            "mass": float(p.mass),
            "com": [float(v) for v in p.com],
            "inertia": [float(I[0, 0]), float(I[1, 1]), float(I[2, 2]), float(I[0, 1]), float(I[0, 2]), float(I[1, 2])],
        },
        "legs": legs,
    }
    head = (
        f"# A platform file written by stewart-drake optimize: the design chosen ({result.pick}) on the Pareto front.\n"
        f"# Proof of the required box: {result.proof.status} ({result.proof.cells_examined} cells). Every command takes it.\n"
    )
    return head + yaml.safe_dump(doc, sort_keys=False, default_flow_style=None, width=120)


def pareto_figure(result):
    """The front (first two objectives; the one objective against stroke when there is one), every feasible
    design evaluated in grey, the chosen design marked."""
    # deferred: pyplot only when a figure is drawn, after selecting the Agg backend
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    req = result.search.requirements
    names = list(req.objectives) + (
        ["stroke"] if len(req.objectives) == 1 and req.objectives[0] != "stroke" else ["peak_force"]
    )
    names = names[:2]
    keys = [OBJECTIVES[n][0] for n in names]
    units = [OBJECTIVES[n][2] for n in names]
    feas = [r for r in result.search.rows if r["error"] is None and max(r["g"]) <= 0]
    front = result.search.front_rows()
    fig, ax = plt.subplots(figsize=(5.5, 4.2))
    if feas:
        ax.scatter([r[keys[0]] for r in feas], [r[keys[1]] for r in feas], s=8, c="0.75", label="feasible designs")
    ax.plot([r[keys[0]] for r in front], [r[keys[1]] for r in front], "o-", ms=4, label="Pareto front")
    ax.plot([result.design[keys[0]]], [result.design[keys[1]]], "r*", ms=14, label=f"chosen ({result.pick})")
    ax.set_xlabel(f"{names[0]} [{units[0]}]" if units[0] else names[0])
    ax.set_ylabel(f"{names[1]} [{units[1]}]" if units[1] else names[1])
    ax.set_title(f"{req.name or 'requirements'}: {len(front)} designs on the front")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    return fig


def write_outputs(result, tmp: Path, source: str, cache_from: Path | None = None) -> list[Path]:
    """Write every file into the folder ``tmp`` (the atomic output folder's temporary); ``cache_from``: the
    running search's ``evaluations.jsonl`` copied along (resume after the run)."""
    import matplotlib.pyplot as plt  # deferred: pyplot and parquet only when files are written (Agg set by pareto_figure)
    import pyarrow as pa
    import pyarrow.csv as pcsv
    import pyarrow.parquet as pq

    table = pa.table(front_table(result))
    pq.write_table(table, tmp / "pareto.parquet")
    pcsv.write_csv(table, tmp / "pareto.csv")
    fig = pareto_figure(result)
    fig.savefig(tmp / "pareto.png", dpi=110, bbox_inches="tight")
    plt.close(fig)
    (tmp / "design.yaml").write_text(design_yaml(result, source), encoding="utf-8")
    (tmp / "requirements.json").write_text(
        dumps_strict(
            {
                "source": source,
                "ok": result.ok,
                "requirements": result.table,
                "proof": result.proof.to_dict(),
                "performance_proof": result.performance.to_dict(),
                "design": {k: v for k, v in result.design.items() if k not in ("g", "f")},
                "requirements_si": result.search.requirements.to_dict(),
            }
        ),
        encoding="utf-8",
    )
    (tmp / "search.json").write_text(
        json.dumps(result.search.to_dict() | {"front": len(result.search.front)}), encoding="utf-8"
    )
    written = [
        tmp / n
        for n in ("pareto.parquet", "pareto.csv", "pareto.png", "design.yaml", "requirements.json", "search.json")
    ]
    if cache_from is not None and cache_from.exists():
        (tmp / CACHE).write_bytes(cache_from.read_bytes())
        written.append(tmp / CACHE)
    return written
