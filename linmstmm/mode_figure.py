"""Mode-shape figures: three orthographic views and an isometric view of one mode.

:func:`plot_mode` writes a PNG, :func:`animate_mode` an animated GIF (one
period of the motion, a single shared palette), :func:`mode_shape_figure`
returns the PNG's figure unsaved. All three are re-exported by
:mod:`linmstmm.plot`. Every view is a 2-D projection drawn on matplotlib's
Agg canvas; no window is opened and pyplot's global state is not touched.

Each view shows the undeformed structure in light grey under the deformed
one, coloured by the size of the local translation as a fraction of the
largest: beams as their deflected curves (the stations of
:class:`linmstmm.modes.BeamField`), rigid bodies as the filled outline
(convex hull) of their ports and mass centre with a square on the mass
centre, springs as diamonds (a spring has zero length; a thin line joins its
two ends when they move apart). The mode is scaled so that its largest
translation is drawn as ``AMPLITUDE`` × the size of the model; the title
gives that scale. In each view nearer pieces are drawn over farther ones.
"""
from __future__ import annotations

from dataclasses import dataclass

import matplotlib
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.cm import ScalarMappable
from matplotlib.collections import LineCollection, PolyCollection
from matplotlib.colors import Normalize
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from PIL import Image

from linmstmm.model import Model
from linmstmm.modes import ModalResult

#: Largest drawn modal translation, as a fraction of the model's size.
AMPLITUDE = 0.1
#: A mode whose largest translation is below this fraction of (model size ×
#: largest rotation) is drawn undeformed and called "rotation only".
NO_TRANSLATION = 1e-9
#: Frames per period of an animated mode, and frames per second.
FRAMES, FPS = 12, 10
#: Half the shortest side of the box of a mode figure, as a fraction of the model size.
_THINNEST = 0.25
#: Width of a mode figure, inches, and its resolution as PNG and as GIF (dots per inch):
#: 1430 and 990 pixels wide.
_WIDTH, _DPI, _GIF_DPI = 11.0, 130, 90
#: Colours in the shared palette of an animated mode.
_GIF_COLORS = 96

_COLORMAP = "plasma"
_UNDEFORMED = "0.8"
_UNDEFORMED_FILL = "0.92"
_WIDTHS = {"beam": 3.0, "spring": 0.8}
_BODY_ALPHA = 0.55


@dataclass(frozen=True)
class _View:
    """A projection: screen right and up as unit vectors (3,) in the model's frame."""

    title: str
    right: tuple
    up: tuple
    labels: tuple[str, str] | None  # axis labels; None: no axes (the isometric view)

    def project(self, points) -> np.ndarray:
        """(..., 3) points -> (..., 2) screen coordinates, m."""
        return np.asarray(points, dtype=float) @ np.array([self.right, self.up]).T

    def depth(self, points) -> np.ndarray:
        """(..., 3) points -> (...) distance towards the viewer, m."""
        return np.asarray(points, dtype=float) @ np.cross(self.right, self.up)


_ISO_RIGHT, _ISO_UP = np.array([1.0, 1.0, 0.0]) / np.sqrt(2), np.array([-1.0, 1.0, 2.0]) / np.sqrt(6)
#: The four views, in the order of the figure's grid (row by row).
VIEWS = (_View("x–z plane, seen from −y", (1, 0, 0), (0, 0, 1), ("x [m]", "z [m]")),
         _View("y–z plane, seen from +x", (0, 1, 0), (0, 0, 1), ("y [m]", "z [m]")),
         _View("x–y plane, seen from +z", (1, 0, 0), (0, 1, 0), ("x [m]", "y [m]")),
         _View("isometric, seen from (+x, −y, +z)", tuple(_ISO_RIGHT), tuple(_ISO_UP), None))


@dataclass(frozen=True, eq=False)
class _Scene:
    """One mode ready to draw.

    segments : (N, 2, 3) undeformed beam pieces and springs, m; segment_motion
    : (N, 2, 3) the mode's translation at their ends; widths : (N,) line
    widths. bodies : per rigid body, (K, 3) ports and mass centre, m;
    body_motion : their translations. markers : (M, 3) mass centres and spring
    middles; marker_motion : (M, 3); marker_shapes : (M,) "s" (mass centre) or
    "D" (spring). scale : modal to drawn translation (0: drawn undeformed).
    largest : largest modal translation (0 for a rotation-only mode). size :
    the model's size, m. limits : (3, 2) axes limits, m.
    """

    segments: np.ndarray
    segment_motion: np.ndarray
    widths: np.ndarray
    bodies: tuple
    body_motion: tuple
    markers: np.ndarray
    marker_motion: np.ndarray
    marker_shapes: np.ndarray
    scale: float
    largest: float
    size: float
    limits: np.ndarray
    title: str

    def colors(self, motion) -> np.ndarray:
        """(n, 4) colours of |motion| (n, m, 3) averaged over its m places, relative to ``largest``."""
        size = np.linalg.norm(np.asarray(motion, dtype=float), axis=-1).mean(axis=1)
        return matplotlib.colormaps[_COLORMAP](size / self.largest if self.largest else 0 * size)

    def body_colors(self) -> np.ndarray:
        """(bodies, 4) colours of the rigid bodies (mean |translation| of their points)."""
        return np.array([self.colors(motion[None])[0] for motion in self.body_motion]).reshape(-1, 4)


