"""One set of elementwise functions for the three number types the solver uses.

* float64 arrays: the fast path over a stack of real frequencies;
* complex128 arrays: complex frequencies (the counting contour);
* object arrays of ``mpmath.mpf``/``mpc``: the arbitrary-precision path.

The element modules call these instead of ``np.cos`` etc. so the same code
serves all three. mpmath is imported by the branches that meet its numbers
(which exist only once it is loaded): a float64 solve starts without it.
"""
from __future__ import annotations

import functools
import math

import numpy as np


def is_mp(x) -> bool:
    """True for an object array (mpmath numbers)."""
    return isinstance(x, np.ndarray) and x.dtype == object


def frequencies(omega) -> np.ndarray:
    """``omega`` as a 1-D array, keeping its number type (float, complex or mpmath)."""
    omega = np.atleast_1d(np.asarray(omega))
    if omega.dtype.kind in "iub":
        omega = omega.astype(float)
    return omega


def numbers(x, exact: bool = False) -> np.ndarray:
    """``x`` as a float64 array, or with ``exact`` as mpmath numbers (each float
    converted exactly), so that quantities derived from model data (1/k, lever
    arms, m·r) are formed at the working precision of the mpmath path."""
    x = np.asarray(x, dtype=float)
    if not exact:
        return x
    import mpmath

    return np.vectorize(mpmath.mpf, otypes=[object])(x)


def number_type(*arrays):
    """float64, or object if any of ``arrays`` holds mpmath numbers."""
    return object if any(is_mp(np.asarray(a)) for a in arrays) else np.float64


def result_dtype(omega):
    """dtype of matrices built from ``omega``: float64, complex128 or object."""
    return object if is_mp(omega) else np.result_type(omega, np.float64)


@functools.cache
def _mp_function(name: str):
    """mpmath's function ``name`` elementwise over an object array."""
    import mpmath

    return np.frompyfunc(getattr(mpmath, name), 1, 1)


def _elementwise(name):
    float_function = getattr(np, name)

    def apply(x):
        return _mp_function(name)(x) if is_mp(x) else float_function(x)

    apply.__name__ = name
    apply.__doc__ = f"Elementwise {name} for float, complex or mpmath arrays."
    return apply


cos, sin, cosh, sinh, sqrt = (_elementwise(name) for name in ("cos", "sin", "cosh", "sinh", "sqrt"))


def magnitude(x) -> np.ndarray:
    """|x| as float64 (for branch decisions only)."""
    return np.abs(x.astype(complex)) if is_mp(x) else np.abs(x)


def size_estimate(x: np.ndarray) -> np.ndarray:
    """|Re x| + |Im x| of a float or complex array: within √2 of |x| and cheaper,
    for scalings and growth tests."""
    return np.abs(x.real) + np.abs(x.imag) if np.iscomplexobj(x) else np.abs(x)


def sin_over(x):
    """sin(x)/x with the value 1 at 0."""
    if is_mp(x):
        return _mp_function("sinc")(x)
    return np.sinc(x / np.pi)


def power_of_two_scale(magnitude):
    """1 / (nearest power of two of ``magnitude``), 1 where it is 0: scaling by it is exact."""
    safe = np.where(magnitude > 0, magnitude, 1.0)
    return np.exp2(-np.round(np.log2(safe)))


def scale_into_half_one(magnitude: float) -> float:
    """The power of two that takes ``magnitude`` (one positive finite float) into [1/2, 1):
    1 / (the least power of two above it), from its binary exponent, so that scaling by it
    is exact. :func:`power_of_two_scale` rounds to the nearest power of two instead."""
    return math.ldexp(1.0, -math.frexp(magnitude)[1])


def zeros_like_stack(omega, shape) -> np.ndarray:
    """Zeros of shape ``(len(omega),) + shape`` in the number type of ``omega``."""
    dtype = result_dtype(omega)
    out = np.zeros((omega.size,) + tuple(shape), dtype=dtype)
    if dtype == object:
        import mpmath

        out[...] = mpmath.mpf(0)
    return out


def constant_times(constant: np.ndarray, stack: np.ndarray) -> np.ndarray:
    """``constant @ stack`` for a matrix (r, c), float or mpmath numbers, and a stack (n, c, k).

    For an mpmath (object) stack only the non-zero entries of ``constant``
    multiply, and ±1 without a product: most entries of a rigid body's,
    spring's or junction's matrix are 0 or ±1, and a dense object matmul
    spent three quarters of an mpmath evaluation of Ū_all converting them.
    """
    if not is_mp(stack):
        return constant @ stack
    import mpmath

    out = np.empty((stack.shape[0], constant.shape[0], stack.shape[2]), dtype=object)
    for row, entries in enumerate(constant):
        total = np.full((stack.shape[0], stack.shape[2]), mpmath.mpf(0), dtype=object)
        for column in np.flatnonzero(entries):
            value = entries[column]
            part = stack[:, column, :]
            total = total + part if value == 1 else total - part if value == -1 else total + part * mpmath.mpf(value)
        out[:, row, :] = total
    return out
