"""Richardson (Romberg) extrapolation of eigenvalues over meshes doubled each
time, with the error estimate of the last step used."""
from __future__ import annotations

import numpy as np


def _romberg(values, max_order: int = 4):
    """Richardson extrapolation of one eigenvalue over meshes h, h/2, h/4, ...

    The error is taken to expand as Σ c_k h^(2k); column q of the table
    removes h^(2q). Of the finest row, only entries whose column also has an
    entry one mesh coarser are candidates (the newest, top column is not yet
    checked); each one's error estimate is the larger of its differences from
    the entry one order lower and from that coarser entry, and the candidate
    with the smallest estimate is returned.

    Returns (value, absolute error estimate); the estimate is inf for one mesh.
    """
    previous, row = [], [values[0]]
    for j in range(1, len(values)):
        previous, row = row, [values[j]]
        for q in range(1, min(j, max_order) + 1):
            row.append(row[q - 1] + (row[q - 1] - previous[q - 1]) / (4 ** q - 1))
    best, best_error = row[0], np.inf
    for q in range(1, min(len(row), max(len(previous), 2))):
        error = abs(row[q] - row[q - 1])
        if q < len(previous):
            error = max(error, abs(row[q] - previous[q]))
        if error < best_error:
            best, best_error = row[q], error
    return best, best_error


def _extrapolate(levels):
    """Per mode of the finest level: Romberg over the meshes that have it.

    levels : list of ascending λ arrays, coarse to fine, mesh doubled each time.
    Returns extrapolated λ and their relative error estimates.
    """
    finest = levels[-1]
    lam, error = finest.copy(), np.full(len(finest), np.inf)
    for i in range(len(finest)):
        history = []
        for level in reversed(levels):
            if len(level) <= i:
                break
            history.insert(0, level[i])
        value, absolute = _romberg(history)
        lam[i], error[i] = value, absolute / abs(value)
    return lam, error
