"""Names for the numeric values of a model, and models with some of them changed.

A *key* names one number of a :class:`~linmstmm.model.Model` by section,
element name and field, with indices for arrays (counted from 0):

* ``rigid.NAME.mass`` kg, ``rigid.NAME.com[i]`` m, ``rigid.NAME.inertia[i][j]``
  kg m² (both ``[i][j]`` and ``[j][i]`` are set: the tensor stays symmetric);
* ``spring.NAME.k[i]`` N/m or N m/rad, ``spring.NAME.c[i]`` (if the spring has
  dashpots), ``spring.NAME.axes[i][j]``;
* ``beam.NAME.E`` (also ``G``, ``rho``, ``A``, ``Iy``, ``Iz``, ``J``, ``Ip``), SI;
* ``points.NAME[i]`` m: one coordinate of a point; the beams that end there
  get their new length and axes (local y kept as near its old direction as
  the new axis allows, as a file's ``y_axis`` is);
* ``damping.alpha`` 1/s, ``damping.beta`` s (if the model has ``[damping]``).

Edits act on the validated model, not on its file: a beam's ``Ip`` keeps its
value when ``Iy`` or ``Iz`` changes (a file's default ``Ip = Iy + Iz`` was
resolved when the file was read). The edited model is validated again on
construction, so an edit that breaks the model contract (a negative mass, a
spring whose ends no longer coincide) raises its usual
:class:`~linmstmm.model.ModelError`.
"""
from __future__ import annotations

import dataclasses
import difflib
import re

import numpy as np

from linmstmm.model import Model, ModelError, model_file, with_numbers
from linmstmm.geometry import cross3, norm3

#: Element section of a key -> the Model attribute holding its records.
SECTIONS = {"rigid": "rigids", "spring": "springs", "beam": "beams"}
#: Numeric fields of each element kind (arrays take indices).
FIELDS = {"rigid": ("mass", "com", "inertia"), "spring": ("k", "c", "axes"),
          "beam": ("E", "G", "rho", "A", "Iy", "Iz", "J", "Ip")}
#: Old local y within this (relative) of the new beam axis: no frame follows from it.
_PARALLEL = 1e-9
_INDICES = re.compile(r"((?:\[\d+\])*)$")


@dataclasses.dataclass(frozen=True)
class Key:
    """One parsed key: ``section`` ("rigid", "spring", "beam", "points", "damping"),
    ``name`` (element or point; "" for damping), ``field`` ("" for a point) and
    ``index`` (a tuple of array indices, empty for a scalar)."""

    text: str
    section: str
    name: str
    field: str
    index: tuple[int, ...]


def parameter_keys(model: Model) -> list[str]:
    """Every key of ``model``, in model order (see the module docstring).

    Parameters
    ----------
    model : Model
        The model.

    Returns
    -------
    list of str
        The keys; ``inertia`` lists each symmetric pair once (i <= j).
    """
    keys = [f"points.{name}[{i}]" for name in model.points for i in range(3)]
    for section, attribute in SECTIONS.items():
        for record in getattr(model, attribute):
            for field in FIELDS[section]:
                value = getattr(record, field)
                if value is None:
                    continue
                shape = np.shape(value)
                indices = np.ndindex(*shape) if shape else [()]
                keys += [f"{section}.{record.name}.{field}" + "".join(f"[{i}]" for i in index)
                         for index in indices
                         if not (field == "inertia" and index[0] > index[1])]
    if model.damping is not None:
        keys += ["damping.alpha", "damping.beta"]
    return keys


def unit(key: Key) -> str:
    """The SI unit of ``key``'s value, as the column headers of ``linmstmm sweep --csv`` write it.

    Parameters
    ----------
    key : Key
        A parsed key (:func:`parse_key`).

    Returns
    -------
    str
        "kg", "m", "kg m^2", "N/m", "N m/rad", "N s/m", "N m s/rad", "Pa",
        "kg/m^3", "m^2", "m^4", "1/s", "s", or "1" for a spring's axis entry.
    """
    if key.section == "points":
        return "m"
    if key.section == "damping":
        return "1/s" if key.field == "alpha" else "s"
    if key.section == "spring":
        rotation = bool(key.index) and key.index[0] >= 3
        return {"k": "N m/rad" if rotation else "N/m", "c": "N m s/rad" if rotation else "N s/m"}.get(key.field, "1")
    return _UNITS[key.field]


#: SI unit of each rigid-body and beam field.
_UNITS = {"mass": "kg", "com": "m", "inertia": "kg m^2", "E": "Pa", "G": "Pa", "rho": "kg/m^3", "A": "m^2",
          "Iy": "m^4", "Iz": "m^4", "J": "m^4", "Ip": "m^4"}


def parse_key(model: Model, text: str) -> Key:
    """The :class:`Key` that ``text`` names in ``model``.

    Parameters
    ----------
    model : Model
        The model.
    text : str
        The key, e.g. ``spring.k1.k[2]``.

    Returns
    -------
    Key

    Raises
    ------
    ModelError
        Naming the model's file and the key, with the closest existing key,
        if ``text`` names no number of ``model``.
    """
    key = _split(text)
    if key is None or not _exists(model, key):
        raise unknown_key(model, text)
    return key


