"""Firing scenes of the MLRS-style launcher (``models/mlrs/``, ``docs/model-format.md``).

"Model only what a scene requires": in the scene of tube l (l = 1 … 18, its
slot in the 3 × 6 bundle) only that tube is flexible — two Euler beams on a
rear and a front elastic support, with the breech body on its rear end. The
other seventeen tubes are rigid masses lumped into the cradle. A scene
therefore moves the flexible tube's points to slot l and rebuilds the
cradle's mass, mass centre and inertia by parallel-axis sums of the empty
cradle frame and the seventeen lumped tubes; rockets already fired leave
their tubes lighter in the same sums.

``bundle.toml`` beside the model file describes the bundle: the slot grid,
the slot of the model file's own flexible tube, the names of the cradle and
of the flexible tube's elements, the empty cradle frame and the rocket mass
(smeared over the tube beams in the model file).

A scene is a set of edits of the model file's values (:func:`scene_values`,
keys of :mod:`linmstmm.parameters`), so a sequence of scenes is a parameter
study: :func:`scene_study` solves it with :func:`linmstmm.sweep.sweep` (warm
starts from the previous scene, modes tracked by MAC, local processes or a
dask cluster), and :func:`scene_model` is the model of one scene.
"""
from __future__ import annotations

import dataclasses
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from linmstmm.geometry import local_axes, norm3
from linmstmm.model import Model, load_model
from linmstmm.parameters import parse_key, with_values
from linmstmm.sweep import SweepResult, sweep


@dataclass(frozen=True)
class MassProps:
    """Mass (kg), mass centre (3,) m and inertia tensor (3, 3) kg m² about it, inertial axes."""

    mass: float
    com: np.ndarray
    inertia: np.ndarray

    def origin_tensor(self) -> np.ndarray:
        """Inertia tensor about the inertial origin (parallel-axis theorem)."""
        return self.inertia + self.mass * _arm_tensor(self.com)

    def __add__(self, other: MassProps) -> MassProps:
        return _from_origin(self.mass + other.mass, self.mass * self.com + other.mass * other.com,
                            self.origin_tensor() + other.origin_tensor())

    def __sub__(self, other: MassProps) -> MassProps:
        return _from_origin(self.mass - other.mass, self.mass * self.com - other.mass * other.com,
                            self.origin_tensor() - other.origin_tensor())

    def scaled(self, factor: float) -> MassProps:
        """The same shape with ``factor`` times the density."""
        return MassProps(factor * self.mass, self.com, factor * self.inertia)

    def shifted(self, offset) -> MassProps:
        """The same body translated by ``offset`` (m)."""
        return MassProps(self.mass, self.com + offset, self.inertia)


def _from_origin(mass, first_moment, origin_tensor) -> MassProps:
    """MassProps from the mass, the first moment Σ m c and the inertia tensor about the origin."""
    com = first_moment / mass
    inertia = origin_tensor - mass * _arm_tensor(com)
    return MassProps(mass, com, (inertia + inertia.T) / 2)


_IDENTITY = np.eye(3)


def _arm_tensor(c: np.ndarray) -> np.ndarray:
    """(3, 3) |c|² I − c cᵀ of a (3,) offset c (m²): the parallel-axis term per unit mass
    (the same numbers as ``c @ c * np.eye(3) - np.outer(c, c)``, without their call costs)."""
    return c @ c * _IDENTITY - c[:, None] * c


def rigid_props(rigid) -> MassProps:
    """Mass properties of a Rigid record."""
    return MassProps(rigid.mass, np.asarray(rigid.com, float), np.asarray(rigid.inertia, float))


def beam_props(beam, points) -> MassProps:
    """Mass properties of a Beam record moving rigidly.

    Euler beams carry no rotary inertia in bending, so the rigid limit is a
    slender rod: m L²/12 about the transverse axes and ρ Ip L about its own axis.
    """
    a, b = (np.asarray(points[p], float) for p in beam.ends)
    along = np.outer(beam.axes[0], beam.axes[0])
    inertia = (beam.rho * beam.Ip * beam.length * along
               + beam.mass * beam.length**2 / 12 * (np.eye(3) - along))
    return MassProps(beam.mass, (a + b) / 2, inertia)


def tube_frame(along) -> np.ndarray:
    """(3, 3) rows: along the tubes, lateral (left, e_Z × along), normal (upwards): the
    local axes of a beam along the tubes (:func:`linmstmm.geometry.local_axes`)."""
    along = np.asarray(along, float)
    return local_axes(along / norm3(along))


