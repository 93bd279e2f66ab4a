"""Figures of modes, determinant scans, responses, FRFs and MAC matrices.

Every function draws on matplotlib's Agg canvas straight into a file (PNG,
or GIF for :func:`animate_mode`); no window is opened and pyplot's global
state is not touched.

Mode figures (:func:`plot_mode`, :func:`animate_mode`) show the undeformed
structure in grey and the deformed one coloured by the size of the local
translation: beams as their deflected curves (the stations of
:class:`linmstmm.modes.BeamField`), rigid bodies as lines from each
port to the mass centre (a square marks the mass centre), springs as small
diamonds between their two ends. The mode is scaled so that its largest
translation is ``AMPLITUDE`` × the size of the model.
"""
from __future__ import annotations

from dataclasses import dataclass

import matplotlib
import numpy as np
from matplotlib.animation import PillowWriter
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.cm import ScalarMappable
from matplotlib.collections import LineCollection
from matplotlib.colors import Normalize
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import MaxNLocator
from mpl_toolkits.mplot3d.art3d import Line3DCollection

from linmstmm.model import COMPONENTS, Model
from linmstmm.modes import ModalResult
from linmstmm.response import QUANTITY_UNITS

#: Largest drawn modal translation, as a fraction of the model's size.
AMPLITUDE = 0.1
#: A mode whose largest translation is below this fraction of (model size ×
#: largest rotation) is drawn undeformed and called "rotation only".
NO_TRANSLATION = 1e-9
#: FRF components below this fraction of the largest of their kind are not drawn.
SIGNIFICANT = 1e-6
#: Frames per period of an animated mode, and frames per second.
FRAMES, FPS = 24, 12
#: Half the shortest side of the box of a mode figure, as a fraction of the model size.
_THINNEST = 0.25
#: MAC values are written into the cells of matrices up to this size.
ANNOTATED_MAC = 16

_COLORMAP = "plasma"
_UNDEFORMED = "0.72"
_WIDTHS = {"beam": 3.0, "rigid": 2.5, "spring": 0.8}
_DPI = 130
_AXIS_COLORS = ("tab:red", "tab:green", "tab:blue")
_SIGN_COLORS = {1.0: "tab:red", -1.0: "tab:blue"}


def _canvas(figsize, rows=1, columns=1, **options):
    """An Agg figure with a grid of axes (``subplots`` options), nothing global."""
    figure = Figure(figsize=figsize, layout="constrained")
    FigureCanvasAgg(figure)
    return figure, figure.subplots(rows, columns, squeeze=False, **options)


# --- mode shapes ------------------------------------------------------------------

@dataclass(frozen=True, eq=False)
class _Scene:
    """One mode ready to draw: every piece of the structure as straight segments and markers.

    segments : (N, 2, 3) undeformed segments, m (beam stations, rigid port to
    mass centre, spring ends); segment_motion : (N, 2, 3) the mode's
    translation at their ends; widths : (N,) line widths. markers : (M, 3)
    mass centres and spring middles; marker_motion : (M, 3); marker_shapes :
    (M,) "s" (mass centre) or "D" (spring). scale : modal to drawn
    translation (0: drawn undeformed). largest : largest modal translation
    (0 for a rotation-only mode). limits : (3, 2) axes limits, m.
    """

    segments: np.ndarray
    segment_motion: np.ndarray
    widths: np.ndarray
    markers: np.ndarray
    marker_motion: np.ndarray
    marker_shapes: np.ndarray
    scale: float
    largest: float
    limits: np.ndarray
    title: str

    def colors(self, motion) -> np.ndarray:
        """(n, 4) colours of |motion| (n, m, 3) averaged over its m places, relative to ``largest``."""
        size = np.linalg.norm(motion, axis=-1).mean(axis=1)
        return matplotlib.colormaps[_COLORMAP](size / self.largest if self.largest else 0 * size)


def plot_mode(result: ModalResult, model: Model, k: int, path) -> None:
    """Write mode ``k`` (0-based index into ``result``) of ``model`` as a 3-D PNG figure.

    Undeformed structure grey, deformed structure coloured by |translation|;
    the title gives the mode number (from 1), the frequency and the modal mass.
    """
    scene = _scene(result, model, k)
    figure, axes = _mode_canvas(scene)
    _Deformed(axes, scene).pose(1.0)
    figure.savefig(path, format="png", dpi=_DPI)


