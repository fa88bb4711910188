"""Drawings of a platform for people: where each anchor is, which leg joins which pair, the base frame, and
the sense of each pose angle (matplotlib is imported only when a figure is drawn)."""

from __future__ import annotations

import numpy as np

from stewart_drake.core.geometry import Platform
from stewart_drake.core.kinematics import plate_anchors

# One colour per leg (matplotlib's tab10 without its greys), so that leg i has the same colour in both views.
LEG_COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b")


def _joint_labels(points: np.ndarray, prefix: str) -> list[tuple[np.ndarray, str]]:
    """``(point, label)`` per distinct joint of ``points`` ``(n, 3)``: legs sharing a joint share one label
    (``B1,2`` for the 6-3 base joint of legs 1 and 2)."""
    out: list[tuple[np.ndarray, list[int]]] = []
    for i, p in enumerate(points):
        for q, legs in out:
            if np.allclose(p, q, atol=1e-9):
                legs.append(i + 1)
                break
        else:
            out.append((p, [i + 1]))
    return [(p, prefix + ",".join(map(str, legs))) for p, legs in out]


def platform_figure(platform: Platform, pose=None):
    """The platform at ``pose`` (``(6,)``, SI, default home) in a top view (X–Y) and a side view (X–Z):
    base joints ``B i`` and plate joints ``T i`` numbered by the legs they carry, each leg in its own colour,
    the base frame's X and Y axes and the plate's rotation centre. Lengths in mm.

    Returns:
        A matplotlib ``Figure``.
    """
    import matplotlib.pyplot as plt  # deferred: importing pyplot picks a backend (commands select Agg first)

    q = platform.home_pose() if pose is None else np.asarray(pose, dtype=float)
    base = platform.base_anchors * 1e3
    top = plate_anchors(platform, q) * 1e3  # (6, 3) the plate joint of each leg, in the base frame
    centre = q[:3] * 1e3
    size = max(np.abs(base[:, :2]).max(), np.abs(top[:, :2]).max())
    fig, (ax_top, ax_side) = plt.subplots(1, 2, figsize=(10, 4.8), gridspec_kw={"width_ratios": [1, 1.1]})
    for ax, (u, v), title in ((ax_top, (0, 1), "top view (X–Y)"), (ax_side, (0, 2), "side view (X–Z)")):
        for i in range(6):
            ax.plot([base[i, u], top[i, u]], [base[i, v], top[i, v]], color=LEG_COLOURS[i], lw=2, label=f"leg {i + 1}")
        ax.plot(*base[:, [u, v]].T, "s", color="#444", ms=6)
        ax.plot(*top[:, [u, v]].T, "o", color="#444", ms=6, mfc="white")
        ax.plot(centre[u], centre[v], "+", color="k", ms=10)
        ax.set_title(title, fontsize=10)
        ax.set_xlabel(f"{'XYZ'[u]} [mm]")
        ax.set_ylabel(f"{'XYZ'[v]} [mm]")
        ax.set_aspect("equal")
        ax.grid(alpha=0.3)
    for points, prefix, outward in ((base, "B", 0.12), (top, "T", -0.12)):  # base labels outside, plate inside
        for p, label in _joint_labels(points, prefix):
            r = np.hypot(*p[:2])
            at = p[:2] + (outward * size * p[:2] / r if r > 0 else 0.0)
            ax_top.text(*at, label, fontsize=8, ha="center", va="center", color="#222" if prefix == "T" else "#555")
    arrow = 0.35 * size
    for k, (colour, name) in enumerate((("#c00", "X"), ("#080", "Y"))):
        d = np.eye(2)[k] * arrow
        ax_top.annotate("", xy=d, xytext=(0, 0), arrowprops={"arrowstyle": "->", "color": colour, "lw": 1.5})
        ax_top.text(*(d * 1.1), name, color=colour, fontsize=10, ha="center", va="center")
    ax_top.margins(0.12)
    ax_side.axhline(0, color="#444", lw=1)
    ax_side.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
    fig.suptitle(
        f"{platform.name}: joints numbered by leg, base B (squares), plate T (circles) at pz = {q[2] * 1e3:.0f} mm",
        fontsize=10,
    )
    fig.tight_layout()
    return fig


def convention_figure(platform: Platform, angle: float = np.radians(15.0)):
    """The sense of each pose angle: the plate of ``platform`` at home and turned by +``angle`` (rad) about
    the base X, Y and Z axes in turn, each seen along the axis it turns about (a positive angle turns
    counter-clockwise seen from the axis' tip: the right-hand rule), in the poses' convention
    ``[px, py, pz, a_x, a_y, a_z]``.

    Returns:
        A matplotlib ``Figure``.
    """
    import matplotlib.pyplot as plt  # deferred: importing pyplot picks a backend (commands select Agg first)

    home = platform.home_pose()
    fig, axes = plt.subplots(1, 3, figsize=(11, 3.8))
    # each panel: the axis turned about, and the two base axes of the plane seen from that axis' tip
    panels = ((3, "a_x about X", (1, 2)), (4, "a_y about Y", (2, 0)), (5, "a_z about Z", (0, 1)))
    for ax, (k, name, (u, v)) in zip(axes, panels):
        turned = home.copy()
        turned[k] += angle
        for q, style, label in ((home, "--", "home"), (turned, "-", f"{name} = +{np.degrees(angle):.0f}°")):
            p = plate_anchors(platform, q) * 1e3
            ring = np.r_[p, p[:1]]
            ax.plot(ring[:, u], ring[:, v], style, color="#1f77b4" if style == "-" else "#999", lw=1.6, label=label)
            ax.plot(p[0, u], p[0, v], "o", color="#d62728" if style == "-" else "#999", ms=5)
        ax.set_xlabel(f"{'XYZ'[u]} [mm]")
        ax.set_ylabel(f"{'XYZ'[v]} [mm]")
        ax.set_title(f"+{name}: seen from the {'XYZ'[k - 3]} tip", fontsize=10)
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="lower right")
    fig.suptitle(
        f"{platform.name}: pose angles, R = Ry(a_y)·Rx(a_x)·Rz(a_z) (convention utn); the red dot is leg 1's "
        "plate joint",
        fontsize=10,
    )
    fig.tight_layout()
    return fig
