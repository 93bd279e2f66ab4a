"""Exact constraints: the sparse master–slave elimination ``q = T q_r`` of linear
homogeneous constraint rows, and the rounding debris dropped before it."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from linmstmm.fe.products import dense_product, small
from linmstmm.fe.sparse import Compressed, compressed_rows, scipy_csr, stored_entries

#: A substituted constraint row whose entries all fall below this fraction of
#: the largest term that entered it is redundant (implied by earlier rows).
REDUNDANT_CONSTRAINT = 1e-10
#: Entries below this fraction of their row's largest are rounding debris.
NEGLIGIBLE_ENTRY = 1e-14


def _eliminate(constraints: Compressed) -> tuple[Compressed, np.ndarray]:
    """Master–slave null-space basis of the rows of ``constraints``.

    Rows are taken one at a time, written in the current masters, and one
    master becomes a slave: among the entries within a factor 2 of the
    largest (threshold pivoting), the one fewest slaves depend on, so chains
    of constraints do not fill in. Redundant rows (closed loops of rigid
    links) are recognised and skipped.

    Returns
    -------
    T1 : (n, n_masters) CSR rows (:class:`~linmstmm.fe.sparse.Compressed`); the
        masters' rows are identity rows.
    masters : (n_masters,) their indices, ascending.
    """
    expression = {}                     # slave -> {master: coefficient}
    users = {}                          # master -> slaves that use it
    indptr, indices, data = constraints.indptr, constraints.indices, constraints.data
    for r in range(constraints.shape[0]):
        if indptr[r + 1] - indptr[r] == 1 and indices[indptr[r]] not in expression \
                and not users.get(indices[indptr[r]]):
            expression[int(indices[indptr[r]])] = {}
            continue
        row, scale = _in_masters(indices[indptr[r]:indptr[r + 1]].tolist(),
                                 data[indptr[r]:indptr[r + 1]].tolist(), expression)
        largest = max(map(abs, row.values()), default=0.0)
        if largest <= REDUNDANT_CONSTRAINT * scale:
            continue
        row = {m: v for m, v in row.items() if abs(v) > NEGLIGIBLE_ENTRY * largest}
        slave = min((m for m, v in row.items() if abs(v) >= 0.5 * largest),
                    key=lambda m: (len(users.get(m, ())), -abs(row[m])))
        pivot = row.pop(slave)
        solved = {m: -v / pivot for m, v in row.items()}
        for dependent in users.pop(slave, ()):
            _substitute(expression[dependent], dependent, slave, solved, users)
        expression[slave] = solved
        for master in solved:
            users.setdefault(master, set()).add(slave)
    return _basis(expression, constraints.shape[1])


def _in_masters(cols: list, values: list, expression: dict) -> tuple[dict, float]:
    """One constraint row (its columns and values) written in the current masters:
    {master: coefficient}, and the largest term that entered it."""
    row, scale = {}, 0.0
    for j, c in zip(cols, values):
        terms = expression.get(j)
        for master, e in (((j, 1.0),) if terms is None else terms.items()):
            term = c * e
            row[master] = row.get(master, 0.0) + term
            scale = max(scale, abs(term))
    return row, scale


def _basis(expression: dict, n: int) -> tuple[Compressed, np.ndarray]:
    """(n, n_masters) CSR rows of T1 (indices ascending) and (n_masters,) masters,
    ascending, from each slave's ``expression`` {master: coefficient}; every other
    DOF is a master."""
    slaves = np.array(list(expression), int)
    is_master = np.ones(n, bool)
    is_master[slaves] = False
    masters = np.flatnonzero(is_master)
    column = np.cumsum(is_master) - 1
    ordered = [sorted(terms.items()) for terms in expression.values()]     # masters ascending
    lengths = is_master.astype(int)
    lengths[slaves] = [len(terms) for terms in ordered]
    indptr = np.zeros(n + 1, int)
    np.cumsum(lengths, out=indptr[1:])
    indices, data = np.empty(indptr[-1], int), np.empty(indptr[-1])
    indices[indptr[masters]], data[indptr[masters]] = column[masters], 1.0
    place = stored_entries(indptr, slaves)[1]
    indices[place] = column[np.array([m for terms in ordered for m, _ in terms], int)]
    data[place] = [v for terms in ordered for _, v in terms]
    return Compressed("csr", indptr, indices, data, (n, len(masters))), masters


def _substitute(terms, owner, slave, solved, users):
    """Replace ``slave`` by its expression ``solved`` inside ``terms`` (in place)."""
    c = terms.pop(slave)
    for master, v in solved.items():
        terms[master] = terms.get(master, 0.0) + c * v
    largest = max((abs(v) for v in terms.values()), default=0.0)
    for master in [m for m, v in terms.items() if abs(v) <= NEGLIGIBLE_ENTRY * largest]:
        del terms[master]
        users.get(master, set()).discard(owner)
    for master in terms:
        users.setdefault(master, set()).add(owner)


def reduced_constraints(constraints: Compressed, t0: sp.csr_matrix) -> Compressed:
    """``constraints @ t0`` (canonical CSR rows), less the entries below NEGLIGIBLE_ENTRY of
    their row's largest: densely where small (:mod:`linmstmm.fe.products`), the same
    entries as scipy.sparse's product."""
    shape = (constraints.shape[0], t0.shape[1])
    if small(*shape):
        return _debris_dropped(compressed_rows(dense_product(constraints, t0)))
    product = sp.csr_matrix(scipy_csr(constraints) @ t0)
    product.sum_duplicates()                           # indices ascending
    return _debris_dropped(Compressed("csr", product.indptr, product.indices, product.data, shape))


def _debris_dropped(matrix: Compressed) -> Compressed:
    """The CSR rows ``matrix`` (columns ascending within a row) without the entries at
    most NEGLIGIBLE_ENTRY of their row's largest."""
    rows = np.repeat(np.arange(matrix.shape[0]), np.diff(matrix.indptr))
    magnitude = np.abs(matrix.data)
    row_max = np.zeros(matrix.shape[0])
    np.maximum.at(row_max, rows, magnitude)
    kept = magnitude > NEGLIGIBLE_ENTRY * row_max[rows]
    indptr = np.concatenate([[0], np.cumsum(np.bincount(rows[kept], minlength=matrix.shape[0]))])
    return Compressed("csr", indptr, matrix.indices[kept], matrix.data[kept], matrix.shape)
