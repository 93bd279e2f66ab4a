"""The model contract: immutable element records and :func:`load_model`.

A model file is read with :mod:`tomllib`, validated completely
(:mod:`linmstmm.model_file`: its keys, units and limits), and only then
turned into the records below; a :class:`Model` built in code runs the same
checks on construction (its records written in the file's form). Nothing
downstream re-validates: a :class:`Model` is always well formed.
:class:`ModelError` and :data:`COMPONENTS` are defined with the checks and
importable from here.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from linmstmm.model_file import (
    _ORTHO_TOL,
    COMPONENTS,
    ELEMENT_CHECKS,
    ModelError,
    _check_damping,
    _element_table,
    _read_toml,
    _Table,
    _validate,
    _check_gap,
    check_mass,
)
from linmstmm.elements.spring import NO_RELEASED_INDICES
from linmstmm.geometry import length_tolerance

__all__ = ["COMPONENTS", "Beam", "Model", "ModelError", "Rigid", "Spring", "load_model"]


@dataclass(frozen=True, eq=False)
class Rigid:
    """Rigid body.

    ports : point names on the body (one or more), in file order.
    mass : kg. com : (3,) mass centre, m, inertial frame.
    inertia : (3, 3) symmetric tensor about the mass centre, kg m^2, inertial axes.
    """

    name: str
    ports: tuple[str, ...]
    mass: float
    com: np.ndarray
    inertia: np.ndarray
    kind: str = field(default="rigid", init=False)


@dataclass(frozen=True, eq=False)
class Spring:
    """Elastic hinge: massless, zero length, between coinciding points.

    k : (6,) stiffnesses [kx, ky, kz, krx, kry, krz] in the spring's local axes,
        N/m and N m/rad; ``inf`` = rigid in that direction, 0 where released.
    axes : (3, 3) rows = local x, y, z unit vectors in the inertial frame.
    c : (6,) viscous damping in the same layout, N s/m and N m s/rad, or None.
    release : (6,) bool, the released directions (x, y, z, rx, ry, rz in the
        spring's axes): no force or moment passes there and the two ends move
        apart freely (a pin releases one rotation, a universal joint two, a
        ball joint three, a slider one translation). None: nothing released.
    """

    name: str
    ends: tuple[str, str]
    k: np.ndarray
    axes: np.ndarray
    c: np.ndarray | None = None
    release: np.ndarray | None = None
    kind: str = field(default="spring", init=False)

    @cached_property
    def released(self) -> np.ndarray:
        """Indices (0..5: x, y, z, rx, ry, rz) of the released directions, ascending, read-only;
        found once per spring (the kinematics of a 10,000-body chain asked 40,000 times)."""
        return NO_RELEASED_INDICES if self.release is None else _frozen(np.flatnonzero(self.release))


@dataclass(frozen=True, eq=False)
class Beam:
    """Straight uniform Euler-Bernoulli beam from ``ends[0]`` (local x = 0) to ``ends[1]``.

    E, G : Pa. rho : kg/m^3 (0 = massless). A : m^2. Iy, Iz, J, Ip : m^4.
    axes : (3, 3) rows = local x, y, z unit vectors in the inertial frame.
    length : m. axial / torsion : False = rigid in that deformation, inertia kept.
    """

    name: str
    ends: tuple[str, str]
    E: float
    G: float
    rho: float
    A: float
    Iy: float
    Iz: float
    J: float
    Ip: float
    axes: np.ndarray
    length: float
    axial: bool = True
    torsion: bool = True
    kind: str = field(default="beam", init=False)

    @property
    def mass(self) -> float:
        """Total mass, kg."""
        return self.rho * self.A * self.length

    def wavenumbers(self, omega: float) -> dict[str, float]:
        """Wavenumbers, 1/m, of the beam's waves at ``omega`` (rad/s): bending
        (ρA ω²/EI)^¼ with Iy ("bending_y") and Iz ("bending_z"), axial ω√(ρ/E) and
        torsion ω√(ρ Ip/GJ), whether or not a direction is declared rigid (the
        caller decides); all zero for a massless beam."""
        return {"bending_y": (self.rho * self.A * omega ** 2 / (self.E * self.Iy)) ** 0.25,
                "bending_z": (self.rho * self.A * omega ** 2 / (self.E * self.Iz)) ** 0.25,
                "axial": omega * math.sqrt(self.rho / self.E),
                "torsion": omega * math.sqrt(self.rho * self.Ip / (self.G * self.J))}


@dataclass(frozen=True, eq=False)
class Model:
    """A validated model.

    points : name -> (3,) position, m.
    rigids, beams, springs : element records in file order.
    boundary : point name -> (6,) bool mask of fixed components
        (x, y, z, rx, ry, rz); points not listed are free.
    damping : (alpha, beta) of C = alpha M + beta K, or None.
    source : the file it came from (for messages), or None.
    """

    name: str
    points: dict[str, np.ndarray]
    rigids: tuple[Rigid, ...] = ()
    beams: tuple[Beam, ...] = ()
    springs: tuple[Spring, ...] = ()
    boundary: dict[str, np.ndarray] = field(default_factory=dict)
    damping: tuple[float, float] | None = None
    description: str = ""
    source: str | None = None

    def __post_init__(self):
        """Run the loader's checks on these records (a Model built in code included).

        Raises :class:`ModelError` naming ``source`` (or ``model 'name'`` for a
        model built in code), the element and the key, exactly as
        :func:`load_model` does for the same breach in a file.
        """
        _check_records(self)
        _freeze(self)

    @property
    def elements(self):
        """All elements: rigid bodies, then beams, then springs, each in file order."""
        return self.rigids + self.beams + self.springs

    @cached_property
    def _length_tolerance(self) -> float:
        """Distance within which two of its points coincide, m (found once for its edits)."""
        return length_tolerance(self.points)

    def element(self, name: str):
        """The element called ``name``.

        Parameters
        ----------
        name : str
            The element's name.

        Returns
        -------
        Rigid, Beam or Spring

        Raises
        ------
        KeyError
            If the model has no element of that name.
        """
        for element in self.elements:
            if element.name == name:
                return element
        raise KeyError(name)

    def fixed_mask(self, point: str) -> np.ndarray:
        """Which displacement components are fixed at ``point``.

        Parameters
        ----------
        point : str
            A point name.

        Returns
        -------
        numpy.ndarray of bool, shape (6,)
            x, y, z, rx, ry, rz: True where fixed.
        """
        return self.boundary.get(point, np.zeros(6, dtype=bool))


def load_model(path) -> Model:
    """Read, validate and build the model in the TOML file ``path``.

    No record is built before the file is validated, and the :class:`Model`
    checks its records again on construction (the same checks).

    Parameters
    ----------
    path : str or os.PathLike
        The model file (format: ``docs/model-format.md``).

    Returns
    -------
    Model

    Raises
    ------
    ModelError
        One line (file, element, key) on any breach of the contract.
    """
    file = str(path)
    fields = _validate(_read_toml(path, file), file)
    return Model(**fields | {
        "rigids": tuple(_build(Rigid, f) for f in fields["rigids"]),
        "beams": tuple(_build(Beam, f) for f in fields["beams"]),
        "springs": tuple(_build(Spring, f) for f in fields["springs"]),
        "points": {name: _frozen(p) for name, p in fields["points"].items()},
        "boundary": {name: _frozen(m) for name, m in fields["boundary"].items()},
        "source": file,
    })


#: Model attribute -> (element kind in the file, record class).
_RECORD_KINDS = {"rigids": ("rigid", Rigid), "beams": ("beam", Beam), "springs": ("spring", Spring)}


def model_file(model: Model) -> str:
    """Where ``model`` comes from, for the messages of a ModelError.

    Parameters
    ----------
    model : Model
        The model.

    Returns
    -------
    str
        Its file, or ``model 'name'`` for a model built in code.
    """
    return model.source if isinstance(model.source, str) else f"model {model.name!r}"


def _check_records(model):
    """Validate ``model`` by the loader's checks on its records written in the file's form.

    A beam's ``length`` and ``axes`` are not keys of the file (the loader derives
    them from the ends and ``y_axis``): they must agree with what it would derive.
    """
    file = model_file(model)
    fields = _validate(_document(model, file), file)
    tol = length_tolerance(fields["points"])
    for beam, derived in zip(model.beams, fields["beams"]):
        _check_beam_frame(_Table(file, {}, f"beam {beam.name!r}"), beam, derived, tol)


def with_numbers(model: Model, points: dict, records: dict, damping) -> Model:
    """``model`` with some of its numbers changed and nothing else, checked.

    Parameters
    ----------
    model : Model
        A model (validated, as every Model is).
    points : dict of str to ndarray
        Every point of ``model`` -> (3,) position, m: the model's own array where
        the point did not move, a new read-only array where it did.
    records : dict of str to record
        Element name -> its new record, for the elements whose numbers changed:
        of the same kind, with the same name, ports or ends and releases.
    damping : tuple or None
        (alpha, beta); None only where ``model`` has none.

    Returns
    -------
    Model

    Raises
    ------
    ModelError
        As the constructor's full check would (the same first breach, in the
        loader's order), from the checks a change of numbers can break alone:
        the moved points, the changed records, the beams on a moved point (all
        of them where the length tolerance changed), the ends of unchanged
        springs on a moved point (all of them where it shrank), the damping and
        the total mass; names, ports, ends, boundary and connectivity cannot
        change. A launcher scene's edit: 0.2 ms here, 0.9 ms by the full check.
    """
    file = model_file(model)
    moved = {name for name, position in points.items() if position is not model.points[name]}
    point_table = _Table(file, _plain({name: points[name] for name in points if name in moved}), "[points]")
    for name in point_table.table:
        point_table.vector(name, 3)
    tol = length_tolerance(points)
    edited = {attribute: tuple(records.get(r.name, r) for r in getattr(model, attribute))
              for attribute in _RECORD_KINDS}
    frames = []
    for attribute, (kind, _) in _RECORD_KINDS.items():
        for index, record in enumerate(edited[attribute]):
            on_moved = kind != "rigid" and not moved.isdisjoint(record.ends)
            if record.name in records or kind == "beam" and (on_moved or tol != model._length_tolerance):
                table = _element_table(file, kind, index, _plain(_record_table(record, file)))
                fields = ELEMENT_CHECKS[kind](table, points, tol)
                if kind == "beam":
                    frames.append((table, record, fields))
            elif kind == "spring" and (on_moved or tol < model._length_tolerance):
                # a spring's other checks read neither points nor tolerance
                _check_gap(_Table(file, {}, f"spring {record.name!r}"), record.ends, points, tol)
    if damping is not None and damping != model.damping:
        _check_damping(_Table(file, _plain(dict(zip(("alpha", "beta"), damping))), "[damping]"))
    check_mass(file, [r.mass for r in edited["rigids"]], [b.rho * b.A * b.length for b in edited["beams"]])
    for table, beam, derived in frames:
        _check_beam_frame(table, beam, derived, tol)
    new = object.__new__(Model)  # checked above: the constructor would check it all again
    for name in model.__dataclass_fields__:
        object.__setattr__(new, name, getattr(model, name))
    for name, value in dict(edited, damping=damping).items():
        object.__setattr__(new, name, value)
    # the records, points and boundary not edited are the model's own, frozen already
    object.__setattr__(new, "points", FrozenDict(points | {name: _read_only(points[name]) for name in moved}))
    for record in records.values():
        _freeze_record(record)
    return new


def _document(model, file):
    """The model as the parsed TOML document that would load to it (plain Python values)."""
    document = {"name": model.name, "description": model.description, "points": model.points,
                "boundary": _boundary_table(model.boundary, file)}
    for attribute, (kind, cls) in _RECORD_KINDS.items():
        records = getattr(model, attribute)
        for i, record in enumerate(records):
            if not isinstance(record, cls):
                raise ModelError(file, f"{attribute}[{i}] must be a {cls.__name__} record, "
                                       f"got {type(record).__name__}")
        document[kind] = [_record_table(record, file) for record in records]
    if model.damping is not None:
        if np.shape(model.damping) != (2,):
            raise ModelError(file, f"must be None or (alpha, beta), got {model.damping!r}",
                             key="damping")
        document["damping"] = dict(zip(("alpha", "beta"), model.damping))
    return _plain(document)


def _record_table(record, file):
    """An element record as its table in the file: a beam's ``axes`` become ``y_axis``;
    a rigid body's inertia must be the (3, 3) tensor (the file's [Ixx, Iyy, Izz] is not)."""
    table = {f: getattr(record, f) for f in record.__dataclass_fields__ if f != "kind"}
    if isinstance(record, Rigid) and np.ndim(record.inertia) != 2:
        raise ModelError(file, f"must be a (3, 3) tensor, got shape {np.shape(record.inertia)}",
                         element=f"rigid {record.name!r}", key="inertia")
    if isinstance(record, Spring) and record.c is None:
        del table["c"]
    if isinstance(record, Spring):
        table["release"] = _release_names(table.pop("release"), file, record.name)
    if isinstance(record, Beam):
        del table["length"]
        axes = table.pop("axes")
        if np.shape(axes) == (3, 3):
            table["y_axis"] = np.asarray(axes)[1]
    return table


def _release_names(mask, file, name):
    """A spring record's ``release`` (None or a (6,) bool mask) as the file's list of names."""
    if mask is None:
        return []
    mask = np.asarray(mask)
    if mask.shape != (6,) or mask.dtype != bool:
        raise ModelError(file, f"must be None or a (6,) bool mask of released directions "
                               f"({', '.join(COMPONENTS)})", element=f"spring {name!r}", key="release")
    return [c for c, free in zip(COMPONENTS, mask) if free]


def _boundary_table(boundary, file):
    """``[boundary]`` as lists of fixed components from (6,) bool masks."""
    if not isinstance(boundary, dict):
        return boundary
    table = {}
    for point, mask in boundary.items():
        mask = np.asarray(mask)
        if mask.shape != (6,) or mask.dtype != bool:
            raise ModelError(file, f"must be a (6,) bool mask of fixed components "
                                   f"({', '.join(COMPONENTS)})", element="[boundary]", key=point)
        table[point] = [c for c, fixed in zip(COMPONENTS, mask) if fixed]
    return table


def _plain(value):
    """``value`` with arrays, tuples and numpy scalars turned into lists and Python scalars."""
    if type(value) in (float, str, int, bool, type(None)):  # exact types (not numpy's float64)
        return value
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, np.ndarray) and value.dtype != object:
        return value.tolist()  # the same nested lists of Python scalars, formed at once
    if isinstance(value, (list, tuple, np.ndarray)):
        return [_plain(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    return value


def _check_beam_frame(t, beam, derived, tol):
    """A beam record's ``length`` and ``axes`` are those derived from its ends and y axis."""
    if not _deviation(beam.length, derived["length"]) <= tol:
        raise t.error("length", f"must be the distance between the ends, "
                                f"{derived['length']:g} m, got {beam.length!r}")
    if not _deviation(beam.axes, derived["axes"]) <= _ORTHO_TOL:
        raise t.error("axes", "rows must be the beam's local x (from ends[0] to ends[1]), "
                              "y and z unit vectors, a right-handed frame")


