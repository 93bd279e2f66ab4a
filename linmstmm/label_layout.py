"""Labels placed where nothing else is drawn.

A label is tried at a few places around its anchor, in order of preference,
and takes the first whose box contains no sample of the figure's lines and
overlaps no box already taken (other labels, node outlines). Used by the
topology figure (:mod:`linmstmm.plot_topology`) and the report figures of
``scripts/speed_accuracy.py``. Works on any matplotlib axes (linear or
logarithmic scales): the geometry is compared in display pixels.
"""
from __future__ import annotations

import numpy as np

#: Places around an anchor: (offset in points, horizontal and vertical alignment),
#: above first, then beside, then below.
AROUND = (((0, 5), "center", "bottom"), ((-4, 4), "right", "bottom"), ((4, 4), "left", "bottom"),
          ((4, -4), "left", "top"), ((-4, -4), "right", "top"), ((0, -5), "center", "top"))


def line_samples(axes, polylines, step: float = 2.0) -> np.ndarray:
    """Points along polylines, in display pixels, at most ``step`` pixels apart.

    Parameters
    ----------
    axes : matplotlib Axes
        The axes whose data coordinates the polylines are in.
    polylines : iterable of array_like, each (k, 2)
        Data coordinates (any scales of ``axes``); non-finite points are dropped.
    step : float
        Largest gap between samples, pixels.

    Returns
    -------
    numpy.ndarray, (m, 2)
        The samples, pixels.
    """
    samples = [np.empty((0, 2))]
    for line in polylines:
        line = np.asarray(line, dtype=float).reshape(-1, 2)
        pixels = axes.transData.transform(line[np.isfinite(line).all(axis=1)])
        samples.append(pixels)
        for a, b in zip(pixels[:-1], pixels[1:]):
            count = int(np.ceil(np.linalg.norm(b - a) / step))
            samples.append(a + np.linspace(0.0, 1.0, count + 1)[1:-1, None] * (b - a))
    return np.vstack(samples)


def place_label(axes, text: str, xy, samples, taken: list, places=AROUND, pad: float = 2.0, **options):
    """Annotate ``text`` at the first of ``places`` around ``xy`` that is clear.

    Parameters
    ----------
    axes : matplotlib Axes
        Where to write; its figure must have a canvas.
    text : str
        The label.
    xy : (float, float)
        Anchor, data coordinates.
    samples : (m, 2) array
        Pixels the label must not cover (:func:`line_samples`).
    taken : list of matplotlib.transforms.Bbox
        Boxes the label must not overlap, pixels; the label's own box is
        appended.
    places : sequence of ((float, float), str, str)
        Offset from ``xy`` in points, horizontal and vertical alignment, in
        order of preference. Where none is clear, the first is used.
    pad : float
        Clearance around the label, pixels.
    **options
        Further options of ``axes.annotate`` (fontsize, color, ...).

    Returns
    -------
    matplotlib.text.Annotation
        The label.
    """
    renderer = axes.figure.canvas.get_renderer()

    def write(offset, ha, va):
        return axes.annotate(text, xy, xytext=offset, textcoords="offset points", ha=ha, va=va, **options)
    for place in places:
        label = write(*place)
        box = label.get_window_extent(renderer)
        if not box.padded(pad).count_contains(samples) and not box.count_overlaps(taken):
            taken.append(box)
            return label
        label.remove()
    label = write(*places[0])
    taken.append(label.get_window_extent(renderer))
    return label
