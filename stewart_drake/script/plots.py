"""Figures of a program's run: leg lengths (with the stroke), leg forces, simulated tracking error."""

from __future__ import annotations

import numpy as np


def _move_marks(ax, result):
    traj = result.trajectory
    t0 = 0.0
    for s in traj.segments:
        t0 += s.duration
        if s.kind == "move":
            ax.axvline(t0, color="0.85", lw=0.8, zorder=0)


def plot_lengths(result, platform_name: str, stroke_mm=None, ax=None):
    """Leg lengths (mm) against time; the stroke limits dashed when given."""
    import matplotlib.pyplot as plt

    fig = None
    if ax is None:
        fig, ax = plt.subplots(figsize=(8, 3.6))
    t = result.trajectory.t
    for i in range(6):
        ax.plot(t, result.L[:, i] * 1e3, label=f"L{i + 1}")
    if stroke_mm is not None:
        for v in stroke_mm:
            ax.axhline(v, color="k", ls="--", lw=0.8)
    _move_marks(ax, result)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("leg length (mm)")
    name = platform_name.replace("$", r"\$")  # a name is text, not mathtext
    ax.set_title(f"leg lengths, platform {name} (grey: end of each move)")
    ax.legend(fontsize=8, ncol=6)
    return fig or ax.figure


def plot_forces(result, ax=None):
    """Leg forces (N, > 0 pushes the plate away from the base) against time."""
    import matplotlib.pyplot as plt

    fig = None
    if ax is None:
        fig, ax = plt.subplots(figsize=(8, 3.6))
    t = result.trajectory.t
    for i in range(6):
        ax.plot(t, result.F[:, i], label=f"F{i + 1}")
    _move_marks(ax, result)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("leg force (N)")
    ax.set_title("leg forces (inverse dynamics, massless legs)")
    ax.legend(fontsize=8, ncol=6)
    return fig or ax.figure


def plot_tracking(log, length_error):
    """Simulated leg-length error (mm) against time."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 3.2))
    for i in range(6):
        ax.plot(log.t, np.asarray(length_error)[:, i] * 1e3, label=f"leg {i + 1}")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("L − L_ref (mm)")
    ax.set_title(f"controller in the loop ({log.kind}): leg-length tracking error")
    ax.legend(fontsize=8, ncol=6)
    return fig
