"""Figures of a workspace: the paper's top, front and side views and the 3-D boundary (matplotlib is
imported only when they are drawn).
"""

from __future__ import annotations

import numpy as np

from stewart_drake.workspace.grid import Workspace
from stewart_drake.workspace.limits import AXES


def view_figures(ws: Workspace, reference=None, title: str = "") -> dict:
    """The paper's views of a workspace: ``{"top": X–Y, "front": X–Z, "side": Y–Z, "3d": boundary}``
    matplotlib figures (axes in metres). ``reference``: optional (3, 2) extents drawn dashed (e.g. a
    paper's numbers)."""
    import matplotlib.pyplot as plt  # deferred: importing pyplot picks a backend (commands select Agg first)

    x, y, z = ws.axes
    views = {"top": (x, y, ws.top, 0, 1), "front": (x, z, ws.front, 0, 2), "side": (y, z, ws.side, 1, 2)}
    names = {"top": "top view X–Y", "front": "front view X–Z", "side": "side view Y–Z"}
    figs = {}
    for name, (u, v, mask, ku, kv) in views.items():
        fig, ax = plt.subplots(figsize=(4.6, 4.2))
        ax.contourf(u, v, mask.T.astype(float), levels=[0.5, 1.5], colors=["#9ecae1"])
        ax.contour(u, v, mask.T.astype(float), levels=[0.5], colors=["#08519c"], linewidths=1)
        ax.axvline(ws.extents[ku, 0], color="k", lw=0.6, ls=":")
        ax.axvline(ws.extents[ku, 1], color="k", lw=0.6, ls=":")
        ax.axhline(ws.extents[kv, 0], color="k", lw=0.6, ls=":")
        ax.axhline(ws.extents[kv, 1], color="k", lw=0.6, ls=":")
        if reference is not None:
            ref = np.asarray(reference, dtype=float)
            ax.plot(ref[ku][[0, 1, 1, 0, 0]], ref[kv][[0, 0, 1, 1, 0]], "r--", lw=1, label="paper extents")
            ax.legend(loc="upper right", fontsize=7)
        ax.set_xlabel(f"{AXES[ku].upper()} (m)")
        ax.set_ylabel(f"{AXES[kv].upper()} (m)")
        ax.set_aspect("equal")
        ax.set_title(f"{title} {names[name]}".strip(), fontsize=9)
        figs[name] = fig
    fig = plt.figure(figsize=(5.5, 4.8))
    ax = fig.add_subplot(projection="3d")
    pts = ws.boundary
    if len(pts) > 15000:
        pts = pts[np.random.default_rng(0).choice(len(pts), 15000, replace=False)]
    ax.scatter(pts[:, 0], pts[:, 1], pts[:, 2], c=pts[:, 2], s=1, cmap="viridis")
    ax.set_xlabel("X (m)")
    ax.set_ylabel("Y (m)")
    ax.set_zlabel("Z (m)")
    ax.set_title(f"{title} boundary (3D)".strip(), fontsize=9)
    figs["3d"] = fig
    return figs