def plot_mode(result: ModalResult, model: Model, k: int, path) -> None:
    """Write mode ``k`` (0-based index into ``result``) of ``model`` as a PNG figure.

    Three orthographic views (x–z, y–z, x–y) and an isometric view, 1430
    pixels wide. Undeformed structure light grey, deformed structure coloured
    by |translation| as a fraction of the largest; the title gives the mode
    number (from 1), the frequency, the modal mass and the drawing scale.
    """
    mode_shape_figure(result, model, k).savefig(path, format="png", dpi=_DPI)


def mode_shape_figure(result: ModalResult, model: Model, k: int) -> Figure:
    """The figure :func:`plot_mode` writes (same arguments but the path), not yet saved."""
    scene = _scene(result, model, k)
    figure, views = _mode_canvas(scene)
    for view in views:
        view.pose(1.0)
    return figure


def animate_mode(result: ModalResult, model: Model, k: int, path,
                 frames: int = FRAMES, fps: int = FPS) -> None:
    """Write mode ``k`` of ``model`` as an animated GIF: one period of sin ωt in ``frames`` frames.

    The same four views as :func:`plot_mode`, 990 pixels wide, every frame
    on one palette of at most 96 colours (a few hundred kB for the launcher).
    """
    scene = _scene(result, model, k)
    figure, views = _mode_canvas(scene)
    images = []
    for phase in np.arange(frames) / frames:
        for view in views:
            view.pose(np.sin(2 * np.pi * phase))
        images.append(_frame(figure))
    palette = images[0].quantize(colors=_GIF_COLORS, method=Image.Quantize.MEDIANCUT)
    indexed = [image.quantize(palette=palette, dither=Image.Dither.NONE) for image in images]
    indexed[0].save(path, format="GIF", save_all=True, append_images=indexed[1:],
                    duration=round(1000 / fps), loop=0, optimize=True)


def _frame(figure) -> Image.Image:
    """The figure drawn at the GIF resolution, as an RGB image."""
    figure.set_dpi(_GIF_DPI)
    canvas = figure.canvas
    canvas.draw()
    return Image.fromarray(np.asarray(canvas.buffer_rgba())[..., :3].copy())


# --- the scene ----------------------------------------------------------------------

def _scene(result: ModalResult, model: Model, k: int) -> _Scene:
    """Pieces, scale, limits and title of mode ``k``."""
    if not 0 <= k < result.omega.size:
        raise IndexError(f"mode index {k} out of range: the result has {result.omega.size} modes")
    segments, widths, bodies, markers, shapes = _pieces(result, model, k)
    every = np.concatenate([segments.reshape(-1, 2, 3), *bodies, markers])  # (·, 2, 3)
    positions = np.concatenate([every[:, 0], np.array(list(model.points.values()), dtype=float)])
    size = max(float(np.ptp(positions, axis=0).max()), 1e-3)
    largest = float(np.linalg.norm(every[:, 1], axis=-1).max(initial=0.0))
    rotation = np.abs(result.shape_matrix().reshape(result.omega.size, -1, 6)[k, :, 3:]).max()
    moves = largest > NO_TRANSLATION * size * rotation
    reach = AMPLITUDE * size
    low, high = positions.min(axis=0) - reach, positions.max(axis=0) + reach
    middle, half = (low + high) / 2, np.maximum((high - low) / 2, _THINNEST * size)
    scale = reach / largest if moves else 0.0
    return _Scene(segments[:, :, 0], segments[:, :, 1], widths,
                  tuple(body[:, 0] for body in bodies), tuple(body[:, 1] for body in bodies),
                  markers[:, 0], markers[:, 1], shapes, scale, largest if moves else 0.0, size,
                  np.stack([middle - half, middle + half], axis=1),
                  _mode_title(result, model, k, scale, size))


