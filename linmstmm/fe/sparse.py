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
    position = rows * shape[1] + cols
    order = np.argsort(position)
    position = position[order]
    if np.any(position[1:] == position[:-1]):
        raise ValueError("csr_of_distinct: a (row, col) position is given twice")
    starts = np.searchsorted(position, np.arange(shape[0] + 1) * shape[1])
    matrix = sp.csr_matrix((np.asarray(values, float)[order], cols[order], starts), shape=shape)
    matrix.has_sorted_indices = True
    return matrix


def symmetric_part(matrix) -> sp.csr_matrix:
    """(A + Aᵀ) / 2 of a square CSR or CSC matrix A without repeated positions, as
    canonical CSR: each entry is formed as scipy's sum forms it, (a + b) * 0.5, and
    positions where a + b is zero are dropped.

    Parameters
    ----------
    matrix : (n, n) scipy.sparse CSR or CSC matrix.

    Returns
    -------
    scipy.sparse.csr_matrix, (n, n), symmetric bit for bit.
    """
    n = matrix.shape[0]
    major = np.repeat(np.arange(n), np.diff(matrix.indptr))
    rows, cols = (major, matrix.indices) if matrix.format == "csr" else (matrix.indices, major)
    position = np.concatenate([rows * n + cols, cols * n + rows])
    order = np.argsort(position, kind="stable")
    position = position[order]
    first = np.flatnonzero(np.diff(position, prepend=-1))
    sums = np.add.reduceat(np.concatenate([matrix.data, matrix.data])[order], first)
    kept = sums != 0
    position = position[first][kept]
    return csr_of_distinct(position // n, position % n, sums[kept] * 0.5, (n, n))