def _deviation(value, expected):
    """max |value - expected| (inf if ``value`` is not numbers of the same shape; nan stays nan)."""
    if type(value) is type(expected) is float and value == expected or (
            type(value) is type(expected) is np.ndarray and value.dtype == expected.dtype == np.float64
            and value.tolist() == expected.tolist()):
        return 0.0  # equal number for number (nan never is): found without numpy's overhead
    try:
        value = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        return math.inf
    return np.abs(value - expected).max() if value.shape == np.shape(expected) else math.inf


def _frozen(array):
    """A read-only copy of ``array``."""
    array = np.array(array)
    array.flags.writeable = False
    return array


def _read_only(value):
    """``value`` if it is a read-only array already, else a read-only copy of it."""
    return value if isinstance(value, np.ndarray) and not value.flags.writeable else _frozen(value)


class FrozenDict(dict):
    """A dict that refuses every change: a :class:`Model`'s ``points`` and ``boundary``.

    A model's solve is compiled once per model object
    (:mod:`linmstmm.compiled_model`), so a model changed in place would be
    answered for as it was; a changed model is a new one
    (:func:`linmstmm.parameters.with_values`, :func:`dataclasses.replace`).
    """

    def _refuse(self, *args, **kwargs):
        raise TypeError("a Model cannot be changed in place: build a new one "
                        "(linmstmm.parameters.with_values or dataclasses.replace)")

    __setitem__ = __delitem__ = __ior__ = clear = pop = popitem = setdefault = update = _refuse

    def __reduce__(self):
        """Pickled as a plain dict's items, rebuilt without a call to ``__setitem__``."""
        return type(self), (dict(self),)


def _freeze(model) -> None:
    """Make ``model`` unchangeable in place: its element lists tuples, its ``points`` and
    ``boundary`` :class:`FrozenDict` of read-only arrays, and every array of its
    records read-only (a copy where the caller's array was writeable)."""
    for name in ("rigids", "beams", "springs"):
        object.__setattr__(model, name, tuple(getattr(model, name)))
    for name in ("points", "boundary"):
        object.__setattr__(model, name, _frozen_table(getattr(model, name)))
    for record in model.elements:
        _freeze_record(record)


def _frozen_table(table: dict) -> FrozenDict:
    """``table`` (name -> array) as a :class:`FrozenDict` of read-only arrays."""
    return FrozenDict({key: _read_only(value) for key, value in table.items()})


def _freeze_record(record) -> None:
    """Make every array of an element record read-only (a copy where it was writeable)."""
    for name in record.__dataclass_fields__:
        value = getattr(record, name)
        if isinstance(value, np.ndarray) and value.flags.writeable:
            object.__setattr__(record, name, _frozen(value))


def _build(cls, fields):
    """``cls(**fields)`` with every ndarray field made read-only."""
    return cls(**{k: _frozen(v) if isinstance(v, np.ndarray) else v for k, v in fields.items()})
