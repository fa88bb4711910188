"""``report.figures``: a report figure is drawn once and cut to its ink plus savefig's tight margin, and is
saved as before (``savefig(bbox_inches="tight")``) wherever cutting could lose something."""

from __future__ import annotations

import io

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from PIL import Image  # noqa: E402

from stewart_drake.report import figures  # noqa: E402

PAD = round(figures.PAD_INCHES * figures.DPI)  # 11 px


def _pixels(data: bytes) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(data)).convert("RGBA"))


def _ink_margins(img: np.ndarray) -> tuple[int, int, int, int]:
    """Background rows/columns above, below, left and right of the ink."""
    ink = (img != img[0, 0]).any(axis=2)
    rows, cols = np.flatnonzero(ink.any(axis=1)), np.flatnonzero(ink.any(axis=0))
    return rows[0], img.shape[0] - 1 - rows[-1], cols[0], img.shape[1] - 1 - cols[-1]


def _draws(fig) -> list:
    seen = []
    fig.canvas.mpl_connect("draw_event", lambda event: seen.append(event))
    return seen


def _plot(**kw):
    fig, ax = plt.subplots(figsize=(5, 3), **kw)
    t = np.linspace(0, 1, 200)
    ax.plot(t, np.sin(6 * t), label="a line")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("position [m]")
    ax.set_title("a title")
    ax.legend()
    return fig


def test_cropped_png_keeps_the_ink_and_pads_it():
    rgba = np.full((40, 50, 4), 255, np.uint8)
    rgba[10:20, 5:45, :3] = (200, 30, 40)  # the ink: rows 10..19, columns 5..44
    img = _pixels(figures.cropped_png(rgba, 3))
    assert img.shape == (10 + 6, 40 + 6, 4)
    assert (img[3:13, 3:43] == rgba[10:20, 5:45]).all()
    assert _ink_margins(img) == (3, 3, 3, 3)
    rgba[0, 25, :3] = 0  # ink on the border: something may lie beyond the canvas
    assert figures.cropped_png(rgba, 3) is None
    assert figures.cropped_png(np.full((8, 8, 4), 255, np.uint8), 3) is None  # nothing drawn


def test_a_figure_is_drawn_once_and_framed_like_savefig_tight():
    fig = _plot()
    draws = _draws(fig)
    img = _pixels(figures.png_bytes(fig))
    assert len(draws) == 1  # savefig(bbox_inches="tight") under a layout engine draws twice
    assert _ink_margins(img) == (PAD, PAD, PAD, PAD)  # savefig's 0.1 inch around the content
    # the same picture as before: savefig's tight box is the artists' extents, which may exceed their ink by a
    # pixel or two of antialiasing and text padding
    old = _plot()
    old.set_layout_engine("constrained")
    buf = io.BytesIO()
    old.savefig(buf, **figures.SAVEFIG)
    before = _pixels(buf.getvalue())
    assert np.abs(np.subtract(img.shape[:2], before.shape[:2])).max() <= 4
    plt.close("all")


def test_what_cutting_could_lose_is_saved_as_before():
    # a figure legend anchored below the figure: no layout places it, the tight box reaches it
    fig = _plot()
    fig.legend(["outside"], loc="upper center", bbox_to_anchor=(0.5, -0.02))
    ours = _pixels(figures.png_bytes(fig))
    assert ours.shape[0] > fig.get_figheight() * figures.DPI  # the canvas grew to hold the legend
    # colorbars made before the layout engine is set: the constrained layout cannot solve it
    fig, ax = plt.subplots(figsize=(4, 3))
    fig.colorbar(ax.pcolormesh(np.arange(12.0).reshape(3, 4)), ax=ax, label="value")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    draws = _draws(fig)
    assert figures.png_bytes(fig)[:8] == b"\x89PNG\r\n\x1a\n"
    assert fig.get_layout_engine().__class__.__name__ == "PlaceHolderLayoutEngine"  # set to "none"
    assert len(draws) >= 2  # the failed draw, then savefig's
    plt.close("all")
