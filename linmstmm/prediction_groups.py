"""Which predictions a predicted search polishes, and which stand alone.

Shared by the search itself (:mod:`linmstmm.predicted`) and the refinement of its
predictions (:mod:`linmstmm.rayleigh`), which refines those the search polishes that
no other prediction stands close to.
"""
from __future__ import annotations

import numpy as np

#: Predictions closer than this (relative) are a cluster: a member's secant result
#: stands only where it converged to xtol (see :func:`linmstmm.predicted._secant_polished`).
CLUSTER = 1e-3
#: Predictions above the count-th are polished only within this (relative) of it;
#: the others only place the certifying count's upper end in the gap above it
#: (the coarse model is within about 1e-2 of every root it predicts).
NEAR_COUNT = 2e-2


def clusters(predictions: np.ndarray) -> list[list[int]]:
    """Indices of ``predictions`` (ascending) grouped where neighbours are within CLUSTER."""
    groups: list[list[int]] = []
    values = predictions.tolist()
    for i, omega in enumerate(values):
        if groups and omega - values[groups[-1][-1]] <= CLUSTER * omega:
            groups[-1].append(i)
        else:
            groups.append([i])
    return groups


def clustered(predictions: np.ndarray) -> list[bool]:
    """(m,): which of ``predictions`` (ascending) share a cluster (:func:`clusters`) with another."""
    return [len(group) > 1 for group in clusters(predictions) for _ in group]


def polished_up_to(predictions: np.ndarray, count: int) -> int:
    """How many of ``predictions`` (ascending, rad/s; at least ``count``) a search for the
    lowest ``count`` polishes: those up to NEAR_COUNT above the count-th (the others only
    place its certifying count's upper end)."""
    return int(np.searchsorted(predictions, predictions[count - 1] * (1 + NEAR_COUNT), side="right"))
