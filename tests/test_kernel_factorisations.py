"""The compiled kernels' own factorisations against numpy's (LAPACK's).

The Gram–Schmidt of the orthonormalisation (a second pass only where the first
cancelled much of a column) against numpy's Householder QR, on stacks as
ill-conditioned as a growing beam's; the LU behind log|det Ū_all| against
numpy's slogdet, at singular and non-finite matrices too.
"""
from __future__ import annotations

import mpmath
import numpy as np
import pytest

from linmstmm import _kernels


def graded(rng, rows, columns, decades, dtype):
    """(rows, columns) with singular values spread over ``decades``, random bases."""
    def basis(n):
        q, _ = np.linalg.qr(rng.standard_normal((n, n)) + (1j * rng.standard_normal((n, n)) if dtype == complex else 0))
        return q
    singular = np.logspace(0, -decades, columns)
    return (basis(rows)[:, :columns] * singular) @ basis(columns)


def exact_log_volume(stack) -> float:
    """log of the product of R's diagonal for the float ``stack`` itself: ½ log det(AᴴA) in mpmath."""
    with mpmath.workdps(60):
        a = mpmath.matrix([[mpmath.mpc(complex(v)) for v in row] for row in stack])
        return float(mpmath.re(mpmath.log(mpmath.det(a.H * a))) / 2)


@pytest.mark.parametrize("dtype", [float, complex])
@pytest.mark.parametrize("rows, columns, decades", [(12, 6, 2), (30, 24, 8), (36, 24, 12), (48, 36, 4)])
def test_gram_schmidt_is_a_qr(dtype, rows, columns, decades):
    """Orthonormal to rounding, a factorisation of the stack to rounding, and the sum of
    the logs of R's diagonal (what the log-scale adds) as close to the exact one as
    numpy's Householder QR gets (the stack's conditioning, 10**decades, bounds both)."""
    stack = graded(np.random.default_rng(rows + decades), rows, columns, decades, dtype)
    work = np.ascontiguousarray(stack.T)  # one column per row, as the kernel keeps them
    diagonal = np.zeros(columns)
    assert _kernels._orthonormal_columns(work, diagonal, np.empty(columns, dtype=work.dtype))
    q = work.T
    assert np.abs(q.conj().T @ q - np.eye(columns)).max() < 1e-14 * rows
    np.testing.assert_allclose(q @ np.triu(q.conj().T @ stack), stack, rtol=0, atol=1e-14 * rows)
    exact = exact_log_volume(stack)
    reference_error = abs(np.log(np.abs(np.diagonal(np.linalg.qr(stack)[1]))).sum() - exact)
    assert abs(np.log(diagonal).sum() - exact) <= max(1e-13 * abs(exact), 10 * reference_error)


def test_gram_schmidt_reports_an_exactly_dependent_column():
    stack = np.eye(12)[:, :6] * np.arange(1.0, 7.0)
    stack[:, 4] = 2.0 * stack[:, 1]
    assert not _kernels._orthonormal_columns(np.ascontiguousarray(stack.T), np.zeros(6), np.empty(6))


@pytest.mark.parametrize("dtype", [float, complex])
def test_log_det_is_numpys_slogdet(dtype):
    rng = np.random.default_rng(1)
    matrix = rng.standard_normal((40, 40)) + (1j * rng.standard_normal((40, 40)) if dtype == complex else 0)
    matrix[:, :20] *= 1e-30  # far from units: the log, not the product
    sign, log_abs = _kernels._log_det(np.asfortranarray(matrix))
    reference = np.linalg.slogdet(matrix)
    np.testing.assert_allclose(sign, reference[0], rtol=1e-12)
    np.testing.assert_allclose(log_abs, reference[1], rtol=1e-13)


@pytest.mark.parametrize("dtype", [float, complex])
def test_log_det_of_singular_and_non_finite_matrices(dtype):
    matrix = np.random.default_rng(2).standard_normal((8, 8)).astype(dtype)
    singular = matrix.copy()
    singular[:, 3] = 0.0
    assert _kernels._log_det(np.asfortranarray(singular)) == (0.0, -np.inf)
    for bad in (np.nan, np.inf):
        broken = matrix.copy()
        broken[5, 2] = bad
        sign, log_abs = _kernels._log_det(np.asfortranarray(broken))
        assert np.isnan(sign) and np.isnan(log_abs)
