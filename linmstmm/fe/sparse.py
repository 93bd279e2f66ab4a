"""Sparse matrices built straight from their entries, without scipy's general
conversion (most of the cost of small models' assembly)."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp


def csr_of_distinct(rows: np.ndarray, cols: np.ndarray, values: np.ndarray, shape) -> sp.csr_matrix:
    """The CSR matrix of entries at distinct positions (no (row, col) twice), indices
    sorted: the same matrix as ``scipy.sparse.csr_matrix((values, (rows, cols)))``,
    explicit zeros kept.

    Parameters
    ----------
    rows, cols : (nnz,) int positions, each pair at most once.
    values : (nnz,) float entries.
    shape : (n_rows, n_cols).

    Returns
    -------
    scipy.sparse.csr_matrix of ``shape``, canonical.

    Raises
    ------
    ValueError
        If a position is given twice.
    """
    order = np.lexsort((cols, rows))
    if np.any((np.diff(rows[order]) == 0) & (np.diff(cols[order]) == 0)):
        raise ValueError("csr_of_distinct: a (row, col) position is given twice")
    starts = np.zeros(shape[0] + 1, dtype=np.int64)
    np.cumsum(np.bincount(rows, minlength=shape[0]), out=starts[1:])
    matrix = sp.csr_matrix((np.asarray(values, float)[order], cols[order], starts), shape=shape)
    matrix.has_sorted_indices = True
    return matrix

