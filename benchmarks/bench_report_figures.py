"""A report figure's cost: ``report.figures.png_bytes`` (one draw, cut to the ink) beside the way the report
saved figures before (the constrained layout and ``savefig(bbox_inches="tight")``: two draws and a tight-box
pass), on figures shaped like the report's (line panels, a histogram, a colour map with its colour bar, 3-D
axes; and one that ``png_bytes`` saves as before, its fallback's cost), in the same process, interleaved, each
the least CPU time of ``--repeat`` renderings:

    PYTHONPATH=. python benchmarks/bench_report_figures.py [--repeat 3]
"""

from __future__ import annotations

import argparse
import io
import time
import warnings

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from stewart_drake.report import figures  # noqa: E402


def _lines():
    fig, axes = plt.subplots(2, 2, figsize=(11, 6), sharex=True)
    t = np.linspace(0, 4, 4000)
    for k, ax in enumerate(axes.flat):
        ax.plot(t, np.sin((k + 1) * t), label="float")
        ax.plot(t, np.sin((k + 1) * t) + 1e-3 * np.sign(np.sin(40 * t)), label="fixed point")
        ax.set_ylabel(f"leg {k + 1} error [mm]")
        ax.legend(fontsize=7)
    for ax in axes[1]:
        ax.set_xlabel("time [s]")
    return fig


def _histogram():
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.6))
    x = np.random.default_rng(0).normal(size=20000)
    axes[0].hist(x, bins=60)
    axes[0].set_xlabel("round-trip error [nm]")
    axes[0].set_ylabel("poses")
    axes[1].semilogy(np.arange(8, 33), 2.0 ** -np.arange(8, 33), "o-")
    axes[1].set_xlabel("word length [bits]")
    axes[1].set_ylabel("worst error [m]")
    return fig


def _map():
    fig, ax = plt.subplots(figsize=(5.5, 4.2), layout="constrained")
    u = np.linspace(-0.45, 0.45, 81)
    X, Y = np.meshgrid(u, u, indexing="ij")
    c = ax.pcolormesh(X * 1e3, Y * 1e3, np.hypot(X, Y), shading="auto")
    fig.colorbar(c, ax=ax, label="log10 condition number")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    return fig


def _three_d(labelpad: float = -4, size: int = 7):
    fig = plt.figure(figsize=(12, 6))
    for k in range(8):
        ax = fig.add_subplot(2, 4, k + 1, projection="3d")
        a = np.linspace(0, 2 * np.pi, 7)
        ax.plot(0.3 * np.cos(a), 0.3 * np.sin(a), 0 * a, color="0.4")
        ax.plot(0.1 * np.cos(a + k), 0.1 * np.sin(a + k), 0.6 + 0 * a, color="tab:blue")
        ax.set_box_aspect((1, 1, 1.2))
        ax.tick_params(labelsize=6)
        for axis in "xyz":
            getattr(ax, f"set_{axis}label")(f"{axis} [m]", fontsize=size, labelpad=labelpad)
        ax.set_title(f"mode {k + 1}", fontsize=9)
    return fig


def _three_d_past_the_edge():
    """3-D axes whose labels the constrained layout leaves past the canvas' edge: ``png_bytes`` sees ink at
    the edge and saves the figure as before (after its own draw: the cost of the fallback)."""
    return _three_d(labelpad=4, size=10)


FIGURES = {
    "4 line panels": _lines,
    "histogram + semilog": _histogram,
    "colour map": _map,
    "8 3-D axes": _three_d,
    "fallback: past the edge": _three_d_past_the_edge,
}


def before(fig) -> bytes:
    """The report's saving before ``report.figures`` (``Section.figure`` then): the constrained layout (a
    figure it cannot lay out saved as drawn), savefig's tight box."""
    buf = io.BytesIO()
    if fig.get_layout_engine() is None:
        fig.set_layout_engine("constrained")
        try:
            with warnings.catch_warnings():
                warnings.filterwarnings("error", message=".*constrained_layout not applied")
                fig.savefig(buf, **figures.SAVEFIG)
        except (ZeroDivisionError, ValueError, UserWarning):
            fig.set_layout_engine("none")
            buf = io.BytesIO()
    if not buf.getvalue():
        fig.savefig(buf, **figures.SAVEFIG)
    return buf.getvalue()


def cpu(make, save, repeat: int) -> float:
    best = float("inf")
    for _ in range(repeat):
        fig = make()
        c0 = time.process_time()
        save(fig)
        best = min(best, time.process_time() - c0)
        plt.close(fig)
    return best


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    before(_lines())  # the process's first figure loads the fonts: not either method's cost
    print(f"{'figure':22} {'savefig tight s':>15} {'png_bytes s':>12} {'ratio':>6}")
    total = [0.0, 0.0]
    for name, make in FIGURES.items():
        old, new = cpu(make, before, args.repeat), cpu(make, figures.png_bytes, args.repeat)
        total[0] += old
        total[1] += new
        print(f"{name:22} {old:15.3f} {new:12.3f} {new / old:6.2f}")
    print(f"{'all':22} {total[0]:15.3f} {total[1]:12.3f} {total[1] / total[0]:6.2f}")


if __name__ == "__main__":
    main()
