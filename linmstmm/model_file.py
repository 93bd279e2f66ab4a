"""The model file: reading the TOML document and validating every key (the
checks a :class:`~linmstmm.model.Model` built in code runs too), with
:class:`ModelError` naming file, element and key.

Examples: ``models/*.toml``; the full reference is
docs/model-format.md. The keys of a file, in brief:

* top level: ``name`` (non-empty string), ``description`` (optional string);
* ``[points]``: ``point = [x, y, z]``, m; every point is used by an element;
* ``[[rigid]]``: ``name``, ``ports`` (point names), ``mass`` kg, ``com``
  [x, y, z] m, ``inertia`` kg m^2 about the mass centre, inertial axes:
  [Ixx, Iyy, Izz] or a symmetric 3x3 array whose principal moments keep the
  triangle inequality of a real body;
* ``[[beam]]``: ``name``, ``ends`` (two points), ``E``, ``G`` Pa, ``rho``
  kg/m^3 (0 = massless), ``A`` m^2, ``Iy``, ``Iz``, ``J`` m^4; optional ``Ip``
  m^4 (default Iy + Iz), ``y_axis`` [x, y, z] (the section's local y,
  projected normal to the beam; default e_Z x local x, e_Y for a vertical
  beam), ``axial`` and ``torsion`` (false = rigid in that deformation);
* ``[[spring]]``: ``name``, ``ends`` (two coinciding points), ``k`` (6
  stiffnesses, N/m and N m/rad, ``inf`` = rigid, 0 exactly where released);
  optional ``axes`` (3x3, rows = local x, y, z), ``c`` (6 dashpots, N s/m
  and N m s/rad) and ``release`` (a list drawn from x, y, z, rx, ry, rz: the
  directions the joint leaves free, no force or moment there);
* ``[boundary]``: ``point = "free" | "fixed" | "pinned"`` or a list drawn
  from x, y, z, rx, ry, rz (the fixed components);
* the elements form one connected structure: each reached from every other
  through shared points (a boundary condition joins nothing);
* ``[damping]``: ``alpha`` 1/s, ``beta`` s of C = alpha M + beta K (each
  optional, default 0).

Units are SI throughout (m, kg, s, N, rad).
"""
from __future__ import annotations

import difflib
import math
import tomllib

import numpy as np

from linmstmm.connected import unreached
from linmstmm.geometry import length_tolerance, local_axes, norm3

#: Names of the six displacement components, in state-vector order.
COMPONENTS = ("x", "y", "z", "rx", "ry", "rz")


class ModelError(ValueError):
    """A model file that breaks the contract.

    ``str(error)`` is the one line shown to the user: file, element, key and
    what is wrong, e.g. ``model.toml: spring 'k1': key 'k': k[2] must be > 0``.
    """

    def __init__(self, file, message, element=None, key=None):
        self.file = str(file)
        self.element = element
        self.key = key
        self.message = message
        parts = [self.file]
        if element is not None:
            parts.append(element)
        if key is not None:
            parts.append(f"key '{key}'")
        super().__init__(": ".join(parts + [message]))


#: Spring axes: max |R R^T - I|; inertia: max asymmetry relative to max |I_ij|.
_ORTHO_TOL = 1e-9
#: Inertia eigenvalues must be >= -_PSD_TOL * max |I_ij|.
_PSD_TOL = 1e-12
#: Principal moments must keep I3 <= I1 + I2 within this fraction of the trace.
_TRIANGLE_TOL = 1e-9
_REQUIRED = object()
_BOUNDARY_WORDS = {"free": (), "fixed": COMPONENTS, "pinned": ("x", "y", "z")}


def _read_toml(path, file):
    """The parsed TOML document; every read or syntax failure is a ModelError."""
    try:
        with open(path, "rb") as stream:
            return tomllib.load(stream)
    except OSError as error:
        raise ModelError(file, f"cannot read model file: {error.strerror or error}") from error
    except UnicodeDecodeError as error:
        raise ModelError(file, f"not UTF-8 text: {error.reason} at byte {error.start}") from error
    except tomllib.TOMLDecodeError as error:
        hint = ""
        if str(error).startswith("Cannot overwrite a value"):
            hint = " (a key given twice, e.g. a duplicate point name)"
        raise ModelError(file, f"invalid TOML: {error}{hint}") from error
    except RecursionError as error:
        raise ModelError(file, "invalid TOML: arrays or tables nested too deeply "
                               "for the TOML reader") from error