@dataclass(frozen=True)
class Bundle:
    """The tube bundle of a ``bundle.toml``.

    rows × columns slots; tube l = (row − 1) · columns + column, row 1 on
    top, column 1 on the left; spacings in m. base_tube : the slot of the
    model file's flexible tube. cradle : name of the cradle body. tube :
    names of the flexible tube's elements (beams, bodies, supports).
    frame_mass (kg), frame_com (3,) m, frame_inertia (3,) kg m²: the empty
    cradle frame, principal moments about the tube axes (along, lateral,
    normal). rocket_mass : kg, smeared over the tube's beams.
    """

    rows: int
    columns: int
    row_spacing: float
    column_spacing: float
    base_tube: int
    cradle: str
    tube: tuple[str, ...]
    frame_mass: float
    frame_com: np.ndarray
    frame_inertia: np.ndarray
    rocket_mass: float

    @property
    def slots(self) -> range:
        """All tube numbers, 1 … rows · columns."""
        return range(1, self.rows * self.columns + 1)

    def grid(self, tube: int) -> tuple[int, int]:
        """(row, column) of slot ``tube``, both counted from 1."""
        if tube not in self.slots:
            raise ValueError(f"tube {tube} is not a slot of the {self.rows} x {self.columns} "
                             f"bundle (1 … {len(self.slots)})")
        row, column = divmod(tube - 1, self.columns)
        return row + 1, column + 1

    def offset(self, tube: int, axes: np.ndarray) -> np.ndarray:
        """(3,) m: slot ``tube`` relative to the base slot; ``axes`` from :func:`tube_frame`."""
        row, column = self.grid(tube)
        row0, column0 = self.grid(self.base_tube)
        return ((column0 - column) * self.column_spacing * axes[1]
                + (row0 - row) * self.row_spacing * axes[2])

    def frame(self, axes: np.ndarray) -> MassProps:
        """The empty cradle frame in inertial axes."""
        return MassProps(self.frame_mass, self.frame_com,
                         axes.T @ np.diag(self.frame_inertia) @ axes)


def load_bundle(path) -> Bundle:
    """Read a ``bundle.toml`` (see ``models/mlrs/bundle.toml``)."""
    with open(path, "rb") as stream:
        data = tomllib.load(stream)
    grid, frame = data["grid"], data["frame"]
    return Bundle(grid["rows"], grid["columns"], grid["row_spacing"], grid["column_spacing"],
                  grid["base_tube"], data["cradle"], tuple(data["tube"]),
                  float(frame["mass"]), np.array(frame["com"], float),
                  np.array(frame["inertia_tube_axes"], float), float(data["rocket"]["mass"]))


def bundle_beside(model: Model) -> Bundle:
    """The ``bundle.toml`` in the directory of the model file."""
    if model.source is None:
        raise ValueError(f"model {model.name!r} has no file, so no bundle.toml beside it: "
                         "pass bundle= explicitly")
    return load_bundle(Path(model.source).with_name("bundle.toml"))


def tube_axes(model: Model, bundle: Bundle) -> np.ndarray:
    """Tube frame (along, lateral, normal) of the flexible tube's first beam."""
    beam = next(b for b in model.beams if b.name in bundle.tube)
    return tube_frame(beam.axes[0])


def loaded_tube(model: Model, bundle: Bundle) -> tuple[MassProps, MassProps]:
    """(whole loaded tube, its rocket) as rigid masses in the base slot.

    The rocket is smeared uniformly over the tube's beams, so it is the
    beams' mass properties scaled by rocket mass / beam mass.
    """
    parts = [model.element(name) for name in bundle.tube]
    beams = [beam_props(p, model.points) for p in parts if p.kind == "beam"]
    bodies = [rigid_props(p) for p in parts if p.kind == "rigid"]
    beam_total = sum(beams[1:], beams[0])
    return sum(bodies, beam_total), beam_total.scaled(bundle.rocket_mass / beam_total.mass)


def cradle_props(model: Model, bundle: Bundle, tube: int,
                 rockets_fired=frozenset()) -> MassProps:
    """The cradle of scene ``tube``: frame + every other tube, rocket-less where fired."""
    return SceneMaker(model, bundle).cradle(tube, frozenset(rockets_fired))


def scene_values(model: Model, tube: int, rockets_fired=frozenset(),
                 bundle: Bundle | None = None) -> dict[str, float]:
    """The scene where tube ``tube`` fires, as edits of ``model``.

    Parameters
    ----------
    model : Model
        The launcher model (its flexible tube in the bundle's base slot).
    tube : int
        The firing tube's slot, 1 … rows · columns.
    rockets_fired : iterable of int
        Slots whose rockets are gone (not ``tube`` itself: the firing tube is loaded).
    bundle : Bundle or None
        Default the ``bundle.toml`` beside the model file.

    Returns
    -------
    dict of str to float
        Key (:mod:`linmstmm.parameters`) -> value, SI: every coordinate of the
        flexible tube's points and mass centres, moved to slot ``tube`` (m),
        and the cradle's mass (kg), mass centre (m) and inertia tensor (kg m²,
        each symmetric pair once). Every scene sets the same keys, so a list
        of scenes is a list of steps for :func:`linmstmm.sweep.sweep`.

    Raises
    ------
    ValueError
        For a slot that is not in the bundle, or a firing tube listed as fired.
    """
    return SceneMaker(model, bundle or bundle_beside(model)).values(tube, rockets_fired)


