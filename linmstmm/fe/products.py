"""Products and rows of small sparse matrices formed in numpy, each entry summed
in the order scipy.sparse sums it: the same values bit for bit, without scipy's
per-call overhead (tens of microseconds a product and as much a conversion,
most of the assembly of a model of a few hundred unknowns).

scipy.sparse forms each entry of ``a @ b`` as a running sum from zero over the
shared index k, in the order it meets k: ``a``'s stored order within a row of a
CSR ``a``, ascending k for a CSC ``a`` (``b`` is converted to CSC, whose row
indices ascend). :func:`dense_product` generates the terms in that order and
adds them with :func:`numpy.bincount`, which adds in the order given.
"""
from __future__ import annotations

import numpy as np

from linmstmm.fe.sparse import Compressed, compressed_rows, stored_entries

#: Largest dense intermediate (rows × columns) for the callers that choose between
#: :func:`dense_product` and scipy.sparse: clearing and scanning a dense result costs
#: a few nanoseconds an entry, scipy's product tens of microseconds a call. Measured
#: on the assembly (n_dof × n_full): dense 1.0 against 1.3 ms sparse at 23,000
#: (launcher, two elements per beam), 1.26 against 1.47 ms at 40,000, even near
#: 55,000 to 80,000, 2.2 against 1.6 ms at 110,000.
DENSE_ENTRIES = 50_000


def small(n_rows: int, n_cols: int) -> bool:
    """Whether a result of ``n_rows`` × ``n_cols`` is formed densely (:data:`DENSE_ENTRIES`)."""
    return n_rows * n_cols <= DENSE_ENTRIES


def dense_product(a, b) -> np.ndarray:
    """``(a @ b).toarray()``, each entry summed as scipy.sparse sums it.

    Parameters
    ----------
    a : (n, m) scipy CSR or CSC matrix or :class:`Compressed`; a CSR one's indices
        in the order scipy would meet them (its stored order).
    b : (m, p) scipy CSR matrix or :class:`Compressed` CSR.

    Returns
    -------
    numpy.ndarray, (n, p).
    """
    n_rows, n_cols = a.shape[0], b.shape[1]
    major = np.repeat(np.arange(len(a.indptr) - 1), np.diff(a.indptr))
    rows, inner = (major, a.indices) if a.format == "csr" else (a.indices, major)
    entry, taken = stored_entries(b.indptr, inner)          # each entry of a times b's row of its k
    position = rows[entry] * n_cols + b.indices[taken]
    summed = np.bincount(position, a.data[entry] * b.data[taken], minlength=n_rows * n_cols)
    return summed.reshape(n_rows, n_cols)


def rows_scaled(matrix, factors: np.ndarray) -> Compressed:
    """``diag(factors) @ matrix`` of a CSR ``matrix`` (each entry times its row's factor),
    stored as ``matrix`` is, as scipy's ``matrix.multiply(factors[:, None])`` forms it."""
    data = matrix.data * np.repeat(factors, np.diff(matrix.indptr))
    return Compressed("csr", matrix.indptr, matrix.indices, data, matrix.shape)


def transposed(matrix, factors: np.ndarray | None = None) -> Compressed:
    """``matrix.T`` of a CSR ``matrix`` as CSC (its own arrays), each entry times its
    row's ``factors`` when given: ``matrix.T @ diag(factors)``."""
    data = matrix.data if factors is None else matrix.data * np.repeat(factors, np.diff(matrix.indptr))
    return Compressed("csc", matrix.indptr, matrix.indices, data, matrix.shape[::-1])


def congruence(T, matrix) -> np.ndarray:
    """``(T.T @ matrix @ T).toarray()`` as scipy.sparse forms it (``T.T @ matrix`` first).

    Parameters
    ----------
    T : (n, m) scipy CSR matrix. matrix : (n, n) scipy CSR matrix.

    Returns
    -------
    numpy.ndarray, (m, m); formed through a dense intermediate (m, the columns of
    ``matrix`` that hold entries: the others add no term), or moved where T keeps
    every DOF ``matrix`` touches (:func:`_moved`).
    """
    used = np.flatnonzero(np.bincount(matrix.indices, minlength=matrix.shape[1]))
    moved = _moved(T, matrix, used)
    if moved is not None:
        return moved
    narrowed = Compressed("csr", matrix.indptr, np.searchsorted(used, matrix.indices), matrix.data,
                          (matrix.shape[0], len(used)))
    line, taken = stored_entries(T.indptr, used)                # the rows of T those columns meet
    indptr = np.zeros(len(used) + 1, int)
    np.cumsum(np.bincount(line, minlength=len(used)), out=indptr[1:])
    rows = Compressed("csr", indptr, T.indices[taken], T.data[taken], (len(used), T.shape[1]))
    return dense_product(compressed_rows(dense_product(transposed(T), narrowed)), rows)


def _moved(T, matrix, used: np.ndarray) -> np.ndarray | None:
    """:func:`congruence` where ``matrix`` (canonical CSR) has entries in the rows ``used``
    and the same columns, and the row of T at each of them is a single 1.0 in a column
    of its own (the DOF is kept as it is: a rigid body's free mass centre), else None.
    Each entry of the product is then one term, 1.0 × a × 1.0 added to zero, which
    is ``a`` exactly: ``matrix``'s nonzero entries moved to those columns. (An empty
    ``matrix`` is left to the general route, whose result is of its own type.)"""
    first = T.indptr[used]
    if not used.size or np.any(T.indptr[used + 1] - first != 1) or np.any(T.data[first] != 1.0) \
            or not np.array_equal(np.flatnonzero(np.diff(matrix.indptr)), used):
        return None
    column = np.zeros(T.shape[0], int)
    column[used] = T.indices[first]
    if np.unique(column[used]).size < used.size:
        return None
    lines = np.repeat(np.arange(matrix.shape[0]), np.diff(matrix.indptr))
    entries = matrix.data != 0
    moved = np.zeros((T.shape[1], T.shape[1]))
    moved[column[lines[entries]], column[matrix.indices[entries]]] = matrix.data[entries]
    return moved


def dense_rows(matrix, rows: np.ndarray) -> np.ndarray:
    """``matrix[rows].toarray()`` of a CSR ``matrix``, for an int array ``rows`` of any
    shape: the result has that shape plus the column axis."""
    flat = np.ravel(rows)
    line, taken = stored_entries(matrix.indptr, flat)
    dense = np.zeros((len(flat), matrix.shape[1]))
    dense[line, matrix.indices[taken]] = matrix.data[taken]
    return dense.reshape(np.shape(rows) + (matrix.shape[1],))

