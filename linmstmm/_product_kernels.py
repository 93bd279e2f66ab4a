"""Compiled sparse products of the counter's and the coarse pencil's assembly: dense
results of small sparse operands, each entry summed as :mod:`linmstmm.fe.products`
(and so scipy.sparse) sums it, the same numbers bit for bit in one call each.

:mod:`linmstmm.fe.products` forms them in numpy, tens of calls a product; here each
is one compiled loop (``@njit(cache=True)``, no fast-math: every sum is the running
sum from zero those form, term after term in their order, with no fused
multiply-add). The Wittrick–Williams counter (:mod:`linmstmm.wittrick_williams`,
compiled engine) forms its springs' stiffness and bodies' mass with them, and the
coarse predictions (:mod:`linmstmm.coarse_prediction`, once the compiled kernels are
loaded) their K and M from the beams' elements, springs and bodies in one call
(:func:`pencil_forms`), where :mod:`linmstmm.fe.assembly` first writes them as
triplets and compresses them; tests/test_pencil_build.py compares both with the
numpy route.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from linmstmm._compile_notice import announce_compiles

announce_compiles()  # one line on stderr if this run compiles (linmstmm._compile_notice)


@njit(cache=True)
def ordered_congruence(t_indptr, t_indices, t_data, m_indptr, m_indices, m_data, n):
    """``Tᵀ M T`` dense, each entry summed as :func:`linmstmm.fe.products.congruence`
    (and so scipy.sparse) sums it: ``Tᵀ M`` first, over T's rows ascending, then that
    times T, over its columns ascending; the same numbers bit for bit.

    Parameters
    ----------
    t_indptr, t_indices, t_data : CSR arrays of T (n_full, n).
    m_indptr, m_indices, m_data : CSR arrays of M (n_full, n_full), each position
        once in a row (in any order; a stored zero adds nothing).
    n : int, T's columns.

    Returns
    -------
    (n, n) float64, not symmetrised.
    """
    n_full = t_indptr.size - 1
    # half[c, i] = (Tᵀ M)[i, c], and for each c the i it holds (members[starts[c]:filled[c]])
    starts = np.zeros(n_full + 1, dtype=np.int64)
    for k in range(n_full):
        for mm in range(m_indptr[k], m_indptr[k + 1]):
            starts[m_indices[mm] + 1] += t_indptr[k + 1] - t_indptr[k]
    starts = np.cumsum(starts)
    filled, members = starts[:-1].copy(), np.empty(starts[-1], dtype=np.int64)
    half, held = np.zeros((n_full, n)), np.zeros((n_full, n), dtype=np.bool_)
    for k in range(n_full):
        for tt in range(t_indptr[k], t_indptr[k + 1]):
            i, t = t_indices[tt], t_data[tt]
            for mm in range(m_indptr[k], m_indptr[k + 1]):
                c = m_indices[mm]
                half[c, i] += t * m_data[mm]
                if not held[c, i]:
                    held[c, i] = True
                    members[filled[c]] = i
                    filled[c] += 1
    product = np.zeros((n, n))
    for c in range(n_full):  # each entry's terms over c ascending
        for q in range(starts[c], filled[c]):
            i = members[q]
            a = half[c, i]
            if a != 0.0:
                for tt in range(t_indptr[c], t_indptr[c + 1]):
                    product[i, t_indices[tt]] += a * t_data[tt]
    return product


@njit(cache=True)
def ordered_gram(s_indptr, s_indices, s_data, t_indptr, t_indices, t_data, weights, n, weight_left):
    """``Gᵀ diag(weights) G`` dense for G = S T, each entry summed as
    :func:`linmstmm.fe.products.dense_product` (and so scipy.sparse) sums it: each
    row g of G from zero over S's row in stored order, zero entries dropped; then
    over G's rows ascending, the term (g_i w) g_j where ``weight_left``
    (``transposed(G, w) @ G``), else g_i (g_j w) (``transposed(G) @ rows_scaled(G, w)``).

    Parameters
    ----------
    s_indptr, s_indices, s_data : CSR arrays of S (r, n_full).
    t_indptr, t_indices, t_data : CSR arrays of T (n_full, n).
    weights : (r,) float64. n : int, T's columns. weight_left : bool.

    Returns
    -------
    (n, n) float64, not symmetrised.
    """
    product, scratch = np.zeros((n, n)), _gram_scratch(n)
    for r in range(s_indptr.size - 1):
        _add_gram_row(s_indices, s_data, s_indptr[r], s_indptr[r + 1], t_indptr, t_indices, t_data, weights[r],
                      weight_left, product, scratch)
    return product


@njit(cache=True)
def _gram_scratch(n):
    """(row values (n,), touched (n,), their columns (n,)) for :func:`_add_gram_row`."""
    return np.zeros(n), np.zeros(n, dtype=np.bool_), np.empty(n, dtype=np.int64)


@njit(cache=True)
def _add_gram_row(cols, values, start, stop, t_indptr, t_indices, t_data, w, weight_left, product, scratch):
    """Add the term of one row of S (``cols``, ``values`` [start, stop), columns
    ascending) to ``product``, as :func:`ordered_gram` does."""
    row, touched, columns = scratch
    used = 0
    for ss in range(start, stop):
        k, s = cols[ss], values[ss]
        for tt in range(t_indptr[k], t_indptr[k + 1]):
            j = t_indices[tt]
            row[j] += s * t_data[tt]
            if not touched[j]:
                touched[j] = True
                columns[used] = j
                used += 1
    for a in range(used):
        i = columns[a]
        if row[i] != 0.0:
            left = row[i] * w if weight_left else row[i]
            for b in range(used):
                j = columns[b]
                if row[j] != 0.0:
                    product[i, j] += left * (row[j] if weight_left else row[j] * w)
    for a in range(used):
        row[columns[a]] = 0.0
        touched[columns[a]] = False


@njit(cache=True)
def _grouped_rows(n_rows, rows, cols, values):
    """The CSR rows (indptr, cols, values) :func:`linmstmm.fe.sparse.compressed_of_distinct`
    makes of triplets whose ``rows`` are grouped and ascending: each row's columns
    ascending, zeros left out; indptr empty where a position is given twice."""
    indptr = np.zeros(n_rows + 1, dtype=np.int64)
    out_cols, out_values = np.empty(rows.size, dtype=np.int64), np.empty(rows.size)
    kept, p = 0, 0
    for r in range(n_rows):
        while p < rows.size and rows[p] == r:
            if values[p] != 0.0:
                place = kept
                while place > indptr[r] and out_cols[place - 1] > cols[p]:  # insertion, columns ascending
                    out_cols[place], out_values[place] = out_cols[place - 1], out_values[place - 1]
                    place -= 1
                if place > indptr[r] and out_cols[place - 1] == cols[p]:
                    return np.zeros(0, dtype=np.int64), out_cols, out_values
                out_cols[place], out_values[place] = cols[p], values[p]
                kept += 1
            p += 1
        indptr[r + 1] = kept
    if p < rows.size:  # not grouped
        return np.zeros(0, dtype=np.int64), out_cols, out_values
    return indptr, out_cols, out_values


@njit(cache=True)
def _full_mass(n_full, rigid_rows, rigid_cols, rigid_values, dofs, masses):
    """The full mass as :func:`linmstmm.fe.sparse.compressed_of_summed` makes it of the
    bodies' triplets followed by the elements' (b, n, 12, 12) ``masses`` on their
    ``dofs`` (b, n, 12): each position's entries summed (a pair a + b is the same in
    either order); CSR rows (indptr, cols, values), columns in the order first met,
    zero sums kept (they add nothing to a product). indptr is empty where a position
    is given three times or more (their sum depends on scipy's order)."""
    starts = np.zeros(n_full + 1, dtype=np.int64)
    for e in range(rigid_rows.size):
        starts[rigid_rows[e] + 1] += 1
    for b in range(dofs.shape[0]):
        for e in range(dofs.shape[1]):
            for a in range(12):
                starts[dofs[b, e, a] + 1] += 12
    starts = np.cumsum(starts)
    cols, values, filled = np.empty(starts[-1], dtype=np.int64), np.empty(starts[-1]), starts[:-1].copy()
    for e in range(rigid_rows.size):
        r = rigid_rows[e]
        cols[filled[r]], values[filled[r]] = rigid_cols[e], rigid_values[e]
        filled[r] += 1
    for b in range(dofs.shape[0]):
        for e in range(dofs.shape[1]):
            for a in range(12):
                r = dofs[b, e, a]
                for c in range(12):
                    cols[filled[r]], values[filled[r]] = dofs[b, e, c], masses[b, e, a, c]
                    filled[r] += 1
    slot, times = np.full(n_full, -1, dtype=np.int64), np.zeros(starts[-1], dtype=np.int64)
    indptr, kept = np.zeros(n_full + 1, dtype=np.int64), 0
    for r in range(n_full):
        first = kept
        for p in range(starts[r], starts[r + 1]):
            c = cols[p]
            if slot[c] < 0:
                slot[c] = kept
                cols[kept], values[kept], times[kept] = c, values[p], 1
                kept += 1
            else:
                values[slot[c]] += values[p]
                times[slot[c]] += 1
                if times[slot[c]] > 2:
                    return np.zeros(0, dtype=np.int64), cols, values
        for q in range(first, kept):
            slot[cols[q]] = -1
        indptr[r + 1] = kept
    return indptr, cols, values


@njit(cache=True)
def _pencil(t_indptr, t_indices, t_data, n, rows, dofs, strain, d, s_indptr, s_indices, s_data, spring_stiffness,
            rigid_rows, rigid_cols, rigid_values, masses):
    """(M, K, formed) of :func:`pencil_forms`; formed False (M, K empty) where the full
    mass gives a position three times or more."""
    indptr, cols, values = _full_mass(t_indptr.size - 1, rigid_rows, rigid_cols, rigid_values, dofs, masses)
    if indptr.size == 0:
        return np.zeros((0, 0)), np.zeros((0, 0)), False
    M = ordered_congruence(t_indptr, t_indices, t_data, indptr, cols, values, n)
    K, scratch = np.zeros((n, n)), _gram_scratch(n)
    ks, vs = np.empty(12, dtype=np.int64), np.empty(12)
    for b in range(dofs.shape[0]):
        for e in range(dofs.shape[1]):
            for r in range(6):
                if strain[b, r]:
                    count = 0
                    for a in range(12):  # the row's nonzero entries, columns ascending
                        if rows[b, e, r, a] != 0.0:
                            place = count
                            while place > 0 and ks[place - 1] > dofs[b, e, a]:
                                ks[place], vs[place] = ks[place - 1], vs[place - 1]
                                place -= 1
                            ks[place], vs[place] = dofs[b, e, a], rows[b, e, r, a]
                            count += 1
                    _add_gram_row(ks, vs, 0, count, t_indptr, t_indices, t_data, d[b, r], True, K, scratch)
    for r in range(s_indptr.size - 1):
        _add_gram_row(s_indices, s_data, s_indptr[r], s_indptr[r + 1], t_indptr, t_indices, t_data,
                      spring_stiffness[r], True, K, scratch)
    _symmetrise(M)
    _symmetrise(K)
    return M, K, True


@njit(cache=True)
def _symmetrise(A):
    """(A + Aᵀ) / 2 of the square ``A`` in place, each entry (a + b) * 0.5 as
    :func:`linmstmm.fe.assembly._symmetric_of_dense` forms it (a diagonal entry is
    itself: a + a doubles and halves exactly)."""
    for i in range(A.shape[0]):
        for j in range(i):
            A[i, j] = A[j, i] = (A[i, j] + A[j, i]) * 0.5


@njit(cache=True)
def unit_scaled(K, M):
    """The coarse pencil scaled to unit mass (or stiffness) per unknown, as
    :func:`linmstmm.scaled_pencil._unit_scaled` scales it in numpy, the same
    numbers in one pass.

    Parameters
    ----------
    K, M : (n, n) float64
        Stiffness (N/m, N m/rad) and mass (kg, kg m²), symmetric.

    Returns
    -------
    scale : (n,) float64
        1 / √(M_ii, or |K_ii| where M_ii is not positive, or 1 where that is 0).
    K_scaled, M_scaled : (n, n) float64
        K_ij (s_i s_j) and M_ij (s_i s_j).
    """
    n = K.shape[0]
    scale = np.empty(n)
    for i in range(n):
        size = M[i, i] if M[i, i] > 0 else np.abs(K[i, i])
        scale[i] = 1 / np.sqrt(size if size > 0 else 1.0)
    K_scaled, M_scaled = np.empty((n, n)), np.empty((n, n))
    for i in range(n):
        for j in range(n):
            both = scale[i] * scale[j]
            K_scaled[i, j], M_scaled[i, j] = K[i, j] * both, M[i, j] * both
    return scale, K_scaled, M_scaled


def counter_terms(parts) -> tuple[np.ndarray, np.ndarray] | None:
    """The Wittrick–Williams counter's springs' stiffness and bodies' mass on the reduced
    DOFs of ``parts`` (:class:`~linmstmm.fe.assembly.ConstrainedParts`): the numbers
    ``dense_product(transposed(G), rows_scaled(G, k))``, G = S T, and
    :func:`~linmstmm.fe.products.congruence` form of the compressed spring rows S and
    body masses, formed from their triplets in one call (:func:`_counter_products`).

    Parameters
    ----------
    parts : linmstmm.fe.assembly.ConstrainedParts

    Returns
    -------
    (static, mass) : (n, n) float64 each (N/m, N m/rad; kg, kg m²), or None where the
    triplets are not of the kind compressed here (left to the numpy route).
    """
    T = parts.T
    stiffness = parts.spring_stiffness
    stiffness = stiffness[0] if len(stiffness) == 1 else (np.concatenate(stiffness) if stiffness else np.zeros(0))
    static, mass, formed = _counter_products(parts.spring_strains.n_rows, *parts.spring_strains.joined(),
                                             stiffness.astype(float, copy=False), *parts.rigid_mass.joined(),
                                             T.indptr, T.indices, T.data, T.shape[1])
    return (static, mass) if formed else None


@njit(cache=True)
def _counter_products(n_strains, strain_rows, strain_cols, strain_values, stiffness, mass_rows, mass_cols,
                      mass_values, t_indptr, t_indices, t_data, n):
    """(static, mass, formed) of :func:`counter_terms`: the strain triplets grouped into
    CSR rows (:func:`_grouped_rows`), the mass triplets summed (:func:`_full_mass`),
    then ``ordered_gram`` and ``ordered_congruence`` on T; formed False (both empty)
    where the triplets are not of that kind."""
    s_indptr, s_cols, s_values = _grouped_rows(n_strains, strain_rows, strain_cols, strain_values)
    indptr, cols, values = _full_mass(t_indptr.size - 1, mass_rows, mass_cols, mass_values,
                                      np.zeros((0, 0, 12), dtype=np.int64), np.zeros((0, 0, 12, 12)))
    if s_indptr.size == 0 or indptr.size == 0:
        return np.zeros((0, 0)), np.zeros((0, 0)), False
    return (ordered_gram(s_indptr, s_cols, s_values, t_indptr, t_indices, t_data, stiffness, n, False),
            ordered_congruence(t_indptr, t_indices, t_data, indptr, cols, values, n), True)


def _triplet_rows(triplets, n_rows) -> tuple | None:
    """CSR arrays (:func:`_grouped_rows`) of ``triplets`` (:class:`~linmstmm.fe.layout._Triplets`)
    with ``n_rows`` rows, or None where they are not grouped by row."""
    indptr, cols, values = _grouped_rows(n_rows, *triplets.joined())
    return None if indptr.size == 0 else (indptr, cols, values)


def pencil_forms(T, elements, parts) -> tuple[np.ndarray, np.ndarray] | None:
    """The ``forms`` of :func:`linmstmm.fe.assembly.assembled`: (Tᵀ M_full T, Gᵀ diag(D) G)
    dense and symmetrised, G = S T, the numbers :func:`linmstmm.fe.products.congruence`
    and ``dense_product(transposed(G, D), G)`` form of the full mass and strain rows
    that :func:`linmstmm.fe.assembly._add_beams` writes (the beams' strain rows, then
    the springs'; the bodies' masses, then the elements'), without writing them.

    Parameters
    ----------
    T : (n_full, n) CSR (scipy or :class:`~linmstmm.fe.sparse.Compressed`).
    elements : linmstmm.fe.assembly._BeamElements
        The beams' elements on the full DOFs.
    parts : linmstmm.fe.assembly.ConstrainedParts
        Its springs' strain rows and stiffnesses and the bodies' mass triplets.

    Returns
    -------
    (M, K) : (n, n) float64 each, or None where a position of the full mass is given
    three times or more (left to the numpy route, which sums them in scipy's order),
    or a spring row's twice (which the numpy route refuses).
    """
    springs = _triplet_rows(parts.spring_strains, parts.spring_strains.n_rows)
    if springs is None:
        return None
    stiffness = np.concatenate(parts.spring_stiffness) if parts.spring_stiffness else np.zeros(0)
    mass = np.swapaxes(elements.to_local, 2, 3) @ elements.m[:, None] @ elements.to_local
    M, K, formed = _pencil(T.indptr, T.indices, T.data, T.shape[1], elements.rows, elements.dofs, elements.strain,
                           elements.d, *springs, stiffness, *parts.rigid_mass.joined(), mass)
    return (M, K) if formed else None
