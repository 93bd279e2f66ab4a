"""Figures of modes, determinant scans, responses, FRFs, frequencies, sweeps and MAC matrices.

Every function draws on matplotlib's Agg canvas: the ``plot_*`` and
``animate_mode`` functions straight into a file (PNG, or GIF for
:func:`animate_mode`), the ``*_figure`` functions into a Figure they return
unsaved (what the results' ``plot()`` methods give). No window is opened and
pyplot's global state is not touched.

The mode figures (:func:`plot_mode`, :func:`animate_mode`: three
orthographic views and an isometric one) are drawn by
:mod:`linmstmm.mode_figure` and re-exported here.
"""
from __future__ import annotations

import matplotlib
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import MaxNLocator

from linmstmm.mode_figure import AMPLITUDE, animate_mode, mode_shape_figure, plot_mode
from linmstmm.model import COMPONENTS
from linmstmm.response import QUANTITY_UNITS

__all__ = ["AMPLITUDE", "animate_mode", "damped_figure", "frequency_figure", "frf_figure", "mode_shape_figure",
           "plot_frf", "plot_mac", "plot_mode", "plot_response", "plot_scan", "response_figure",
           "scan_figure", "significant_components", "sweep_figure"]

#: FRF components below this fraction of the largest of their kind are not drawn.
SIGNIFICANT = 1e-6
#: An FRF axis with more lines than this has a legend by point (colour) and direction (dashes).
LEGEND_LINES = 12
#: MAC values are written into the cells of matrices up to this size.
ANNOTATED_MAC = 16

_DPI = 130
_AXIS_COLORS = ("tab:red", "tab:green", "tab:blue")
_SIGN_COLORS = {1.0: "tab:red", -1.0: "tab:blue"}


def _canvas(figsize, rows=1, columns=1, **options):
    """An Agg figure with a grid of axes (``subplots`` options), nothing global."""
    figure = Figure(figsize=figsize, layout="constrained")
    FigureCanvasAgg(figure)
    return figure, figure.subplots(rows, columns, squeeze=False, **options)


# --- determinant scan ---------------------------------------------------------------

def plot_scan(omegas, sign, log_abs, roots, count, path, title: str = "") -> None:
    """Write the det/count scan figure (:func:`scan_figure`, same arguments but the path) as a PNG."""
    scan_figure(omegas, sign, log_abs, roots, count, title).savefig(path, format="png", dpi=_DPI)


def scan_figure(omegas, sign, log_abs, roots, count, title: str = "") -> Figure:
    """The det/count scan figure, not yet saved.

    omegas : (n,) scanned circular frequencies, rad/s. sign, log_abs : (n,)
    sign and natural log of |det Ū_all| there. roots : natural frequencies
    found, rad/s. count : (n,) number of natural frequencies at or below each
    scanned frequency, N(ω). The frequency axis is in Hz.
    """
    hz = np.asarray(omegas, dtype=float) / (2 * np.pi)
    roots_hz = np.asarray(roots, dtype=float) / (2 * np.pi)
    sign, log10 = np.asarray(sign).real, np.asarray(log_abs, dtype=float) / np.log(10)
    figure, axes = _canvas((8.0, 6.0), 2, 1, sharex=True, height_ratios=(2, 1))
    top, bottom = axes[:, 0]
    points = np.column_stack([hz, log10])
    top.add_collection(LineCollection(np.stack([points[:-1], points[1:]], axis=1),
                                      colors=[_SIGN_COLORS[s] for s in np.where(sign[:-1] < 0, -1.0, 1.0)]))
    top.autoscale_view()
    for root in roots_hz:
        for axis in (top, bottom):
            axis.axvline(root, color="0.4", ls=":", lw=0.8)
    top.set_ylabel("log₁₀ |det Ū_all|")
    top.legend(handles=[Line2D([], [], color=_SIGN_COLORS[1.0], label="det > 0"),
                        Line2D([], [], color=_SIGN_COLORS[-1.0], label="det < 0"),
                        Line2D([], [], color="0.4", ls=":", label="natural frequency")],
               fontsize=8, loc="best")
    top.set_title(title or "determinant scan")
    bottom.step(hz, count, where="post", color="k")
    bottom.plot(roots_hz, np.arange(1, roots_hz.size + 1), "o", color="tab:orange", markersize=4)
    bottom.yaxis.set_major_locator(MaxNLocator(integer=True))
    bottom.set_ylabel("N(f): roots ≤ f")
    bottom.set_xlabel("frequency [Hz]")
    bottom.set_xlim(hz[0], hz[-1])
    return figure


