"""Modes followed by their shapes from step to step of a parameter study.

Frequencies by rank swap places where two modes veer or cross. Each step is
compared with its neighbour by the MAC of the mode shapes at the model's
points, translations in m and rotations times the model's size in m (so the
MAC does not depend on the units of length); the assignment that maximises
the sum of the MACs gives each column the mode nearest in shape to the
column's mode at the neighbour. Every column is filled: where the mode a
column followed left the lowest ``count``, one that entered takes its place,
with a MAC below SAME_MODE_MAC.
"""
from __future__ import annotations

import numpy as np

from linmstmm.model import Model

#: A column whose shape's MAC against its shape at the neighbouring step is below this
#: holds another mode there (:attr:`linmstmm.sweep.SweepResult.switched`).
SAME_MODE_MAC = 0.5


def track(shapes, previous, count: int, length: float) -> tuple[np.ndarray, np.ndarray]:
    """Columns that follow mode shapes from step to step.

    Parameters
    ----------
    shapes : list of ndarray
        Per step (m, p, 6) shapes at the points (m <= count).
    previous : list of int or None
        Per step the index of the step it is tracked from (None: ranks as they are).
    count : int
        Columns.
    length : float
        m, the model's size; rotations are weighted by it in the MAC.

    Returns
    -------
    order : ndarray
        (steps, count) int: rank of each column's mode, -1 where none.
    mac : ndarray
        (steps, count): MAC of each column against the same column at the previous step.
    """
    # here, not at the top: importing scipy.optimize costs every command 0.1 s
    from scipy.optimize import linear_sum_assignment

    steps = len(shapes)
    order = np.full((steps, count), -1, dtype=int)
    mac = np.full((steps, count), np.nan)
    vectors = [_mac_vectors(s, length) for s in shapes]
    for step, back in enumerate(previous):
        found = vectors[step].shape[0]
        if back is None:
            order[step, :found], mac[step, :found] = np.arange(found), 1.0
            continue
        columns = np.flatnonzero(order[back] >= 0)
        matrix = _mac(vectors[back][order[back, columns]], vectors[step])
        rows, ranks = linear_sum_assignment(matrix, maximize=True)
        order[step, columns[rows]] = ranks
        mac[step, columns[rows]] = matrix[rows, ranks]
        unclaimed = np.setdiff1d(np.arange(found), ranks)
        free = np.flatnonzero(order[step] < 0)[:unclaimed.size]
        order[step, free] = unclaimed[:free.size]
    return order, mac


def length_scale(model: Model) -> float:
    """The model's size, m: the diagonal of the box around its points and mass centres (1 if
    that is 0); rotations are weighted by it in the MAC (:func:`track`).

    Parameters
    ----------
    model : Model
        The model.

    Returns
    -------
    float
        m.
    """
    places = np.array([*model.points.values(), *(r.com for r in model.rigids)], dtype=float)
    size = float(np.linalg.norm(np.ptp(places, axis=0)))
    return size if size > 0 else 1.0


def _mac_vectors(shapes: np.ndarray, length: float) -> np.ndarray:
    """(m, 6 p) shape vectors: translations, and rotations times ``length`` (both m)."""
    scaled = np.concatenate([shapes[..., :3], shapes[..., 3:] * length], axis=-1)
    return scaled.reshape(scaled.shape[0], -1)


def _mac(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(n_a, n_b) MAC between the rows of ``a`` and of ``b``."""
    from linmstmm.modes import mac_matrix

    return mac_matrix(a, b) if a.size and b.size else np.zeros((a.shape[0], b.shape[0]))
