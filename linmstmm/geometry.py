"""The geometry a model's checks and edits read: the distance within which two of its
points coincide, the length and cross product of 3-vectors, and a beam's local axes.

Lengths and cross products are formed in numpy's own arithmetic, operation for
operation, so every result is the one numpy gives bit for bit
(tests/test_vector_arithmetic.py checks it over the whole float64 range),
without numpy's per-call overhead: a model's checks and edits form a few dozen
of them per model, where numpy.linalg.norm and numpy.cross cost microseconds
each in argument handling.
"""
from __future__ import annotations

import math

import numpy as np

#: Spring ends coincide / a beam has length: relative to the model's size ...
_REL_TOL = 1e-9
#: ... with this absolute floor, m.
_ABS_TOL = 1e-12
#: A direction whose part normal to a beam's axis is this small (relative) is parallel to it.
PARALLEL_TOL = 1e-9
_E_Y = np.array([0.0, 1.0, 0.0])
_E_Z = np.array([0.0, 0.0, 1.0])


def length_tolerance(points: dict) -> float:
    """Distance below which two points of a model coincide.

    Parameters
    ----------
    points : dict of str to numpy.ndarray
        Point name -> (3,) position, m.

    Returns
    -------
    float
        m: 1e-9 of the diagonal of the points' bounding box, at least 1e-12.
    """
    if not points:
        return _ABS_TOL
    coords = np.array(list(points.values()))
    size = norm3(coords.max(axis=0) - coords.min(axis=0))
    return max(_REL_TOL * size, _ABS_TOL)


def norm3(vector: np.ndarray) -> float:
    """Euclidean length of a vector, as numpy.linalg.norm finds it.

    Parameters
    ----------
    vector : numpy.ndarray, shape (3,)
        The vector (any unit).

    Returns
    -------
    float
        Its length, same unit: for float64 sqrt(vector · vector) from the dot
        product numpy.linalg.norm forms (``vector.dot(vector)``) and a correctly
        rounded square root; any other dtype through numpy.linalg.norm itself.
    """
    if vector.dtype != np.float64:
        return float(np.linalg.norm(vector))
    return math.sqrt(vector.dot(vector))


def cross3(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross product of two vectors, as numpy.cross forms it.

    Parameters
    ----------
    a, b : numpy.ndarray of float, shape (3,)
        The vectors, one of them float64 at least (numpy.cross then works in float64).

    Returns
    -------
    numpy.ndarray of float64, shape (3,)
        a × b: per component a product minus a product, each operation rounded
        once, as numpy.cross computes them (here in Python floats).
    """
    a0, a1, a2 = a.tolist()
    b0, b1, b2 = b.tolist()
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def cross_rows(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross product of each row of ``a`` with ``b``, as numpy.cross forms it (the same
    numbers, without its axis handling: 0.2 ms a call).

    Parameters
    ----------
    a : numpy.ndarray of float, shape (..., 3)
        The vectors on the left.
    b : numpy.ndarray of float, shape (3,) or broadcasting with ``a``
        The vector(s) on the right.

    Returns
    -------
    numpy.ndarray of float64, shape (..., 3)
        a × b row by row: per component a product minus a product, as :func:`cross3`.
    """
    return np.stack([a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1], a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
                     a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]], axis=-1)


def local_axes(x: np.ndarray, y_axis=None) -> np.ndarray:
    """A beam's local axes by the model format's rule (``y_axis`` of a beam, docs/model-format.md).

    Parameters
    ----------
    x : numpy.ndarray of float64, shape (3,)
        Unit vector along the beam (local x), inertial frame.
    y_axis : array_like, shape (3,), optional
        The direction local y is to take, made normal to x (any length, any unit).
        Default e_Z × x, or e_Y made normal to x where x is vertical.

    Returns
    -------
    numpy.ndarray, shape (3, 3)
        Rows: local x, y, z unit vectors (right-handed).

    Raises
    ------
    ValueError
        Where ``y_axis`` is zero or parallel to x (its part normal to x at most
        PARALLEL_TOL of its length).
    """
    if y_axis is not None:
        given = np.asarray(y_axis, float)
        size = norm3(given)
        y = given - (given @ x) * x
        if size == 0 or norm3(y) <= PARALLEL_TOL * size:
            raise ValueError(f"{given.tolist()} is zero or parallel to the beam axis")
    else:
        y = cross3(_E_Z, x)
        if norm3(y) <= PARALLEL_TOL:
            y = _E_Y - (_E_Y @ x) * x
    y = y / norm3(y)
    return np.array([x, y, cross3(x, y)])