# --- response and FRF ---------------------------------------------------------------

def plot_response(result, path, quantity: str = "displacement", title: str = "") -> None:
    """Write the response histories of a :class:`linmstmm.response.ResponseResult`
    (:func:`response_figure`, same arguments but the path) as a PNG."""
    response_figure(result, quantity, title).savefig(path, format="png", dpi=_DPI)


def response_figure(result, quantity: str = "displacement", title: str = "") -> Figure:
    """The response histories of a :class:`linmstmm.response.ResponseResult`, not yet saved.

    One row per response point: translations x, y, z on the left, rotations
    on the right. quantity : "displacement", "velocity" or "acceleration".
    """
    if quantity not in QUANTITY_UNITS:
        raise ValueError(f"quantity must be one of {tuple(QUANTITY_UNITS)}, got {quantity!r}")
    values = getattr(result, quantity)
    rows = len(result.points)
    figure, axes = _canvas((9.0, 1.2 + 1.9 * rows), rows, 2, sharex=True)
    for row, point in enumerate(result.points):
        for column, (unit, first) in enumerate(zip(QUANTITY_UNITS[quantity], (0, 3))):
            axis = axes[row, column]
            for c in range(3):
                axis.plot(result.times, values[:, row, first + c], color=_AXIS_COLORS[c],
                          lw=1.0, label=COMPONENTS[first + c])
            axis.set_ylabel(f"{point}\n[{unit}]")
            axis.grid(alpha=0.3)
            axis.legend(fontsize=7, loc="upper right", ncols=3)
    for axis in axes[-1]:
        axis.set_xlabel("time [s]")
    axes[0, 0].set_title(f"{quantity}: translations")
    axes[0, 1].set_title(f"{quantity}: rotations")
    figure.suptitle(title or f"modal response, {quantity}")
    return figure


def plot_frf(result, path, natural_hz=(), load_unit: str = "N", title: str = "") -> None:
    """Write magnitude and phase of a :class:`linmstmm.response.FRFResult`.

    Every (point, component) whose largest |H| is at least SIGNIFICANT × the
    largest of its kind (translation or rotation) is drawn: translations
    (m per load unit) and rotations (rad per load unit) on separate magnitude
    axes, the phases of all on one axis below. Each line has its own colour
    and line style and is labelled by point and direction. natural_hz :
    natural frequencies to mark, Hz. load_unit : unit of the load, "N" or "N m".
    """
    frf_figure(result, natural_hz, load_unit, title).savefig(path, format="png", dpi=_DPI)


def frf_figure(result, natural_hz=(), load_unit: str = "N", title: str = "") -> Figure:
    """The figure :func:`plot_frf` writes (same arguments but the path), not yet saved.

    Its axes are the magnitude axes, translations first (those present), then
    the phase axis.
    """
    lines = significant_components(result.receptance)
    kinds = [(name, unit, [(p, c) for p, c in lines if (c < 3) == (name == "translation")])
             for name, unit in (("translation", "m"), ("rotation", "rad"))]
    kinds = [kind for kind in kinds if kind[2]]
    figure, axes = _canvas((9.0, 2.6 + 2.6 * len(kinds)), len(kinds) + 1, 1, sharex=True,
                           height_ratios=(2,) * len(kinds) + (1.2,))
    phase = axes[-1, 0]
    styles = _line_styles(lines)
    for axis, (name, unit, chosen) in zip(axes[:, 0], kinds):
        for p, c in chosen:
            label = f"{result.points[p]} {COMPONENTS[c]}"
            axis.semilogy(result.excitation_hz, np.abs(result.receptance[:, p, c]), lw=1.2,
                          label=label, **styles[p, c])
            phase.plot(result.excitation_hz, np.degrees(np.angle(result.receptance[:, p, c])),
                       lw=1.0, **styles[p, c])
        axis.set_ylabel(f"|H|, {name}\n[{unit}/{load_unit}]")
        _frf_legend(axis, result.points, chosen, styles)
        axis.grid(alpha=0.3)
    for frequency in natural_hz:
        for axis in axes[:, 0]:
            axis.axvline(frequency, color="0.5", ls=":", lw=0.8)
    axes[0, 0].set_title(title or "frequency response (receptance)")
    phase.set_ylabel("phase [deg]")
    phase.set_yticks([-180, -90, 0, 90, 180])
    phase.set_xlabel("frequency [Hz]")
    phase.grid(alpha=0.3)
    return figure


