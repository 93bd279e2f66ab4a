"""Sparse matrices built straight from their entries, without scipy's general
conversion (most of the cost of small models' assembly): as :class:`Compressed`
arrays where only numpy reads them, as scipy CSR where scipy does."""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

#: Entries up to which :func:`compressed_of_summed` sums in numpy: 61 against 77 µs
#: for scipy's conversion at 1,300 entries, 190 against 130 µs at 6,600 (a 1,000-beam
#: chain's 1.2 million mass entries: 73 against 45 ms).
FEW_ENTRIES = 4000


class Compressed(NamedTuple):
    """A sparse matrix's stored entries in scipy's compressed layout, without a scipy
    object (the attributes a scipy CSR or CSC matrix has too).

    format : "csr" (``indptr`` runs over rows, ``indices`` are columns) or "csc".
    indptr : (n_major + 1,) int. indices : (nnz,) int. data : (nnz,) float.
    shape : (n_rows, n_cols).
    """

    format: str
    indptr: np.ndarray
    indices: np.ndarray
    data: np.ndarray
    shape: tuple


def compressed_of_distinct(rows: np.ndarray, cols: np.ndarray, values: np.ndarray, shape) -> Compressed:
    """The CSR rows of entries at distinct positions (no (row, col) twice), indices
    sorted: the matrix ``scipy.sparse.csr_matrix((values, (rows, cols)))`` stores,
    explicit zeros kept.

    Parameters
    ----------
    rows, cols : (nnz,) int positions, each pair at most once.
    values : (nnz,) float entries.
    shape : (n_rows, n_cols).

    Returns
    -------
    Compressed, CSR of ``shape``, canonical.

    Raises
    ------
    ValueError
        If a position is given twice.
    """
    position = rows.astype(np.int64) * shape[1] + cols
    order = np.argsort(position)
    position = position[order]
    if np.any(position[1:] == position[:-1]):
        raise ValueError("compressed_of_distinct: a (row, col) position is given twice")
    return _sorted_rows(position, cols[order], np.asarray(values, float)[order], shape)


def compressed_of_summed(rows: np.ndarray, cols: np.ndarray, values: np.ndarray, shape) -> Compressed:
    """The CSR rows scipy makes of entries that may share a position:
    ``scipy.sparse.coo_matrix((values, (rows, cols))).tocsr()``, zeros dropped.

    Where there are few entries (FEW_ENTRIES) and no position is given more than
    twice they are summed here (a sum of two is the same in either order); three or
    more are left to scipy, which sums them in the order its sort leaves them, and
    so are many entries (its conversion is linear, a sort is not).

    Parameters
    ----------
    rows, cols : (nnz,) int positions. values : (nnz,) float entries.
    shape : (n_rows, n_cols).

    Returns
    -------
    Compressed, CSR of ``shape``, canonical.
    """
    if len(rows) <= FEW_ENTRIES:
        position = rows.astype(np.int64) * shape[1] + cols
        order = np.argsort(position)
        position = position[order]
        if not np.any(position[2:] == position[:-2]):
            return _pairs_summed(position, cols[order], np.asarray(values, float)[order], shape)
    matrix = sp.coo_matrix((values, (rows, cols)), shape=shape).tocsr()
    matrix.eliminate_zeros()
    return Compressed("csr", matrix.indptr, matrix.indices, matrix.data, shape)


def _pairs_summed(position: np.ndarray, cols: np.ndarray, values: np.ndarray, shape) -> Compressed:
    """CSR rows of entries at ascending ``position`` = row × n_cols + col, each position
    at most twice (summed), zeros dropped."""
    repeated = np.flatnonzero(position[1:] == position[:-1])
    sums = values.copy()
    sums[repeated] += values[repeated + 1]
    kept = np.ones(len(position), bool)
    kept[repeated + 1] = False
    kept &= sums != 0
    return _sorted_rows(position[kept], cols[kept], sums[kept], shape)


def _sorted_rows(position: np.ndarray, cols: np.ndarray, values: np.ndarray, shape) -> Compressed:
    """CSR rows of entries at ascending distinct ``position`` = row × n_cols + col."""
    return Compressed("csr", np.searchsorted(position, np.arange(shape[0] + 1) * shape[1]), cols, values, shape)


def compressed_rows(dense: np.ndarray) -> Compressed:
    """The nonzero entries of ``dense`` (n, p) as canonical CSR rows (column indices
    ascending), as scipy stores the sparse matrix it equals."""
    rows, cols = np.nonzero(dense != 0)       # (a mask: float nonzero scans several times slower)
    indptr = np.zeros(dense.shape[0] + 1, cols.dtype)
    np.cumsum(np.bincount(rows, minlength=dense.shape[0]), out=indptr[1:])
    return Compressed("csr", indptr, cols, dense[rows, cols], dense.shape)


def stored_entries(indptr: np.ndarray, which: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The stored entries of the rows (or columns) ``which`` of a compressed matrix,
    row after row in stored order.

    Parameters
    ----------
    indptr : (n_major + 1,) int, the matrix's. which : (k,) int, rows in any order.

    Returns
    -------
    owner : (e,) the place in ``which`` each entry belongs to.
    place : (e,) its place in the matrix's ``indices`` and ``data``.
    """
    lengths = np.diff(indptr)[which]
    owner = np.repeat(np.arange(len(which)), lengths)
    return owner, indptr[which][owner] + np.arange(len(owner)) - (np.cumsum(lengths) - lengths)[owner]


def as_scipy(matrix) -> sp.csr_matrix:
    """The scipy CSR matrix of a CSR :class:`Compressed` with its arrays as they are
    (indices in their stored order, not flagged sorted), or ``matrix`` itself.

    Parameters
    ----------
    matrix : Compressed (CSR) or scipy sparse matrix.

    Returns
    -------
    scipy.sparse.csr_matrix, or ``matrix`` where it is not a :class:`Compressed`.
    """
    if not isinstance(matrix, Compressed):
        return matrix
    return sp.csr_matrix((matrix.data, matrix.indices, matrix.indptr), shape=matrix.shape)


def scipy_csr(matrix) -> sp.csr_matrix:
    """The scipy CSR matrix of a dense array, of a CSR :class:`Compressed` whose indices
    ascend in each row, or of a scipy sparse matrix (itself if CSR). The index arrays
    are made of the type scipy would choose, once, here.

    Parameters
    ----------
    matrix : numpy.ndarray (n, p), Compressed or scipy sparse.

    Returns
    -------
    scipy.sparse.csr_matrix, flagged as having sorted indices where made here.
    """
    if isinstance(matrix, np.ndarray):
        matrix = compressed_rows(matrix)
    if not isinstance(matrix, Compressed):
        return matrix.tocsr()
    index = index_type(matrix.shape[1], len(matrix.data))
    csr = sp.csr_matrix((matrix.data, matrix.indices.astype(index, copy=False),
                         matrix.indptr.astype(index, copy=False)), shape=matrix.shape)
    csr.has_sorted_indices = True
    return csr


def index_type(n_cols: int, n_entries: int) -> type:
    """The index type scipy gives a CSR matrix's ``indices`` and ``indptr``: int32 where
    every column index and entry count fits, else int64.

    Parameters
    ----------
    n_cols : int
        The matrix's columns.
    n_entries : int
        Its stored entries.

    Returns
    -------
    numpy.int32 or numpy.int64
    """
    return np.int32 if max(n_cols, n_entries) < 2 ** 31 else np.int64


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
    return scipy_csr(_sorted_rows(position, position % n, sums[kept] * 0.5, (n, n)))
