"""Figures of the design maps (matplotlib; imported only when drawing)."""

from __future__ import annotations

import numpy as np

from stewart_drake.design.maps import AXIS_NAMES, SliceMaps


def plot_slice_maps(m: SliceMaps, length_unit: str = "mm", max_condition: float = 20.0):
    """One figure: condition number with the safe region and the other assembly mode, minimum
    translational stiffness with the softest direction, and the lowest frequency (when present)."""
    import matplotlib.pyplot as plt  # deferred: importing pyplot picks a backend (commands select Agg first)

    scale = [1e3 if length_unit == "mm" else 1.0 if a < 3 else 180 / np.pi for a in m.axes]
    units = [length_unit if a < 3 else "°" for a in m.axes]
    U, V = np.meshgrid(m.u * scale[0], m.v * scale[1], indexing="ij")
    panels = 1 + (m.k_min is not None) + (m.f1 is not None)
    fig, axes = plt.subplots(1, panels, figsize=(5.5 * panels, 4.5), squeeze=False)
    axes = axes[0]
    c = axes[0].pcolormesh(U, V, np.log10(np.minimum(m.condition, 1e4)), shading="auto", cmap="viridis_r")
    if m.safe.any() and not m.safe.all():
        axes[0].contour(U, V, m.safe.astype(float), levels=[0.5], colors="w", linewidths=2)
    other = (~m.same_mode & m.within).astype(float)
    if other.any():
        axes[0].contourf(U, V, other, levels=[0.5, 1.5], colors="none", hatches=["//"])
    axes[0].set_title(f"log10 condition; white: safe edge (κ ≤ {max_condition:g}); hatched: other assembly", fontsize=8)
    fig.colorbar(c, ax=axes[0])
    k = 1
    if m.k_min is not None:
        c = axes[k].pcolormesh(U, V, m.k_min / 1e3, shading="auto", cmap="magma")
        s = slice(None, None, max(1, len(m.u) // 15))
        d = m.softest[..., list(m.axes)] if max(m.axes) < 3 else m.softest[..., :2]
        axes[k].quiver(
            U[s, s], V[s, s], d[s, s, 0], d[s, s, 1], color="c", pivot="mid", headwidth=1, headlength=0, scale=25
        )
        axes[k].set_title("min translational stiffness (kN/m), softest direction", fontsize=8)
        fig.colorbar(c, ax=axes[k])
        k += 1
    if m.f1 is not None:
        c = axes[k].pcolormesh(U, V, m.f1, shading="auto", cmap="cividis")
        axes[k].set_title("lowest natural frequency (Hz)", fontsize=8)
        fig.colorbar(c, ax=axes[k])
    for ax in axes:
        ax.set_xlabel(f"{AXIS_NAMES[m.axes[0]]} ({units[0]})")
        ax.set_ylabel(f"{AXIS_NAMES[m.axes[1]]} ({units[1]})")
    return fig