class SceneMaker:
    """The scenes of one launcher model and bundle: what every scene shares (the tube
    frame, the loaded and the emptied tube, the keys) made once, each tube lumped in
    its slot made when a scene first asks for it (a caller of one scene builds the
    tubes it sums: 17 of the launcher's 36), and the cradle's running sums over the slots kept, so
    that scenes whose slots agree up to some slot add those up once (scene l and
    scene l + 1 share the sum over slots 1 … l − 1). Every number is formed by the
    same operations in the same order as for one scene alone: the same bits.

    Parameters
    ----------
    model : Model
        The launcher model (its flexible tube in the bundle's base slot).
    bundle : Bundle
        Its tube bundle.
    """

    def __init__(self, model: Model, bundle: Bundle):
        self.model, self.bundle = model, bundle
        self.axes = tube_axes(model, bundle)
        loaded, rocket = loaded_tube(model, bundle)
        self._tubes = {False: loaded, True: loaded - rocket}  # fired -> the tube in the base slot
        self._lumped: dict[tuple[int, bool], MassProps] = {}  # (slot, fired) -> :meth:`_lumped_tube`
        self._sums = {(): bundle.frame(self.axes)}  # slots added so far -> frame + those tubes
        moving = set()
        for element in map(model.element, bundle.tube):
            moving.update(element.ports if element.kind == "rigid" else element.ends)
        self._points = [name for name in model.points if name in moving]
        self._bodies = [rigid for rigid in model.rigids if rigid.name in bundle.tube]

    def cradle(self, tube: int, fired: frozenset) -> MassProps:
        """The cradle of scene ``tube``: frame + every other tube, rocket-less where fired.

        Parameters
        ----------
        tube : int
            The firing tube's slot (left out of the sum).
        fired : frozenset of int
            Slots whose rockets are gone.

        Returns
        -------
        MassProps
            kg, m, kg m²: the sum slot by slot from the frame (:func:`cradle_props`).
        """
        added, total = (), self._sums[()]
        for slot in self.bundle.slots:
            if slot != tube:
                added += ((slot, slot in fired),)
                if added not in self._sums:
                    self._sums[added] = total + self._lumped_tube(*added[-1])
                total = self._sums[added]
        return total

    def _lumped_tube(self, slot: int, fired: bool) -> MassProps:
        """The tube of ``slot`` as a rigid mass there (kg, m, kg m²), loaded or, where
        ``fired``, without its rocket; made once, when a scene first sums it."""
        if (slot, fired) not in self._lumped:
            self._lumped[slot, fired] = self._tubes[fired].shifted(self.bundle.offset(slot, self.axes))
        return self._lumped[slot, fired]

    def values(self, tube: int, rockets_fired=frozenset()) -> dict[str, float]:
        """The scene where tube ``tube`` fires, as edits of the model.

        Parameters
        ----------
        tube : int
            The firing tube's slot, 1 … rows · columns.
        rockets_fired : iterable of int
            Slots whose rockets are gone (not ``tube`` itself).

        Returns
        -------
        dict of str to float
            As :func:`scene_values` gives them.

        Raises
        ------
        ValueError
            For a slot that is not in the bundle, or a firing tube listed as fired.
        """
        bundle, fired = self.bundle, frozenset(rockets_fired)
        if tube in fired:
            raise ValueError(f"tube {tube} fires in this scene, so its rocket cannot be already fired")
        unknown = sorted(fired - set(bundle.slots))
        if unknown:
            raise ValueError(f"rockets_fired: {unknown} are not slots of the bundle (1 … {len(bundle.slots)})")
        offset = bundle.offset(tube, self.axes)
        values = {}
        for name in self._points:
            values.update(_vector(f"points.{name}", self.model.points[name] + offset))
        cradle = self.cradle(tube, fired)
        values[f"rigid.{bundle.cradle}.mass"] = float(cradle.mass)
        values.update(_vector(f"rigid.{bundle.cradle}.com", cradle.com))
        values.update({f"rigid.{bundle.cradle}.inertia[{i}][{j}]": float(cradle.inertia[i, j])
                       for i in range(3) for j in range(i, 3)})
        for rigid in self._bodies:
            values.update(_vector(f"rigid.{rigid.name}.com", rigid.com + offset))
        return values


