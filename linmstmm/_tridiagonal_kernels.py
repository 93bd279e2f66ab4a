"""The lowest eigenvalues of a symmetric tridiagonal matrix to a relative accuracy asked for, in compiled code.

LAPACK's stebz (:class:`linmstmm.standard_eigen.Bisection`, its counterpart and the
test oracle: tests/test_tridiagonal_values.py) finds each eigenvalue to rounding;
a search whose coarse predictions may stand as they are (from
:data:`linmstmm.rayleigh.AS_PREDICTED_FROM` up) needs them only to a small fraction
of its rtol. :func:`lowest_values` brackets them by Sturm counts to that
accuracy, all of them in lockstep: each sweep counts at one point per eigenvalue
still wide (its bracket cut in g + 1 equal parts where g eigenvalues share it, in
two where it holds one), each count's recurrence interleaved with the others', so
that the divisions of independent counts overlap instead of waiting on each other.
On the launcher's tridiagonal form (84 unknowns), its 13 lowest to 1e-7: 29 sweeps,
0.045 ms, where stebz took 0.18 ms to rounding.

Compiled once by numba (``@njit(cache=True)``), float64 arrays and integers only.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from linmstmm._compile_notice import announce_compiles

announce_compiles()  # one line on stderr if this run compiles (linmstmm._compile_notice)

#: The smallest positive normal float64: the pivots of a Sturm count are kept at
#: least this times the largest squared off-diagonal entry away from zero, as stebz keeps them.
SAFE_MINIMUM = 2.2250738585072014e-308


@njit(cache=True)
def lowest_values(diagonal, off_diagonal, count, relative_width, out):
    """The ``count`` lowest eigenvalues of the symmetric tridiagonal T into ``out``.

    Each is the midpoint of a bracket whose two ends' Sturm counts (negative pivots
    of T − x I, as LAPACK's dlaebz counts them) hold it, narrowed until its width is
    at most ``relative_width`` times its larger end's magnitude, or 4 ε ‖T‖ (the
    accuracy of T's eigenvalues themselves; ε = 2⁻⁵²), whichever is larger. Equal
    eigenvalues come out equal: their brackets never part.

    Parameters
    ----------
    diagonal : numpy.ndarray, shape (n,)
        T's diagonal, n >= 1.
    off_diagonal : numpy.ndarray, shape (n - 1,)
        T's sub- (and super-) diagonal.
    count : int
        1 <= count <= n.
    relative_width : float
        Width of a bracket relative to its value, >= 0.
    out : numpy.ndarray, shape (count,)
        Written with the eigenvalues, ascending (non-finite where T is not finite).
    """
    n = diagonal.size
    squared = np.zeros(n)  # squared[i]: the coupling of row i to row i − 1
    low, high = diagonal[0], diagonal[0]
    largest_square = 0.0
    for i in range(n):
        above = abs(off_diagonal[i - 1]) if i > 0 else 0.0
        below = abs(off_diagonal[i]) if i < n - 1 else 0.0
        low = min(low, diagonal[i] - above - below)  # Gershgorin's interval
        high = max(high, diagonal[i] + above + below)
        if i > 0:
            squared[i] = off_diagonal[i - 1] * off_diagonal[i - 1]
            largest_square = max(largest_square, squared[i])
    if not (_finite(diagonal) and _finite(off_diagonal) and math.isfinite(low) and math.isfinite(high)):
        out[:] = np.nan
        return
    pivot_floor = SAFE_MINIMUM * max(largest_square, 1.0)
    # At least two units in the last place of any value in the brackets, so that a bracket
    # still to be cut has a cut strictly inside it (its middle one): every sweep narrows it.
    narrowest = 4.0 * 2.0 ** -52 * max(abs(low), abs(high))
    lower = np.full(count, low - narrowest)
    upper = np.full(count, high + narrowest)
    points = np.empty(count)
    pivots = np.empty(count)
    below_point = np.empty(count)
    while True:
        cuts = _cuts(lower, upper, relative_width, narrowest, points)
        if cuts == 0:
            break
        for p in range(cuts):  # Sturm counts at every cut, their recurrences interleaved
            pivots[p] = 1.0
            below_point[p] = 0.0
        for i in range(n):
            for p in range(cuts):
                pivot = diagonal[i] - points[p] - squared[i] / pivots[p]
                pivot = pivot if abs(pivot) >= pivot_floor else -pivot_floor
                pivots[p] = pivot
                below_point[p] += 1.0 if pivot < 0.0 else 0.0
        for p in range(cuts):  # every bracket a cut falls in narrows to it
            for k in range(count):
                if below_point[p] <= k:
                    lower[k] = max(lower[k], points[p])
                else:
                    upper[k] = min(upper[k], points[p])
    for k in range(count):
        out[k] = 0.5 * (lower[k] + upper[k])


@njit(cache=True)
def _finite(values):
    """Whether every entry of ``values`` is finite (min and max above pass a NaN by)."""
    for value in values:
        if not math.isfinite(value):
            return False
    return True


@njit(cache=True)
def _cuts(lower, upper, relative_width, narrowest, points):
    """The points a sweep counts at, into ``points``; returns how many. Eigenvalues
    k whose brackets (``lower[k]``, ``upper[k]``) are the same share their cuts:
    g of them cut it in g + 1 equal parts; a bracket no wider than
    ``relative_width`` times its larger end's magnitude, or ``narrowest``, is not cut."""
    count = lower.size
    cuts = 0
    k = 0
    while k < count:
        sharing = 1
        while k + sharing < count and lower[k + sharing] == lower[k] and upper[k + sharing] == upper[k]:
            sharing += 1
        width = upper[k] - lower[k]
        if width > max(relative_width * max(abs(lower[k]), abs(upper[k])), narrowest):
            step = width / (sharing + 1)
            for j in range(sharing):
                points[cuts] = lower[k] + (j + 1) * step
                cuts += 1
        k += sharing
    return cuts
