"""Figures of a program's run: leg lengths (with the stroke), leg forces, simulated tracking error."""

from __future__ import annotations

import numpy as np

# More move ends than this are not marked one by one (a line each would cost seconds per thousand).
MAX_MARKS = 200


def _move_marks(ax, result):
    """Grey vertical lines at the ends of the moves, as one collection (none beyond ``MAX_MARKS``)."""
    traj = result.trajectory
    ends = np.cumsum([s.duration for s in traj.segments])
    marks = [t for t, s in zip(ends, traj.segments) if s.kind == "move"]
    if 0 < len(marks) <= MAX_MARKS:
        ax.vlines(marks, 0, 1, transform=ax.get_xaxis_transform(), color="0.85", lw=0.8, zorder=0)


def plot_lengths(result, platform_name: str, stroke_mm=None, ax=None):
    """Leg lengths (mm) against time; the stroke limits dashed when given."""
    import matplotlib.pyplot as plt  # deferred: importing pyplot picks a backend (commands select Agg first)

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
    ax.legend(fontsize=8, ncol=6, loc="upper right")
    return fig or ax.figure


def plot_forces(result, ax=None):
    """Leg forces (N, > 0 pushes the plate away from the base) against time."""
    import matplotlib.pyplot as plt  # deferred: importing pyplot picks a backend (commands select Agg first)

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
    ax.legend(fontsize=8, ncol=6, loc="upper right")
    return fig or ax.figure


def plot_tracking(log, length_error):
    """Simulated leg-length error (mm) against time."""
    import matplotlib.pyplot as plt  # deferred: importing pyplot picks a backend (commands select Agg first)

    fig, ax = plt.subplots(figsize=(8, 3.2))
    for i in range(6):
        ax.plot(log.t, np.asarray(length_error)[:, i] * 1e3, label=f"leg {i + 1}")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("L − L_ref (mm)")
    ax.set_title(f"controller in the loop ({log.kind}): leg-length tracking error")
    ax.legend(fontsize=8, ncol=6, loc="upper right")
    return fig