def _pieces(result: ModalResult, model: Model, k: int):
    """The structure of mode ``k``, every place as (position, modal translation).

    Returns segments (N, 2 ends, 2, 3) of beams and springs, widths (N,),
    bodies (per rigid body (K, 2, 3): its ports, then its mass centre),
    markers (M, 2, 3) and marker shapes (M,).
    """
    def at(point):
        return model.points[point], result.point_displacements[point][k, :3]

    segments, widths, bodies, markers, shapes = [], [], [], [], []
    for field in result.beam_fields.values():
        ends = np.stack([field.positions, field.displacements[k, :, :3]], axis=1)
        segments += list(np.stack([ends[:-1], ends[1:]], axis=1))
        widths += [_WIDTHS["beam"]] * (len(ends) - 1)
    for rigid in model.rigids:
        centre = (rigid.com, result.com_displacements[rigid.name][k, :3])
        bodies.append(np.array([*map(at, rigid.ports), centre], dtype=float))
        markers.append(centre)
        shapes.append("s")
    for spring in model.springs:
        ends = np.array([at(end) for end in spring.ends], dtype=float)
        segments.append(ends)
        widths.append(_WIDTHS["spring"])
        markers.append(ends.mean(axis=0))
        shapes.append("D")
    return (np.array(segments, dtype=float).reshape(-1, 2, 2, 3), np.array(widths), bodies,
            np.array(markers, dtype=float).reshape(-1, 2, 3), np.array(shapes))


def _mode_title(result: ModalResult, model: Model, k: int, scale: float, size: float) -> str:
    kind = "rigid-body mode" if result.omega[k] == 0 else f"f = {result.frequencies_hz[k]:.6g} Hz"
    mass = (f"modal mass {result.modal_mass[k]:.4g} {result.modal_mass_units[k].replace('^2', '²')} "
            f"({result.normalization} normalisation)")
    drawing = (f"displacements drawn × {scale:.3g}: the largest as {AMPLITUDE:g} × the model's size "
               f"({size:.3g} m)" if scale else "rotation only, drawn undeformed")
    return f"{model.name}\nmode {k + 1}: {kind}, {mass}\n{drawing}"


def convex_hull(points) -> np.ndarray:
    """(H, 2) corners of the convex hull of (n, 2) ``points``, counter-clockwise.

    Andrew's monotone chain; collinear or coincident points give the two
    ends of their segment (or the one point), never an error.
    """
    unique = np.unique(np.asarray(points, dtype=float), axis=0)  # sorted by x, then y
    if len(unique) < 3:
        return unique

    def turns_left(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]) > 0

    def chain(ordered):
        kept = []
        for p in ordered:
            while len(kept) >= 2 and not turns_left(kept[-2], kept[-1], p):
                kept.pop()
            kept.append(p)
        return kept[:-1]
    return np.array(chain(unique) + chain(unique[::-1]))


# --- drawing ------------------------------------------------------------------------

def _mode_canvas(scene: _Scene):
    """An Agg figure with the four views (undeformed drawn), colour bar, legend and title.

    Returns the figure and one :class:`_DeformedView` per view.
    """
    spans = np.ptp(scene.limits, axis=1)
    columns, rows = (spans[0], max(spans[1], 0.6 * spans[0])), (spans[2], max(spans[1], 0.45 * spans[0]))
    height = _WIDTH * sum(rows) / sum(columns) + 2.2
    figure = Figure(figsize=(_WIDTH, height), layout="constrained")
    FigureCanvasAgg(figure)
    grid = figure.subplots(2, 2, width_ratios=columns, height_ratios=rows).ravel()
    views = [_DeformedView(axes, view, scene) for axes, view in zip(grid, VIEWS)]
    label = "displacement, fraction of largest" if scene.largest else "no translation"
    figure.colorbar(ScalarMappable(Normalize(0.0, 1.0), _COLORMAP), ax=grid.tolist(), location="bottom",
                    shrink=0.5, aspect=40, pad=0.02, label=label)
    figure.suptitle(scene.title, fontsize=10)
    figure.legend(handles=_legend_handles(scene), loc="outside lower center", ncols=5, fontsize=8,
                  frameon=False)
    return figure, views


def _legend_handles(scene: _Scene) -> list:
    """Legend entries for the undeformed structure and each kind of piece the scene has."""
    handles = [Line2D([], [], color=_UNDEFORMED, lw=2, label="undeformed")]
    if (scene.widths == _WIDTHS["beam"]).any():
        handles.append(Line2D([], [], color="tab:purple", lw=_WIDTHS["beam"], label="beam"))
    if scene.bodies:
        handles += [Patch(facecolor="tab:purple", alpha=_BODY_ALPHA, edgecolor="tab:purple",
                          label="rigid body: outline of its ports and mass centre"),
                    Line2D([], [], color="tab:purple", marker="s", ls="", markersize=4, label="mass centre")]
    if (scene.marker_shapes == "D").any():
        handles.append(Line2D([], [], color="tab:purple", marker="D", ls="", markersize=4, label="spring"))
    return handles


