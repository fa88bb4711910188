"""A study's summary (percentiles, worst run, sensitivity) and its files (Parquet, CSV, JSON, plots).

Sensitivity: the Spearman rank correlation of each drawn parameter with each error metric over the
runs (``scipy.stats.spearmanr``; a monotone relation gives ±1 whatever its shape). Parameters that do
not vary are left out; the ``latency`` mode enters as its index in ``LATENCY_MODES``.
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np

from stewart_drake.control.chatter import CHATTER_RANGE_FRACTION
from stewart_drake.montecarlo.spec import LATENCY_MODES
from stewart_drake.system.jsonout import dumps_strict

METRICS = (
    "max_leg_error_m",
    "rms_leg_error_m",
    "max_position_error_m",
    "rms_position_error_m",
    "max_angle_error_rad",
    "rms_angle_error_rad",
    "saturated_ticks",
    "saturated_leg_ticks",
    "force_ripple_rms_N",
    "chatter_ratio",
    "longest_saturation_s",
)
# The verdict columns of a row: simulate's verdicts on the run (``control.verdict.run_verdict``).
VERDICT_COLUMNS = (
    "force_ripple_rms_N",  # the largest leg's force ripple (RMS of force − quasi-static force), N
    "chatter_ratio",  # ripple / working force, largest over the legs
    "ripple_range_fraction",  # largest ripple / command range
    "longest_saturation_s",  # the longest stretch a leg's command stayed saturated, s
    "chatter",  # the loop chatters (ripple above the working force and the range bound)
    "saturated",  # a leg saturated too long in one stretch, or at the reference's start or end
    "tracking_failed",  # a leg or plate position error beyond simulate's bound (a fraction of the stroke)
    "failures",  # simulate's failure messages, joined by FAILURE_SEPARATOR ("" when none)
)
FAILURE_SEPARATOR = " | "
# Row fields that are not drawn parameters.
NOT_PARAMETERS = set(METRICS) | set(VERDICT_COLUMNS) | {"run", "seed", "lost_tracking", "error", "wall_s"}
PERCENTILES = (5, 50, 95, 99)
WORST_BY = "max_leg_error_m"


def parameter_columns(rows: list[dict]) -> list[str]:
    """The drawn parameters that vary over ``rows`` (in row order)."""
    cols = [k for k in rows[0] if k not in NOT_PARAMETERS]
    return [k for k in cols if len({r[k] for r in rows}) > 1]


def _numeric(rows, k) -> np.ndarray:
    if k == "latency":
        return np.array([LATENCY_MODES.index(r[k]) for r in rows], float)
    return np.array([r[k] for r in rows], float)


def sensitivity(rows: list[dict], metric: str = WORST_BY, p_values: bool = True) -> list[dict]:
    """``[{"parameter", "spearman", "p_value"}]`` sorted by |ρ| (largest first), over the runs whose
    ``metric`` is finite. ``p_values=False``: ρ alone (no ``"p_value"``), by ``spearman_rho``, without importing
    ``scipy.stats`` (~0.6 s of CPU in a fresh process, more than the rest of a small study's summary)."""
    if p_values:
        from scipy.stats import spearmanr as rank_correlation
    else:

        def rank_correlation(x, y):
            return spearman_rho(x, y), math.nan

    ok = [r for r in rows if math.isfinite(float(r[metric]))]
    if len(ok) < 3:
        return []
    y = _numeric(ok, metric)
    out = []
    if np.ptp(y) == 0:  # a metric no parameter moved: no correlation (scipy warned on stderr)
        return out
    for k in parameter_columns(ok):
        x = _numeric(ok, k)
        if np.ptp(x) == 0:
            continue
        rho, p = rank_correlation(x, y)
        if math.isfinite(rho):
            out.append({"parameter": k, "spearman": float(rho)} | ({"p_value": float(p)} if p_values else {}))
    return sorted(out, key=lambda d: -abs(d["spearman"]))


def spearman_rho(x, y) -> float:
    """Spearman's ρ of ``x`` and ``y`` (n,) as ``scipy.stats.spearmanr`` computes it, bit for bit: the average
    ranks of each (tied values share the mean of their positions, halves and integers: exact in float64), then
    ``np.corrcoef`` of the (n, 2) rank columns; NaN if either holds a NaN (scipy's default ``propagate``)."""
    a = np.column_stack((x, y)).astype(float)
    if np.isnan(a).any():
        return math.nan
    ranks = np.column_stack([_average_ranks(c) for c in a.T])
    return float(np.corrcoef(ranks, rowvar=False)[1, 0])


def _average_ranks(v: np.ndarray) -> np.ndarray:
    """``(n,)`` 1-based ranks of ``v`` (n,), ties given the mean of their ranks (``rankdata(method="average")``)."""
    order = np.argsort(v, kind="mergesort")
    s = v[order]
    group = np.cumsum(np.r_[True, s[1:] != s[:-1]])  # 1-based group of each sorted value
    ends = np.r_[0, np.flatnonzero(np.r_[s[1:] != s[:-1], True]) + 1]  # ends[g]: values in groups 1 … g
    ranks = np.empty(len(v))
    ranks[order] = 0.5 * (ends[group] + ends[group - 1] + 1)
    return ranks


def summarise(rows: list[dict], settings: dict, key: str) -> dict:
    """The study's summary: per metric the percentiles, mean and max; the worst run (largest
    ``WORST_BY``); the runs that lost tracking (``lost_tracking_runs``) and those that failed
    (``failed_runs``: ``{"run", "reason"}``, a run whose simulation failed or that ``simulate``'s verdicts
    fail: chatter, saturation, tracking); ``ok``: neither; the sensitivity ranking per leg and pose metric."""
    stats = {}
    for m in METRICS:
        v = _numeric(rows, m)
        v = v[np.isfinite(v)]
        stats[m] = (
            (
                {f"p{q}": float(np.percentile(v, q)) for q in PERCENTILES}
                | {"mean": float(v.mean()), "max": float(v.max())}
            )
            if v.size
            else {}
        )
    finite = [r for r in rows if math.isfinite(float(r[WORST_BY]))]
    worst = max(finite, key=lambda r: r[WORST_BY]) if finite else rows[0]
    wall = np.array([r["wall_s"] for r in rows], float)
    lost = [r["run"] for r in rows if r["lost_tracking"]]
    failed = [{"run": r["run"], "reason": r["error"] or r["failures"]} for r in rows if r["error"] or r["failures"]]
    return {
        "key": key,
        "runs": len(rows),
        "settings": settings,
        "ok": not lost and not failed,
        "lost_tracking_runs": lost,
        "failed_runs": failed,
        "metrics": stats,
        "worst_run": {"run": worst["run"], "seed": worst["seed"], "by": WORST_BY, **{m: worst[m] for m in METRICS}},
        "sensitivity": {m: sensitivity(rows, m) for m in ("max_leg_error_m", "max_position_error_m")},
        "varied_parameters": parameter_columns(rows),
        "run_wall_s": {"sum": float(wall.sum()), "mean": float(wall.mean())},
    }


def write_table(rows: list[dict], folder: Path) -> list[Path]:
    """``results.parquet`` (pyarrow) and ``results.csv`` (floats as Python's shortest exact repr)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    pq_path = folder / "results.parquet"
    pq.write_table(pa.Table.from_pylist(rows), pq_path)
    csv_path = folder / "results.csv"
    with csv_path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(list(rows[0]))
        w.writerows([[repr(v) if isinstance(v, float) else v for v in r.values()] for r in rows])
    return [pq_path, csv_path]


def read_table(folder) -> list[dict]:
    """The rows of ``folder/results.parquet`` in run order."""
    import pyarrow.parquet as pq

    return sorted(pq.read_table(Path(folder) / "results.parquet").to_pylist(), key=lambda r: r["run"])


def write_plots(rows: list[dict], summary: dict, folder: Path) -> list[Path]:
    """``distributions.png`` (histograms of the leg and pose errors and of the force ripple, against the chatter
    bound) and ``sensitivity.png`` (the leg error against the most influential parameter, and the ranking). Drawn
    on ``Figure`` objects, not pyplot, so that the caller's backend (a notebook's inline figures) is left as it
    was."""
    # deferred: matplotlib is loaded only when a study writes its plots
    from matplotlib.figure import Figure

    paths = []
    ripple = "ripple_range_fraction" in rows[0]  # the loop's force ripple, when the runs were judged
    fig = Figure(figsize=(17 if ripple else 13, 3.6))
    ax = fig.subplots(1, 4 if ripple else 3)
    if ripple:  # what the chatter verdict sees: the ripple against its share of the command range
        v = _numeric(rows, "ripple_range_fraction")
        ax[3].hist(v[np.isfinite(v)] * 100, bins=max(5, min(40, len(rows) // 5)))
        ax[3].axvline(CHATTER_RANGE_FRACTION * 100, color="red", linestyle="--", label="chatter bound")
        ax[3].set_xlabel("force ripple [% of the command range]")
        ax[3].legend(fontsize=7)
    for a, (m, scale, label) in zip(
        ax,
        [
            ("max_leg_error_m", 1e3, "max leg error [mm]"),
            ("max_position_error_m", 1e3, "max position error [mm]"),
            ("max_angle_error_rad", 180 / np.pi, "max angle error [deg]"),
        ],
    ):
        v = _numeric(rows, m)
        a.hist(v[np.isfinite(v)] * scale, bins=max(5, min(40, len(rows) // 5)))
        a.set_xlabel(label)
    ax[0].set_ylabel("runs")
    fig.suptitle(f"{len(rows)} runs")
    paths.append(folder / "distributions.png")
    fig.savefig(paths[-1], dpi=100, bbox_inches="tight")
    ranking = summary["sensitivity"]["max_leg_error_m"]
    fig = Figure(figsize=(13, 4), layout="constrained")
    ax = fig.subplots(1, 2)
    if ranking:
        top = ranking[0]["parameter"]
        ax[0].scatter(_numeric(rows, top), _numeric(rows, "max_leg_error_m") * 1e3, s=8)
        ax[0].set_xlabel(top)
        ax[0].set_ylabel("max leg error [mm]")
        ax[0].set_title(f"most influential: ρ = {ranking[0]['spearman']:.2f}")
        shown = ranking[:12][::-1]
        ax[1].barh([d["parameter"] for d in shown], [d["spearman"] for d in shown])
        ax[1].set_xlabel("Spearman ρ with max leg error")
    paths.append(folder / "sensitivity.png")
    fig.savefig(paths[-1], dpi=100, bbox_inches="tight")
    return paths


def write_outputs(out, rows: list[dict], summary: dict) -> list[Path]:
    """Replace ``out`` atomically with the table, ``summary.json``, ``study.json`` and the plots. ``out``: a
    path, or an ``output_folder.OutputFolder`` checked before the runs."""
    from stewart_drake.system.output_folder import OutputFolder, atomic_folder

    folder, out = out, Path(out.typed if isinstance(out, OutputFolder) else out)
    with atomic_folder(folder) as tmp:
        written = write_table(rows, tmp) + write_plots(rows, summary, tmp)
        (tmp / "study.json").write_text(
            json.dumps({"key": summary["key"], "runs": summary["runs"], "settings": summary["settings"]}, indent=2)
        )
        (tmp / "summary.json").write_text(dumps_strict(summary))  # NaN metrics of failed runs: null, strict JSON
        written += [tmp / "study.json", tmp / "summary.json"]
        names = [p.name for p in written]
    return [out / n for n in names]
