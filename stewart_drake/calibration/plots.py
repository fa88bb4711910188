"""Figures of a calibration (matplotlib; imported only when drawing): residuals per pose before and after,
and the parameter corrections with their σ."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from stewart_drake.calibration.identify import CalibrationResult


def plot_calibration(result: CalibrationResult, folder: Path) -> list[str]:
    """Write ``residuals.png`` and ``corrections.png`` into ``folder``; returns their names."""
    import matplotlib.pyplot as plt  # deferred: importing pyplot picks a backend (commands select Agg first)

    before = result.pose_rms_before
    after = result.pose_rms_after
    fig, ax = plt.subplots(figsize=(8, 3.5))
    x = np.asarray(result.lines)
    ax.semilogy(x, before, "o-", label="nominal model", color="tab:red")
    ax.semilogy(x, after, "o-", label="calibrated model", color="tab:blue")
    for o in result.outliers:
        k = int(np.flatnonzero(x == o["line"])[0])
        ax.annotate(f"line {o['line']}", (x[k], after[k]), fontsize=7)
    ax.set_xlabel("pose (its line in the measurement file)")
    ax.set_ylabel("residual RMS, in σ of the stated noise")
    ax.set_title(f"{result.nominal.name}: residuals per pose ({result.layout.kind} data)", fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(folder / "residuals.png", dpi=110)
    plt.close(fig)

    names = result.layout.names
    corr = result.corrections * 1e6
    sig = result.sigma * 1e6
    fig, ax = plt.subplots(figsize=(max(8, 0.18 * len(names)), 4))
    idx = np.arange(len(names))
    fixed = ~result.identifiability.free
    ax.bar(idx[~fixed], corr[~fixed], yerr=2 * sig[~fixed], color="tab:blue", capsize=2, label="correction ± 2σ")
    if fixed.any():
        ax.bar(idx[fixed], corr[fixed] + 0.0, color="lightgray", edgecolor="gray", label="fixed by convention (0)")
    ax.set_xticks(idx, names, rotation=90, fontsize=6)
    ax.set_ylabel("µm (a gain: its error × L_ref)")
    ax.set_title("identified corrections to the nominal geometry", fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(folder / "corrections.png", dpi=110)
    plt.close(fig)
    return ["residuals.png", "corrections.png"]