class _DeformedView:
    """One view on ``axes``: the undeformed structure, and the deformed one moved by :meth:`pose`."""

    def __init__(self, axes, view: _View, scene: _Scene):
        self.axes, self.view, self.scene = axes, view, scene
        self.segment_order = np.argsort(view.depth(scene.segments.mean(axis=1)), kind="stable")
        self.body_order = np.argsort([view.depth(body.mean(axis=0)) for body in scene.bodies],
                                     kind="stable").astype(int)
        self.marker_order = np.argsort(view.depth(scene.markers), kind="stable")
        widths = scene.widths[self.segment_order]
        axes.add_collection(PolyCollection(self._hulls(0.0), facecolors=_UNDEFORMED_FILL,
                                           edgecolors=_UNDEFORMED, linewidths=0.8, zorder=1))
        axes.add_collection(LineCollection(self._segments(0.0), colors=_UNDEFORMED, linewidths=widths,
                                           zorder=1))
        colors = scene.body_colors()[self.body_order]
        self.hulls = PolyCollection(self._hulls(1.0), facecolors=colors, edgecolors=colors,
                                    alpha=_BODY_ALPHA, linewidths=1.0, zorder=2)
        self.lines = LineCollection(self._segments(1.0), linewidths=widths, zorder=3,
                                    colors=scene.colors(scene.segment_motion[self.segment_order]))
        axes.add_collection(self.hulls)
        axes.add_collection(self.lines)
        marker_colors = scene.colors(scene.marker_motion[self.marker_order, None])
        self.shapes = scene.marker_shapes[self.marker_order]
        self.markers = {shape: axes.scatter(*self._markers(1.0)[self.shapes == shape].T, marker=shape,
                                            c=marker_colors[self.shapes == shape], s=18, zorder=4,
                                            edgecolors="k", linewidths=0.3)
                        for shape in ("s", "D") if (self.shapes == shape).any()}
        self._frame()

    def pose(self, factor: float) -> None:
        """Move the deformed structure to ``factor`` (−1 … 1) × the scaled mode."""
        self.lines.set_segments(self._segments(factor))
        self.hulls.set_verts(self._hulls(factor))
        moved = self._markers(factor)
        for shape, markers in self.markers.items():
            markers.set_offsets(moved[self.shapes == shape])

    def _markers(self, factor):
        scene = self.scene
        return self.view.project(scene.markers + factor * scene.scale * scene.marker_motion)[self.marker_order]

    def _segments(self, factor):
        scene = self.scene
        return self.view.project(scene.segments + factor * scene.scale * scene.segment_motion)[self.segment_order]

    def _hulls(self, factor):
        scene = self.scene
        return [convex_hull(self.view.project(scene.bodies[b] + factor * scene.scale * scene.body_motion[b]))
                for b in self.body_order]

    def _frame(self) -> None:
        """Limits, equal scales, labels; the isometric view gets an axis triad instead of axes."""
        axes, view, scene = self.axes, self.view, self.scene
        if view.labels is None:  # the structure's own extent, with room for the motion
            places = np.concatenate([scene.segments.reshape(-1, 3), *scene.bodies, scene.markers])
            screen = view.project(places)
            reach = AMPLITUDE * scene.size
            low, high = screen.min(axis=0) - reach, screen.max(axis=0) + reach
        else:
            low, high = view.project(scene.limits.T)
        axes.set_xlim(low[0], high[0])
        axes.set_ylim(low[1], high[1])
        axes.set_aspect("equal", adjustable="box")
        axes.set_title(view.title, fontsize=9)
        if view.labels is None:
            axes.set_axis_off()
            self._triad()
            return
        axes.set_xlabel(view.labels[0], fontsize=8)
        axes.set_ylabel(view.labels[1], fontsize=8)
        axes.tick_params(labelsize=7)
        axes.grid(alpha=0.25)

    def _triad(self) -> None:
        """Arrows x, y, z of the model's frame in the lower left corner of the view."""
        origin = (0.1, 0.12)
        for name, axis in zip("xyz", np.eye(3)):
            tip = np.add(origin, 0.08 * self.view.project(axis))
            self.axes.annotate("", tip, origin, xycoords="axes fraction",
                               arrowprops=dict(arrowstyle="->", lw=1.0, color="0.3"))
            self.axes.annotate(name, tip, xycoords="axes fraction", fontsize=8, color="0.3",
                               ha="center", va="center",
                               xytext=12 * self.view.project(axis), textcoords="offset points")