def scene_model(base, tube: int, rockets_fired=frozenset(), bundle: Bundle | None = None) -> Model:
    """The model of the scene where tube ``tube`` fires.

    Parameters
    ----------
    base : Model or path
        The launcher model or its file (``bundle.toml`` is read beside it
        unless ``bundle`` is given).
    tube : int
        The firing tube's slot.
    rockets_fired : iterable of int
        Slots whose rockets are gone (not ``tube`` itself: the firing tube is loaded).
    bundle : Bundle or None
        The tube bundle.

    Returns
    -------
    Model
        ``base`` with the edits of :func:`scene_values` (the beams whose ends
        moved take their length and axes from the moved points), named after the scene.
    """
    model = base if isinstance(base, Model) else load_model(base)
    fired = frozenset(rockets_fired)
    values = scene_values(model, tube, fired, bundle)
    name = f"{model.name}, tube {tube} firing"
    if fired:
        name += f", rockets {', '.join(map(str, sorted(fired)))} fired"
    edited = with_values(model, {parse_key(model, key): value for key, value in values.items()})
    return dataclasses.replace(edited, name=name)


def salvo(tube: int) -> frozenset:
    """Rockets gone when tube ``tube`` fires in a salvo in slot order 1, 2, …"""
    return frozenset(range(1, tube))


def scene_study(base, count: int = 6, tubes=range(1, 19), fired=None, bundle: Bundle | None = None,
                warm_start: bool = True, engine: str = "auto", **options) -> SweepResult:
    """The scenes of ``tubes`` as a parameter study: one step of :func:`linmstmm.sweep.sweep` each.

    Parameters
    ----------
    base : Model or path
        The launcher model or its file; read and validated once, each scene
        only moves the tube and rebuilds the cradle (:meth:`SceneMaker.values`).
    count : int
        Elastic frequencies per scene.
    tubes : iterable of int
        The firing tubes, in the order of the steps.
    fired : callable or None
        tube -> slots already fired (e.g. :func:`salvo`); default none.
    bundle : Bundle or None
        Default the ``bundle.toml`` beside the model file.
    warm_start : bool
        Start each scene's root search from the previous scene's frequencies, or
        from them extrapolated along their last move (certified by a root count as
        a cold search is), while these miss by less than the coarse predictions'
        error allows (:func:`linmstmm.warm_starts.warm_starts`), else from the
        scene's predictions: with every other tube loaded the roots move 40 ppm a
        scene and every scene starts warm; in a salvo, whose scenes move 1-1.4 %,
        the extrapolation misses by 3e-4 to 1e-3 away from the scenes where two
        modes veer, and about half the scenes start from it.
    engine : str
        How det Ū_all is evaluated (default "auto", resolved once for every scene
        as :func:`linmstmm.sweep.sweep` resolves it: the compiled kernels if this
        process has loaded them, or where the scenes are many enough to pay for
        loading them; else numpy).
    **options
        Passed to :func:`linmstmm.sweep.sweep`: ``workers``, ``dask``,
        ``sensitivity``, ``progress``, ``track_modes``.

    Returns
    -------
    SweepResult
        One step per tube, modes tracked by MAC from scene to scene.
    """
    model = base if isinstance(base, Model) else load_model(base)
    bundle = bundle or bundle_beside(model)
    scenes = SceneMaker(model, bundle)
    steps = [scenes.values(tube, fired(tube) if fired else frozenset()) for tube in tubes]
    return sweep(model, steps, count=count, warm_start=warm_start, engine=engine, **options)


def scene_sweep(base, count: int = 6, tubes=range(1, 19), fired=None,
                bundle: Bundle | None = None, warm_start: bool = True, engine: str = "auto",
                **options) -> list:
    """[(tube, frequencies in Hz)] of the scenes of ``tubes``, from :func:`scene_study` without
    mode shapes or tracking (the frequencies by rank, as the firing-scene tables show them:
    half the cost of a tracked study).

    Parameters
    ----------
    base, count, tubes, fired, bundle, warm_start, engine, **options
        As for :func:`scene_study`.

    Returns
    -------
    list of (int, ndarray)
        Per tube its elastic natural frequencies (Hz, ascending, at most ``count``).
    """
    tubes = list(tubes)
    study = scene_study(base, count, tubes, fired, bundle, warm_start, engine, track_modes=False, **options)
    return [(tube, row[~np.isnan(row)]) for tube, row in zip(tubes, study.frequencies_hz_by_rank)]


def _vector(key: str, values) -> dict[str, float]:
    """``key[i]`` -> ``values[i]`` for each coordinate of a (3,) vector."""
    return {f"{key}[{i}]": float(v) for i, v in enumerate(values)}
