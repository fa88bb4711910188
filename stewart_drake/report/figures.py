"""A report figure as PNG bytes, drawn once.

``savefig(bbox_inches="tight")`` of a figure under the constrained layout draws it twice and measures it in
between: a draw that runs the layout (itself two passes over every axes' extent), the figure's tight box (a
third pass over every tick and label), then the draw that renders. The Python work over the artists in those
passes is what a report figure costs. ``png_bytes`` draws the figure once (the layout runs in that draw), then
cuts the rendered pixels to the ink plus the same 0.1-inch margin of background that ``savefig`` puts around a
tight box: the same picture, drawn once (``benchmarks/bench_report_figures.py`` measures the difference). The box
is the ink's rather than the artists' extents, so an image may be a few pixels smaller (a 3-D axes' invisible
margin is not kept).

A figure with a layout engine of its own (or laid out by ``tight_layout``) is drawn once the same way (the
engine runs in the draw). Where cutting could lose something, the figure is saved as before: one the
constrained layout cannot solve (it is then saved as drawn), and one whose ink reaches the edge of the canvas
(an artist no layout places, such as a figure legend anchored outside, which the tight box would have kept).
"""

from __future__ import annotations

import io
import warnings

import numpy as np

DPI = 110
PAD_INCHES = 0.1  # savefig's margin around a tight box (its pad_inches default)
# zlib level 1 for the figures' PNGs: a few per cent larger files than matplotlib's default level 6, for an
# encoding that costs next to nothing
COMPRESS_LEVEL = 1
SAVEFIG = {"format": "png", "dpi": DPI, "bbox_inches": "tight", "pil_kwargs": {"compress_level": COMPRESS_LEVEL}}


def png_bytes(fig) -> bytes:
    """The PNG of matplotlib figure ``fig`` at ``DPI``, laid out by the constrained layout (unless it has a
    layout engine of its own, or was laid out already), cut to its content plus ``PAD_INCHES``; the figure is
    left open."""
    rgba = None
    if fig.get_layout_engine() is None:  # lay labels, titles and legends out without overlaps or clipping
        fig.set_layout_engine("constrained")
        try:
            with warnings.catch_warnings():
                warnings.filterwarnings("error", message=".*constrained_layout not applied")  # then do without
                rgba = _drawn(fig)
        except (ZeroDivisionError, ValueError, UserWarning):  # a layout it cannot solve: the figure as drawn
            fig.set_layout_engine("none")
    else:  # its own engine runs in the draw (savefig's first draw is for the same), or it was laid out already
        rgba = _drawn(fig)
    data = None if rgba is None else cropped_png(rgba, round(PAD_INCHES * DPI))
    if data is not None:
        return data
    buf = io.BytesIO()
    fig.savefig(buf, **SAVEFIG)
    return buf.getvalue()


def _drawn(fig) -> np.ndarray:
    """``(h, w, 4)`` uint8: ``fig`` rendered by Agg at ``DPI`` (its layout engine runs in the draw)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = fig.canvas if isinstance(fig.canvas, FigureCanvasAgg) else FigureCanvasAgg(fig)
    fig.set_dpi(DPI)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba())


def cropped_png(rgba: np.ndarray, pad: int) -> bytes | None:
    """PNG of the ``(h, w, 4)`` image cut to the pixels that differ from its border's colour, with ``pad``
    pixels of that colour around them; None when the border is not one colour (ink reaches the edge: something
    may lie beyond the canvas) or there is no ink."""
    from PIL import Image
    from PIL.PngImagePlugin import PngInfo

    border = np.concatenate([rgba[0], rgba[-1], rgba[:, 0], rgba[:, -1]])
    bg = border[0]
    if not (border == bg).all():
        return None
    ink = (rgba != bg).any(axis=2)
    rows, cols = np.flatnonzero(ink.any(axis=1)), np.flatnonzero(ink.any(axis=0))
    if not len(rows):
        return None
    core = rgba[rows[0] : rows[-1] + 1, cols[0] : cols[-1] + 1]
    out = np.empty((core.shape[0] + 2 * pad, core.shape[1] + 2 * pad, 4), np.uint8)
    out[...] = bg
    out[pad : pad + core.shape[0], pad : pad + core.shape[1]] = core
    import matplotlib

    info = PngInfo()
    info.add_text("Software", f"Matplotlib version{matplotlib.__version__}, https://matplotlib.org/")
    buf = io.BytesIO()
    Image.fromarray(out).save(buf, format="png", compress_level=COMPRESS_LEVEL, dpi=(DPI, DPI), pnginfo=info)
    return buf.getvalue()
