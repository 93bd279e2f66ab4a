"""Compiled sparse products of the counter's and the coarse pencil's assembly: dense
results of small sparse operands, each entry summed as :mod:`linmstmm.fe.products`
(and so scipy.sparse) sums it, the same numbers bit for bit in one call each.

:mod:`linmstmm.fe.products` forms them in numpy, tens of calls a product; here each
is one compiled loop (``@njit(cache=True)``, no fast-math: every sum is the running
sum from zero those form, term after term in their order, with no fused
multiply-add). The Wittrick–Williams counter (:mod:`linmstmm.wittrick_williams`,
compiled engine) forms its springs' stiffness and bodies' mass with them, and the
coarse predictions (:mod:`linmstmm.coarse_prediction`, once the compiled kernels are
loaded) their K and M (:func:`pencil_forms`); tests/test_pencil_build.py and
tests/test_wittrick_williams.py compare them with the numpy route.
"""
from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def ordered_congruence(t_indptr, t_indices, t_data, m_indptr, m_indices, m_data, n):
    """``Tᵀ M T`` dense, each entry summed as :func:`linmstmm.fe.products.congruence`
    (and so scipy.sparse) sums it: ``Tᵀ M`` first, over T's rows ascending, then that
    times T, over its columns ascending; the same numbers bit for bit.

    Parameters
    ----------
    t_indptr, t_indices, t_data : CSR arrays of T (n_full, n).
    m_indptr, m_indices, m_data : CSR arrays of M (n_full, n_full), canonical.
    n : int, T's columns.

    Returns
    -------
    (n, n) float64, not symmetrised.
    """
    n_full = t_indptr.size - 1
    half = np.zeros((n, n_full))
    for k in range(n_full):
        for tt in range(t_indptr[k], t_indptr[k + 1]):
            i, t = t_indices[tt], t_data[tt]
            for mm in range(m_indptr[k], m_indptr[k + 1]):
                half[i, m_indices[mm]] += t * m_data[mm]
    product = np.zeros((n, n))
    for i in range(n):
        for c in range(n_full):
            a = half[i, c]
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
    product = np.zeros((n, n))
    row = np.zeros(n)
    touched = np.zeros(n, dtype=np.bool_)
    columns = np.empty(n, dtype=np.int64)
    for r in range(s_indptr.size - 1):
        used = 0
        for ss in range(s_indptr[r], s_indptr[r + 1]):
            k, s = s_indices[ss], s_data[ss]
            for tt in range(t_indptr[k], t_indptr[k + 1]):
                j = t_indices[tt]
                row[j] += s * t_data[tt]
                if not touched[j]:
                    touched[j] = True
                    columns[used] = j
                    used += 1
        w = weights[r]
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
    return product


def pencil_forms(T, mass, strains, D: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The ``forms`` of :func:`linmstmm.fe.assembly.assembled`: (Tᵀ M_full T, Gᵀ diag(D) G)
    dense and not symmetrised, G = S T, as :func:`linmstmm.fe.products.congruence` and
    ``dense_product(transposed(G, D), G)`` form them.

    Parameters
    ----------
    T : (n_full, n) CSR (scipy or :class:`~linmstmm.fe.sparse.Compressed`).
    mass : (n_full, n_full) canonical CSR, kg and kg m².
    strains : (r, n_full) canonical CSR, the strain rows S (m or rad).
    D : (r,) their stiffnesses.

    Returns
    -------
    M, K : (n, n) float64.
    """
    n = T.shape[1]
    return (ordered_congruence(T.indptr, T.indices, T.data, mass.indptr, mass.indices, mass.data, n),
            ordered_gram(strains.indptr, strains.indices, strains.data, T.indptr, T.indices, T.data, D, n, True))