def unknown_key(model: Model, text: str) -> ModelError:
    """The ModelError for a key that names no number of ``model``, with the closest key
    (one that differs in case only, else the nearest spelling).

    Parameters
    ----------
    model : Model
        The model.
    text : str
        The key that was asked for.

    Returns
    -------
    ModelError
        The error (not raised), its key ``text``.
    """
    keys = parameter_keys(model)
    close = [k for k in keys if k.lower() == text.lower()] or difflib.get_close_matches(text, keys, n=1, cutoff=0.5)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    return ModelError(model_file(model), f"names no number of the model{hint}; keys look like "
                                    "rigid.NAME.mass, spring.NAME.k[2], beam.NAME.E, points.NAME[0]",
                      key=text)


def get_value(model: Model, key: Key) -> float:
    """The current value of ``key`` in ``model``.

    Parameters
    ----------
    model : Model
        The model.
    key : Key
        A key of ``model`` (:func:`parse_key`).

    Returns
    -------
    float
        The value, in the key's SI unit (:func:`unit`).
    """
    if key.section == "points":
        return float(model.points[key.name][key.index])
    if key.section == "damping":
        return float(model.damping[("alpha", "beta").index(key.field)])
    value = getattr(model.element(key.name), key.field)
    return float(np.asarray(value)[key.index]) if key.index else float(value)


def with_values(model: Model, edits: dict[Key, float]) -> Model:
    """A validated copy of ``model`` with each key of ``edits`` set to its value.

    Parameters
    ----------
    model : Model
        The model.
    edits : dict of Key to float
        The new values, SI.

    Returns
    -------
    Model

    Raises
    ------
    ModelError
        (file, element, key) if the edited model breaks the model contract,
        as :func:`linmstmm.model.load_model` would for that file.
    """
    return with_numbers(model, *_edited_numbers(model, edits))


def _edited_numbers(model: Model, edits: dict[Key, float]) -> tuple[dict, dict, tuple | None]:
    """(points, changed records by name, damping) of ``model`` with ``edits``, as
    :func:`linmstmm.model.with_numbers` takes them (unchecked)."""
    points = dict(model.points)
    original = {record.name: record for record in model.elements}
    records = dict(original)
    damping = model.damping
    arrays, fields = {}, {}  # (point) or (element, field) -> [(index, value)]; element -> {field: value}
    for key, value in edits.items():
        value = float(value)
        if key.section == "points":
            arrays.setdefault((key.name,), []).append((key.index, value))
        elif key.section == "damping":
            damping = tuple(value if f == key.field else v for f, v in zip(("alpha", "beta"), damping))
        elif key.index:
            arrays.setdefault((key.name, key.field), []).append((_symmetric(key), value))
        else:
            fields.setdefault(key.name, {})[key.field] = value
    for place, changes in arrays.items():  # each array copied once, its edits in their order
        if len(place) == 1:
            points[place[0]] = _replaced(points[place[0]], changes)
        else:
            fields.setdefault(place[0], {})[place[1]] = _replaced(getattr(records[place[0]], place[1]), changes)
    for name, changed in fields.items():  # each record replaced once
        records[name] = dataclasses.replace(records[name], **changed)
    moved = {name for name in points if points[name] is not model.points[name]}
    for record in model.beams:
        if moved & set(record.ends):
            records[record.name] = _beam_on(records[record.name], points)
    return points, {name: record for name, record in records.items() if record is not original[name]}, damping


def _split(text: str) -> Key | None:
    """``text`` parsed into a Key by its grammar alone (None if it has none)."""
    indices = _INDICES.search(text).group(1)
    head = text[:len(text) - len(indices)]
    index = tuple(int(i) for i in re.findall(r"\d+", indices))
    section, _, rest = head.partition(".")
    if section == "points" and rest:
        return Key(text, section, rest, "", index)
    if section == "damping" and rest in ("alpha", "beta") and not index:
        return Key(text, section, "", rest, index)
    name, _, field = rest.rpartition(".")
    if section in SECTIONS and name and field in FIELDS[section]:
        return Key(text, section, name, field, index)
    return None


def _exists(model: Model, key: Key) -> bool:
    """Whether ``key`` (grammatical) names a number of ``model``."""
    if key.section == "points":
        return key.name in model.points and len(key.index) == 1 and key.index[0] < 3
    if key.section == "damping":
        return model.damping is not None
    record = next((r for r in getattr(model, SECTIONS[key.section]) if r.name == key.name), None)
    value = None if record is None else getattr(record, key.field)
    if value is None:
        return False
    shape = np.shape(value)
    return len(key.index) == len(shape) and all(i < n for i, n in zip(key.index, shape))


def _symmetric(key: Key):
    """The array positions ``key`` sets: [i][j] and [j][i] of an inertia tensor, else its index."""
    if key.field == "inertia":
        i, j = key.index
        return ([i, j], [j, i])
    return key.index


def _replaced(array, changes) -> np.ndarray:
    """A read-only float copy of ``array`` with ``array[index] = value`` for each
    (index, value) of ``changes``, in their order."""
    array = np.array(array, dtype=float)
    for index, value in changes:
        array[index] = value
    array.flags.writeable = False
    return array


def _beam_on(beam, points):
    """``beam`` with the length and axes its (moved) end points give; local y is the old
    local y made normal to the new axis (as the loader treats a file's ``y_axis``)."""
    a, b = (np.asarray(points[p], float) for p in beam.ends)
    along = b - a
    length = norm3(along)
    x = along / length if 0 < length < np.inf else beam.axes[0]
    y = beam.axes[1] - (beam.axes[1] @ x) * x
    size_y = norm3(y)
    if not size_y > _PARALLEL:  # the model's own check names the breach
        return dataclasses.replace(beam, length=length)
    y = y / size_y
    axes = np.array([x, y, cross3(x, y)])
    axes.flags.writeable = False
    return dataclasses.replace(beam, length=length, axes=axes)