def _frf_legend(axis, points, chosen, styles) -> None:
    """Legend right of ``axis``: one entry per line, or colours by point and dashes by direction
    when there are more than LEGEND_LINES lines."""
    options = dict(fontsize=7, title_fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    if len(chosen) <= LEGEND_LINES:
        axis.legend(title="point, direction", **options)
        return
    component = dict(chosen)  # point index -> one of its components
    handles = [Line2D([], [], label=points[p], **(styles[p, c] | dict(ls="-"))) for p, c in component.items()]
    handles += [Line2D([], [], color="k", ls=_DIRECTION_DASHES[c % 3], label=f"{COMPONENTS[c]}")
                for c in sorted({c for _, c in chosen})]
    axis.legend(handles=handles, title="colour: point\ndashes: direction",
                ncols=1 + len(handles) // 20, **options)


#: Line colours of the FRF figure (by point) and line styles (by direction, x/rx … z/rz).
_POINT_COLORS = matplotlib.colormaps["tab10"].colors
_DIRECTION_DASHES = ("-", "--", "-.")
_MARKERS = (None, "o", "s", "^", "v", "D")


def _line_styles(lines) -> dict:
    """(point, component) -> plot options: colour by point, dashes by direction.

    Points beyond the ten colours also get a marker, so that no two lines
    share colour, dashes and marker (up to 60 points).
    """
    order = {p: i for i, p in enumerate(dict.fromkeys(p for p, _ in lines))}
    return {(p, c): dict(color=_POINT_COLORS[order[p] % 10], ls=_DIRECTION_DASHES[c % 3],
                         marker=_MARKERS[order[p] // 10 % len(_MARKERS)], markevery=0.1, markersize=4)
            for p, c in lines}


def significant_components(receptance) -> list[tuple[int, int]]:
    """(point, component) pairs of a (n_f, n_points, 6) receptance worth showing.

    A component counts if its largest |H| is non-zero and at least SIGNIFICANT
    × the largest of its kind (translations 0–2, rotations 3–5) over all points.
    """
    peak = np.abs(np.asarray(receptance)).max(axis=0)  # (n_points, 6)
    chosen = np.zeros(peak.shape, dtype=bool)
    for kind in (slice(0, 3), slice(3, 6)):
        chosen[:, kind] = (peak[:, kind] > 0) & (peak[:, kind] >= SIGNIFICANT * peak[:, kind].max(initial=0.0))
    return [(int(p), int(c)) for p, c in zip(*np.nonzero(chosen))]


# --- frequencies, damped frequencies and sweeps -------------------------------------

def frequency_figure(frequencies_hz, rigid_body_modes: int = 0, error_estimate=None, title: str = "") -> Figure:
    """Natural frequencies against their mode number, not yet saved.

    frequencies_hz : (n,) elastic natural frequencies, Hz, ascending (a repeated
    one once per multiplicity). rigid_body_modes : zero-frequency modes, named
    in the legend. error_estimate : (n,) relative error estimates of the
    frequencies (e.g. the FE route's), drawn on a second axis below; None: none.
    """
    frequencies = np.asarray(frequencies_hz, dtype=float)
    panels = 1 if error_estimate is None else 2
    figure, axes = _canvas((7.0, 2.0 + 2.4 * panels), panels, 1, sharex=True)
    number = np.arange(1, frequencies.size + 1)
    top = axes[0, 0]
    top.plot(number, frequencies, "o", color="tab:blue", markersize=4,
             label=f"elastic modes ({rigid_body_modes} rigid-body modes at 0 Hz not shown)")
    top.set_ylabel("natural frequency [Hz]")
    top.legend(fontsize=8, loc="upper left")
    top.grid(alpha=0.3)
    top.set_title(title or "natural frequencies")
    if error_estimate is not None:
        bottom = axes[1, 0]
        bottom.semilogy(number, np.asarray(error_estimate, dtype=float), "s", color="tab:orange", markersize=4)
        bottom.set_ylabel("estimated relative error")
        bottom.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("elastic mode number")
    axes[-1, 0].xaxis.set_major_locator(MaxNLocator(integer=True))
    return figure


def damped_figure(damped_hz, damping_ratio, undamped_hz=(), title: str = "") -> Figure:
    """Damping ratio against damped natural frequency, not yet saved.

    damped_hz : (n,) damped natural frequencies ω_d / 2π, Hz. damping_ratio :
    (n,) ζ. undamped_hz : the undamped natural frequencies, Hz, marked by
    dotted lines.
    """
    figure, axes = _canvas((7.0, 4.4))
    axis = axes[0, 0]
    for frequency in undamped_hz:
        axis.axvline(frequency, color="0.5", ls=":", lw=0.8)
    axis.plot(damped_hz, damping_ratio, "o", color="tab:red", markersize=5, label="damped mode")
    axis.legend(handles=[*axis.get_legend_handles_labels()[0],
                         Line2D([], [], color="0.5", ls=":", label="undamped natural frequency")],
                fontsize=8, loc="best")
    axis.set_xlabel("damped natural frequency ω_d / 2π [Hz]")
    axis.set_ylabel("damping ratio ζ [-]")
    axis.set_ylim(bottom=0.0)
    axis.grid(alpha=0.3)
    axis.set_title(title or "damped natural frequencies")
    return figure


def sweep_figure(result, log_x: bool = False) -> Figure:
    """The tracked frequencies (Hz) of a :class:`linmstmm.sweep.SweepResult` against its first key, not yet saved.

    One colour per tracked column; with a grid of several keys, one line per
    combination of the other keys' values. log_x : logarithmic value axis.
    """
    figure, axes = _canvas((7.5, 4.8))
    axis = axes[0, 0]
    lines = result.values.shape[0] // result.shape[0]
    x = result.values[:, 0].reshape(result.shape[0], lines)
    frequencies = result.frequencies_hz.reshape(result.shape[0], lines, -1)
    for column in range(frequencies.shape[2]):
        colour = f"C{column % 10}"
        for line in range(lines):
            axis.plot(x[:, line], frequencies[:, line, column], "-o", color=colour, markersize=2.5,
                      lw=1.2, label=f"mode {column + 1}" if line == 0 else None)
    if log_x:
        axis.set_xscale("log")
    axis.set_xlabel(result.keys[0])
    axis.set_ylabel("natural frequency [Hz]")
    others = f"; one line per value of {', '.join(result.keys[1:])}" if len(result.shape) > 1 else ""
    axis.set_title(f"{result.model}: modes followed by shape (MAC){others}", fontsize=9)
    axis.legend(fontsize=8)
    axis.grid(alpha=0.3)
    return figure


# --- MAC ----------------------------------------------------------------------------

def plot_mac(matrix, path, row_hz=None, column_hz=None, labels=("MSTMM", "FE"), title: str = "") -> None:
    """Write a MAC matrix (n_a, n_b) as a grey-scale image with its values.

    row_hz, column_hz : frequencies of the two mode sets (tick labels).
    labels : names of the two mode sets (rows, columns).
    """
    matrix = np.atleast_2d(matrix)
    n_rows, n_columns = matrix.shape
    figure, axes = _canvas((1.6 + 0.55 * n_columns + 2.0, 1.6 + 0.5 * n_rows + 1.0))
    axis = axes[0, 0]
    image = axis.imshow(matrix, vmin=0.0, vmax=1.0, cmap="Greys")
    figure.colorbar(image, ax=axis, shrink=0.8, label="MAC")
    if max(matrix.shape) <= ANNOTATED_MAC:
        for (i, j), value in np.ndenumerate(matrix):
            axis.text(j, i, f"{value:.2f}", ha="center", va="center", fontsize=7,
                      color="white" if value > 0.5 else "black")
    axis.set_xticks(range(n_columns), _tick_labels(n_columns, column_hz), fontsize=7)
    axis.set_yticks(range(n_rows), _tick_labels(n_rows, row_hz), fontsize=7)
    axis.set_xlabel(f"{labels[1]} mode")
    axis.set_ylabel(f"{labels[0]} mode")
    axis.set_title(title or f"MAC, {labels[0]} against {labels[1]}", fontsize=10)
    figure.savefig(path, format="png", dpi=_DPI)


def _tick_labels(n: int, hz) -> list[str]:
    if hz is None:
        return [str(i + 1) for i in range(n)]
    return [f"{i + 1}\n{f:.4g} Hz" for i, f in enumerate(hz)]