def _describe(value):
    """Short TOML-flavoured description of a value for messages."""
    if isinstance(value, bool):
        return f"boolean {str(value).lower()}"
    if isinstance(value, str):
        return f"string {value!r}"
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, list):
        return f"array of length {len(value)}"
    if isinstance(value, dict):
        return "table"
    return type(value).__name__


def _did_you_mean(name, choices):
    """' (did you mean 'x'?)' for the closest of ``choices``, or ''."""
    close = difflib.get_close_matches(name, list(choices), n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""


class _Table:
    """One TOML table under validation; knows the file and element for messages."""

    def __init__(self, file, table, element=None):
        self.file = file
        self.table = table
        self.element = element

    def __contains__(self, key):
        return key in self.table

    def error(self, key, message):
        """A ModelError about ``key`` of this table."""
        return ModelError(self.file, message, element=self.element, key=key)

    def check_keys(self, required, optional=()):
        """No unknown keys (typo protection), then no missing required ones."""
        allowed = (*required, *optional)
        for key in self.table:
            if key not in allowed:
                raise self.error(key, f"unknown key{_did_you_mean(key, allowed)}; "
                                      f"allowed keys: {', '.join(allowed)}")
        for key in required:
            if key not in self.table:
                raise self.error(key, "missing required key")

    def string(self, key, default=_REQUIRED, nonempty=False):
        """A string value (``default`` if absent and not required)."""
        if key not in self.table and default is not _REQUIRED:
            return default
        value = self.table[key]
        if not isinstance(value, str) or (nonempty and not value):
            kind = "a non-empty string" if nonempty else "a string"
            raise self.error(key, f"must be {kind}, got {_describe(value)}")
        return value

    def boolean(self, key, default):
        """A boolean value, ``default`` if absent."""
        value = self.table.get(key, default)
        if not isinstance(value, bool):
            raise self.error(key, f"must be true or false, got {_describe(value)}")
        return value

    def number(self, key, sign=None, default=_REQUIRED):
        """A finite number as float (``default`` if absent and not required)."""
        if key not in self.table and default is not _REQUIRED:
            return default
        return self._float(key, self.table[key], sign, allow_inf=False)

    def vector(self, key, n, sign=None, allow_inf=False):
        """An array of ``n`` numbers as a float ndarray."""
        value = self.table[key]
        if not isinstance(value, list) or len(value) != n:
            raise self.error(key, f"must be an array of {n} numbers, got {_describe(value)}")
        return np.array([self._float(key, v, sign, allow_inf, (i,)) for i, v in enumerate(value)])

    def matrix(self, key, form):
        """A 3x3 nested array of finite numbers as a float ndarray; ``form`` names what is expected."""
        value = self.table[key]
        if not (isinstance(value, list) and len(value) == 3
                and all(isinstance(row, list) and len(row) == 3 for row in value)):
            raise self.error(key, f"must be {form}, got {_describe(value)}")
        return np.array([[self._float(key, v, None, False, (i, j)) for j, v in enumerate(row)]
                         for i, row in enumerate(value)])

    def point_names(self, key, points, count=None):
        """A tuple of known point names: exactly ``count`` of them, or one or more."""
        value = self.table[key]
        if not isinstance(value, list) or not value or (count and len(value) != count):
            form = f"an array of {count} point names" if count else "a non-empty array of point names"
            raise self.error(key, f"must be {form}, got {_describe(value)}")
        for i, name in enumerate(value):
            if not isinstance(name, str):
                raise self.error(key, f"{key}[{i}] must be a point name, got {_describe(name)}")
            if name not in points:
                raise self.error(key, f"unknown point {name!r}{_did_you_mean(name, points)}")
        return tuple(value)

    def section(self, key):
        """The sub-table ``[key]`` (empty if absent), labelled ``[key]``."""
        value = self.table.get(key, {})
        if not isinstance(value, dict):
            raise self.error(key, f"must be a table [{key}], got {_describe(value)}")
        return _Table(self.file, value, f"[{key}]")

    def array_of_tables(self, key):
        """The list of tables ``[[key]]`` (empty if absent)."""
        value = self.table.get(key, [])
        if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
            raise self.error(key, f"must be an array of tables [[{key}]], got {_describe(value)}")
        return value

    def _float(self, key, value, sign, allow_inf, index=()):  # index: its place in an array
        if type(value) is not float:
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise self.error(key, f"{_label(key, index)} must be a number, got {_describe(value)}")
            value = float(value)
        if not math.isfinite(value) and (math.isnan(value) or not allow_inf):
            raise self.error(key, f"{_label(key, index)} must be finite, got {value}")
        if sign is not None and (sign == "> 0" and not value > 0 or sign == ">= 0" and not value >= 0):
            raise self.error(key, f"{_label(key, index)} must be {sign}, got {value:g}")
        return value


def _label(key, index):
    """``key`` with the array indices ``index``, as messages name a number: ``k[2]``."""
    return key + "".join(f"[{i}]" for i in index)


def _validate(data, file):
    """Check the whole document; return plain constructor fields for every record."""
    top = _Table(file, data)
    top.check_keys(("name", "points"),
                   ("description", "rigid", "beam", "spring", "boundary", "damping"))
    name = top.string("name", nonempty=True)
    description = top.string("description", default="")
    points_table = top.section("points")
    points = {p: points_table.vector(p, 3) for p in points_table.table}
    tol = length_tolerance(points)

    elements = {"rigid": [], "beam": [], "spring": []}
    owners = {}
    for kind, check in ELEMENT_CHECKS.items():
        for index, table in enumerate(top.array_of_tables(kind)):
            element = _element_table(file, kind, index, table)
            fields = check(element, points, tol)
            if fields["name"] in owners:
                raise element.error("name", f"duplicate element name {fields['name']!r}, "
                                            f"already used by {owners[fields['name']]}")
            owners[fields["name"]] = element.element
            elements[kind].append(fields)

    boundary = _check_boundary(top.section("boundary"), points)
    damping = _check_damping(top.section("damping")) if "damping" in top else None

    if not any(elements.values()):
        raise ModelError(file, "model has no elements: give at least one [[rigid]], "
                               "[[beam]] or [[spring]]")
    used = {p for f in elements["rigid"] for p in f["ports"]}
    used |= {p for kind in ("beam", "spring") for f in elements[kind] for p in f["ends"]}
    for point in points:
        if point not in used:
            raise points_table.error(point, "point is not used by any element")
    _check_connected(file, elements, owners)

    check_mass(file, [f["mass"] for f in elements["rigid"]],
               [f["rho"] * f["A"] * f["length"] for f in elements["beam"]])
    return {"name": name, "description": description, "points": points,
            "rigids": elements["rigid"], "beams": elements["beam"],
            "springs": elements["spring"], "boundary": boundary, "damping": damping}


def check_mass(file, rigid_masses, beam_masses):
    """ModelError unless the model has mass: rigid bodies' masses and beams' ρ A L, kg."""
    if not sum(rigid_masses) + sum(beam_masses) > 0:
        raise ModelError(file, "model has no mass: every rigid body has mass 0 and every beam has rho = 0")


def _check_connected(file, elements, labels):
    """ModelError unless the elements form one structure (:func:`linmstmm.connected.unreached`).

    elements : kind -> list of constructor fields; labels : element name -> "kind 'name'".
    """
    joined = [(f["name"], f["ports"] if kind == "rigid" else f["ends"])
              for kind in ("rigid", "beam", "spring") for f in elements[kind]]
    apart = unreached(joined)
    if apart:
        name, ends = apart[0]
        raise ModelError(file, f"not connected to {labels[joined[0][0]]}: no chain of elements joins its points "
                               f"{', '.join(ends)} to it ({len(apart)} of {len(joined)} elements apart); a model is "
                               f"one connected structure (a boundary condition joins nothing): give each part its "
                               f"own model", element=labels[name],
                         key="ports" if labels[name].startswith("rigid") else "ends")


def _element_table(file, kind, index, table):
    """The element's table, labelled "kind 'name'" (or "kind #n" while the name is unusable)."""
    name = table.get("name")
    label = f"{kind} {name!r}" if isinstance(name, str) and name else f"{kind} #{index + 1}"
    return _Table(file, table, label)


def _check_rigid(t, points, tol):
    """Fields of a Rigid."""
    t.check_keys(("name", "ports", "mass", "com", "inertia"))
    name = t.string("name", nonempty=True)
    ports = t.point_names("ports", points)
    for i, port in enumerate(ports):
        if port in ports[:i]:
            raise t.error("ports", f"point {port!r} is listed twice")
    return {"name": name, "ports": ports, "mass": t.number("mass", ">= 0"),
            "com": t.vector("com", 3), "inertia": _check_inertia(t)}


def _check_inertia(t):
    """(3, 3) inertia tensor from [Ixx, Iyy, Izz] or a symmetric 3x3 array, kg m^2,
    whose principal moments are those of a real body."""
    value = t.table["inertia"]
    if isinstance(value, list) and len(value) == 3 and not any(isinstance(v, list) for v in value):
        tensor = np.diag(t.vector("inertia", 3, ">= 0"))
        return _check_principal_moments(t, tensor, np.linalg.eigvalsh(tensor))
    tensor = t.matrix("inertia", "[Ixx, Iyy, Izz] or a 3x3 array of arrays")
    scale = np.abs(tensor).max()
    asymmetry = np.abs(tensor - tensor.T)
    if asymmetry.max() > _ORTHO_TOL * scale:
        i, j = np.unravel_index(asymmetry.argmax(), asymmetry.shape)
        raise t.error("inertia", f"tensor is not symmetric: inertia[{i}][{j}] = {tensor[i, j]:g} "
                                 f"but inertia[{j}][{i}] = {tensor[j, i]:g}")
    tensor = (tensor + tensor.T) / 2
    moments = np.linalg.eigvalsh(tensor)
    if moments[0] < -_PSD_TOL * scale:
        raise t.error("inertia", f"tensor is not positive semidefinite "
                                 f"(smallest eigenvalue {moments[0]:g})")
    return _check_principal_moments(t, tensor, moments)


def _check_principal_moments(t, tensor, moments):
    """``tensor`` if its principal moments (``moments``, ascending) keep I3 <= I1 + I2 (every
    real body does: equality for a flat plate); the tolerance is relative to the trace."""
    low, middle, high = moments
    if high - (low + middle) > _TRIANGLE_TOL * (low + middle + high):
        raise t.error("inertia", f"principal moments {low:g}, {middle:g}, {high:g} kg m^2 break "
                                 f"the triangle inequality ({high:g} > {low:g} + {middle:g}): "
                                 f"no real body has them")
    return tensor


def _check_ends(t, points):
    """The two end point names (which must differ) and their positions."""
    ends = t.point_names("ends", points, count=2)
    if ends[0] == ends[1]:
        raise t.error("ends", f"both ends are point {ends[0]!r}: zero length")
    return ends, points[ends[0]], points[ends[1]]


def _check_spring(t, points, tol):
    """Fields of a Spring."""
    t.check_keys(("name", "ends", "k"), ("axes", "c", "release"))
    name = t.string("name", nonempty=True)
    ends = _check_ends(t, points)[0]
    _check_gap(t, ends, points, tol)
    release = _check_release(t)
    k = _check_joint_stiffness(t, release)
    axes = _check_rotation(t, "axes") if "axes" in t else np.eye(3)
    c = t.vector("c", 6, ">= 0") if "c" in t else None
    return {"name": name, "ends": ends, "k": k, "axes": axes, "c": c,
            "release": release if release.any() else None}


def _check_gap(t, ends, points, tol):
    """ModelError unless a spring's ends (two point names) coincide within ``tol``, m."""
    gap = norm3(points[ends[1]] - points[ends[0]])
    if gap > tol:
        raise t.error("ends", f"points {ends[0]!r} and {ends[1]!r} do not coincide "
                              f"(distance {gap:g} m); a spring has no length")


def _check_release(t):
    """(6,) bool mask of the directions listed in ``release`` (distinct, not all six)."""
    value = t.table.get("release", [])
    if not isinstance(value, list):
        raise t.error("release", f"must be a list drawn from {', '.join(COMPONENTS)}, "
                                 f"got {_describe(value)}")
    for i, component in enumerate(value):
        if component not in COMPONENTS:
            raise t.error("release", f"release[{i}] = {_describe(component)} is not one of "
                                     f"{', '.join(COMPONENTS)}")
        if component in value[:i]:
            raise t.error("release", f"component {component!r} is listed twice")
    if len(value) == 6:
        raise t.error("release", "all six directions are released: the spring joins nothing; "
                                 "remove it")
    return np.array([c in value for c in COMPONENTS])


def _check_joint_stiffness(t, release):
    """``k``: > 0 (``inf`` allowed) in every direction kept, exactly 0 in every released one.

    A zero stiffness outside ``release`` is refused rather than read as a
    release: it may as well be a slip of the pen, and the file should say
    which it means.
    """
    k = t.vector("k", 6, allow_inf=True)
    for i, (value, free) in enumerate(zip(k, release)):
        if free and value != 0:
            raise t.error("k", f"k[{i}] = {value:g} but {COMPONENTS[i]!r} is released: a released "
                               f"direction has no stiffness, give 0 (or leave it out of 'release')")
        if not free and value == 0:
            raise t.error("k", f"k[{i}] must be > 0, got 0; to leave direction {COMPONENTS[i]!r} "
                               f"free (a joint), list it in 'release' as well")
        if not free and value < 0:
            raise t.error("k", f"k[{i}] must be > 0, got {value:g}")
    return k


def _check_rotation(t, key):
    """A right-handed orthonormal 3x3 array (rows = local x, y, z)."""
    axes = t.matrix(key, "a 3x3 array of arrays (rows = local x, y, z unit vectors)")
    error = np.abs(axes @ axes.T - np.eye(3)).max()
    if error > _ORTHO_TOL:
        raise t.error(key, f"rows must be orthonormal unit vectors (max |R R^T - I| = {error:.3g})")
    if np.linalg.det(axes) < 0:
        raise t.error(key, "rows must form a right-handed frame (determinant is -1)")
    return axes


def _check_beam(t, points, tol):
    """Fields of a Beam."""
    t.check_keys(("name", "ends", "E", "G", "rho", "A", "Iy", "Iz", "J"),
                 ("Ip", "y_axis", "axial", "torsion"))
    name = t.string("name", nonempty=True)
    ends, a, b = _check_ends(t, points)
    along = b - a
    length = norm3(along)
    if length <= tol:
        raise t.error("ends", f"zero length: points {ends[0]!r} and {ends[1]!r} coincide")
    fields = {"name": name, "ends": ends, "length": length}
    fields.update({key: t.number(key, "> 0") for key in ("E", "G")})
    fields["rho"] = t.number("rho", ">= 0")
    fields.update({key: t.number(key, "> 0") for key in ("A", "Iy", "Iz", "J")})
    fields["Ip"] = t.number("Ip", "> 0", default=fields["Iy"] + fields["Iz"])
    fields["axes"] = _beam_axes(t, along / length)
    fields["axial"] = t.boolean("axial", True)
    fields["torsion"] = t.boolean("torsion", True)
    return fields


def _beam_axes(t, x):
    """Rows local x, y, z (:func:`linmstmm.geometry.local_axes`), from the beam's ``y_axis`` if given."""
    try:
        return local_axes(x, t.vector("y_axis", 3) if "y_axis" in t else None)
    except ValueError as error:
        raise t.error("y_axis", str(error)) from None


def _check_boundary(t, points):
    """point -> (6,) bool mask of fixed components; free points are left out."""
    masks = {}
    for point, value in t.table.items():
        if point not in points:
            raise t.error(point, f"unknown point {point!r}{_did_you_mean(point, points)}")
        if isinstance(value, str):
            if value not in _BOUNDARY_WORDS:
                raise t.error(point, f"unknown condition {value!r}; use \"free\", \"fixed\", "
                                     f"\"pinned\" or a list drawn from {', '.join(COMPONENTS)}")
            fixed = _BOUNDARY_WORDS[value]
        elif isinstance(value, list):
            for i, component in enumerate(value):
                if component not in COMPONENTS:
                    raise t.error(point, f"{point}[{i}] = {_describe(component)} is not one of "
                                         f"{', '.join(COMPONENTS)}")
                if component in value[:i]:
                    raise t.error(point, f"component {component!r} is listed twice")
            fixed = value
        else:
            raise t.error(point, f"must be \"free\", \"fixed\", \"pinned\" or a list of "
                                 f"components, got {_describe(value)}")
        mask = np.array([c in fixed for c in COMPONENTS])
        if mask.any():
            masks[point] = mask
    return masks


def _check_damping(t):
    """(alpha, beta), each >= 0, missing ones 0."""
    t.check_keys((), ("alpha", "beta"))
    return (t.number("alpha", ">= 0", default=0.0), t.number("beta", ">= 0", default=0.0))


#: Element kind in the file -> the check of one of its tables, (table, points, tol) -> fields.
ELEMENT_CHECKS = {"rigid": _check_rigid, "beam": _check_beam, "spring": _check_spring}