def animate_mode(result: ModalResult, model: Model, k: int, path,
                 frames: int = FRAMES, fps: int = FPS) -> None:
    """Write mode ``k`` of ``model`` as an animated GIF: one period of sin ωt in ``frames`` frames."""
    scene = _scene(result, model, k)
    figure, axes = _mode_canvas(scene)
    deformed = _Deformed(axes, scene)
    writer = PillowWriter(fps=fps)
    with writer.saving(figure, path, dpi=_DPI // 2):
        for phase in np.arange(frames) / frames:
            deformed.pose(np.sin(2 * np.pi * phase))
            writer.grab_frame()


def _scene(result: ModalResult, model: Model, k: int) -> _Scene:
    """Segments, markers, scale, limits and title of mode ``k``."""
    if not 0 <= k < result.omega.size:
        raise IndexError(f"mode index {k} out of range: the result has {result.omega.size} modes")
    segments, widths, markers, shapes = _pieces(result, model, k)
    positions = np.concatenate([segments[:, :, 0].reshape(-1, 3), markers[:, 0],
                                np.array(list(model.points.values()), dtype=float)])
    size = max(float(np.ptp(positions, axis=0).max()), 1e-3)
    largest = float(np.linalg.norm(segments[:, :, 1], axis=-1).max(initial=0.0))
    rotation = np.abs(result.shape_matrix().reshape(result.omega.size, -1, 6)[k, :, 3:]).max()
    moves = largest > NO_TRANSLATION * size * rotation
    reach = AMPLITUDE * size
    low, high = positions.min(axis=0) - reach, positions.max(axis=0) + reach
    middle, half = (low + high) / 2, np.maximum((high - low) / 2, _THINNEST * size)
    return _Scene(segments[:, :, 0], segments[:, :, 1], widths, markers[:, 0], markers[:, 1], shapes,
                  reach / largest if moves else 0.0, largest if moves else 0.0,
                  np.stack([middle - half, middle + half], axis=1), _mode_title(result, model, k, moves))


def _pieces(result: ModalResult, model: Model, k: int):
    """The structure of mode ``k`` as segments and markers, each with (position, motion).

    Returns segments (N, 2 ends, 2, 3), widths (N,), markers (M, 2, 3) and
    marker shapes (M,); the axis of length 2 is (position, modal translation).
    """
    def at(point):
        return model.points[point], result.point_displacements[point][k, :3]

    segments, widths, markers, shapes = [], [], [], []
    for field in result.beam_fields.values():
        ends = np.stack([field.positions, field.displacements[k, :, :3]], axis=1)
        segments += list(np.stack([ends[:-1], ends[1:]], axis=1))
        widths += [_WIDTHS["beam"]] * (len(ends) - 1)
    for rigid in model.rigids:
        centre = (rigid.com, result.com_displacements[rigid.name][k, :3])
        segments += [np.array([at(port), centre], dtype=float) for port in rigid.ports]
        widths += [_WIDTHS["rigid"]] * len(rigid.ports)
        markers.append(centre)
        shapes.append("s")
    for spring in model.springs:
        ends = np.array([at(end) for end in spring.ends], dtype=float)
        segments.append(ends)
        widths.append(_WIDTHS["spring"])
        markers.append(ends.mean(axis=0))
        shapes.append("D")
    return (np.array(segments, dtype=float).reshape(-1, 2, 2, 3), np.array(widths),
            np.array(markers, dtype=float).reshape(-1, 2, 3), np.array(shapes))


def _mode_title(result: ModalResult, model: Model, k: int, moves: bool) -> str:
    kind = "rigid-body mode" if result.omega[k] == 0 else f"f = {result.frequencies_hz[k]:.6g} Hz"
    mass = f"modal mass {result.modal_mass[k]:.4g} kg ({result.normalization} normalisation)"
    note = "" if moves else "; rotation only, drawn undeformed"
    return f"{model.name}\nmode {k + 1}: {kind}, {mass}{note}"


def _mode_canvas(scene: _Scene):
    """An Agg figure with 3-D axes, the undeformed structure, a colour bar and a legend."""
    figure = Figure(figsize=(8.0, 6.5))
    FigureCanvasAgg(figure)
    axes = figure.add_subplot(projection="3d")
    axes.add_collection3d(Line3DCollection(scene.segments, colors=_UNDEFORMED, linewidths=scene.widths))
    for shape in ("s", "D"):
        chosen = scene.markers[scene.marker_shapes == shape]
        axes.plot(*chosen.T, marker=shape, ls="", markersize=4, color=_UNDEFORMED)
    for (low, high), setter in zip(scene.limits, (axes.set_xlim, axes.set_ylim, axes.set_zlim)):
        setter(low, high)
    axes.set_box_aspect(np.ptp(scene.limits, axis=1))
    for name, axis in zip("xyz", (axes.xaxis, axes.yaxis, axes.zaxis)):
        axis.set_major_locator(MaxNLocator(4))
        axis.set_label_text(f"{name} [m]")
    label = (f"|translation| / largest ({scene.largest:.3g}); largest drawn as {AMPLITUDE:g} × model size"
             if scene.largest else "no translation")
    figure.colorbar(ScalarMappable(Normalize(0.0, 1.0), _COLORMAP), ax=axes, shrink=0.6, pad=0.12,
                    label=label)
    figure.suptitle(scene.title, fontsize=10)
    handles = [Line2D([], [], color=_UNDEFORMED, lw=2, label="undeformed"),
               Line2D([], [], color="tab:purple", lw=_WIDTHS["beam"], label="beam (deformed)"),
               Line2D([], [], color="tab:purple", lw=_WIDTHS["rigid"], marker="s",
                      label="rigid body: ports to mass centre"),
               Line2D([], [], color="tab:purple", marker="D", ls="", markersize=4, label="spring")]
    figure.legend(handles=handles, loc="lower left", fontsize=8, frameon=False)
    return figure, axes


class _Deformed:
    """The deformed structure on ``axes``; :meth:`pose` moves it to ``factor`` × the scaled mode."""

    def __init__(self, axes, scene: _Scene):
        self.axes, self.scene = axes, scene
        self.lines = Line3DCollection(scene.segments, colors=scene.colors(scene.segment_motion),
                                      linewidths=scene.widths)
        axes.add_collection3d(self.lines)
        self.markers = []

    def pose(self, factor: float) -> None:
        """Move the deformed structure to ``factor`` (−1 … 1) × the scaled mode."""
        scene = self.scene
        self.lines.set_segments(scene.segments + factor * scene.scale * scene.segment_motion)
        for markers in self.markers:
            markers.remove()
        moved = scene.markers + factor * scene.scale * scene.marker_motion
        colors = scene.colors(scene.marker_motion[:, None])
        self.markers = [self.axes.scatter(*moved[chosen].T, c=colors[chosen], marker=shape, s=20,
                                          depthshade=False)
                        for shape in ("s", "D") if (chosen := scene.marker_shapes == shape).any()]


# --- determinant scan ---------------------------------------------------------------

def plot_scan(omegas, sign, log_abs, roots, count, path, title: str = "") -> None:
    """Write the det/count scan figure.

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
    figure.savefig(path, format="png", dpi=_DPI)


# --- response and FRF ---------------------------------------------------------------

def plot_response(result, path, quantity: str = "displacement", title: str = "") -> None:
    """Write the response histories of a :class:`linmstmm.response.ResponseResult`.

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
    figure.savefig(path, format="png", dpi=_DPI)


def plot_frf(result, path, natural_hz=(), load_unit: str = "N", title: str = "") -> None:
    """Write magnitude and phase of a :class:`linmstmm.response.FRFResult`.

    Every (point, component) whose largest |H| is at least SIGNIFICANT × the
    largest of its kind (translation or rotation) is drawn. natural_hz :
    natural frequencies to mark. load_unit : unit of the load, "N" or "N m".
    """
    figure, axes = _canvas((9.0, 6.5), 2, 1, sharex=True, height_ratios=(2, 1))
    top, bottom = axes[:, 0]
    for p, c in significant_components(result.receptance):
        unit = "m" if c < 3 else "rad"
        line, = top.semilogy(result.excitation_hz, np.abs(result.receptance[:, p, c]), lw=1.0,
                             label=f"{result.points[p]} {COMPONENTS[c]} [{unit}/{load_unit}]")
        bottom.plot(result.excitation_hz, np.degrees(np.angle(result.receptance[:, p, c])),
                    lw=1.0, color=line.get_color())
    for frequency in natural_hz:
        for axis in (top, bottom):
            axis.axvline(frequency, color="0.5", ls=":", lw=0.8)
    top.set_ylabel("|receptance|")
    top.legend(fontsize=7, loc="best")
    top.grid(alpha=0.3, which="both")
    top.set_title(title or "frequency response (receptance)")
    bottom.set_ylabel("phase [deg]")
    bottom.set_yticks([-180, -90, 0, 90, 180])
    bottom.set_xlabel("frequency [Hz]")
    bottom.grid(alpha=0.3)
    figure.savefig(path, format="png", dpi=_DPI)


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
