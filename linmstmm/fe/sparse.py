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
    position = rows.astype(np.int64) * shape[1] + cols
    order = np.argsort(position)
    position = position[order]
    if np.any(position[1:] == position[:-1]):
        raise ValueError("csr_of_distinct: a (row, col) position is given twice")
    return _csr_of_sorted(position, cols[order], np.asarray(values, float)[order], shape)


def csr_of_summed(rows: np.ndarray, cols: np.ndarray, values: np.ndarray, shape) -> sp.csr_matrix:
    """The CSR matrix scipy makes of entries that may share a position:
    ``scipy.sparse.coo_matrix((values, (rows, cols))).tocsr()``, zeros dropped.

    Where no position is given more than twice it is summed here (a sum of two is
    the same in either order); three or more are left to scipy, which sums them in
    the order its sort leaves them.

    Parameters
    ----------
    rows, cols : (nnz,) int positions. values : (nnz,) float entries.
    shape : (n_rows, n_cols).

    Returns
    -------
    scipy.sparse.csr_matrix of ``shape``, canonical.
    """
    position = rows.astype(np.int64) * shape[1] + cols
    order = np.argsort(position)
    position = position[order]
    if np.any(position[2:] == position[:-2]):
        matrix = sp.coo_matrix((values, (rows, cols)), shape=shape).tocsr()
        matrix.eliminate_zeros()
        return matrix
    values = np.asarray(values, float)[order]
    repeated = np.flatnonzero(position[1:] == position[:-1])
    sums = values.copy()
    sums[repeated] += values[repeated + 1]
    kept = np.ones(len(position), bool)
    kept[repeated + 1] = False
    kept &= sums != 0
    return _csr_of_sorted(position[kept], cols[order][kept], sums[kept], shape)


def _csr_of_sorted(position: np.ndarray, cols: np.ndarray, values: np.ndarray, shape) -> sp.csr_matrix:
    """CSR of entries at ascending distinct ``position`` = row × n_cols + col."""
    return csr_of_rows(np.searchsorted(position, np.arange(shape[0] + 1) * shape[1]), cols, values, shape)


def csr_of_rows(indptr: np.ndarray, indices: np.ndarray, data: np.ndarray, shape) -> sp.csr_matrix:
    """The scipy CSR matrix of compressed rows whose column ``indices`` ascend in each
    row, its index arrays made of the type scipy would choose (once, here).

    Parameters
    ----------
    indptr : (n_rows + 1,) int. indices : (nnz,) int. data : (nnz,) float.
    shape : (n_rows, n_cols).

    Returns
    -------
    scipy.sparse.csr_matrix, flagged as having sorted indices.
    """
    index = np.int32 if max(shape[1], len(data)) < 2 ** 31 else np.int64
    matrix = sp.csr_matrix((data, indices.astype(index, copy=False), indptr.astype(index, copy=False)), shape=shape)
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
    major = np.repeat(np.arange(n, dtype=np.int64), np.diff(matrix.indptr))
    minor = matrix.indices.astype(np.int64)
    rows, cols = (major, minor) if matrix.format == "csr" else (minor, major)
    position = np.concatenate([rows * n + cols, cols * n + rows])
    order = np.argsort(position, kind="stable")
    position = position[order]
    first = np.flatnonzero(np.diff(position, prepend=-1))
    sums = np.add.reduceat(np.concatenate([matrix.data, matrix.data])[order], first)
    kept = sums != 0
    position = position[first][kept]
    return _csr_of_sorted(position, position % n, sums[kept] * 0.5, (n, n))
