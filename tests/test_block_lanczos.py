"""Block shift-invert Lanczos (linmstmm.block_lanczos) against closed forms: a fixed-fixed
chain of equal masses and springs has the eigenvalues (4k/m) sin²(jπ / 2(n+1)) and the
modes sin(i j π / (n+1)), two such chains side by side each of them twice. The coarse
prediction's sparse route gives ARPACK's frequencies, and where the Lanczos gives no
answer the dense route answers."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse

from linmstmm import block_lanczos
from linmstmm.block_lanczos import PRECISION, lowest_eigenvalues, lowest_modes


def chain(n: int, stiffness: float, mass: float):
    """K, M (n, n) of n equal masses between fixed ends, and its eigenvalues ascending."""
    K = scipy.sparse.diags([-np.ones(n - 1), 2 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1]) * stiffness
    M = scipy.sparse.identity(n) * mass
    exact = 4 * stiffness / mass * np.sin(np.arange(1, n + 1) * np.pi / (2 * (n + 1))) ** 2
    return K.tocsr(), M.tocsr(), exact


@pytest.mark.parametrize("stiffness, mass", [(1.0, 1.0), (3.7e9, 2.1e-4)])
@pytest.mark.parametrize("count", [10, 60])
def test_lowest_eigenvalues_of_a_chain_are_the_closed_form(stiffness, mass, count):
    """In any units, each within PRECISION (relative) of the closed form."""
    K, M, exact = chain(600, stiffness, mass)
    lam = lowest_eigenvalues(K, M, count, 0.5 * exact[0])
    assert lam.shape == (count,)
    np.testing.assert_allclose(lam, exact[:count], rtol=PRECISION, atol=0)


@pytest.mark.parametrize("stiffness, mass", [(1.0, 1.0), (3.7e9, 2.1e-4)])
def test_ritz_vectors_of_a_chain_are_its_modes(stiffness, mass):
    """lowest_modes: lowest_eigenvalues' values to the bit, and M-orthonormal vectors each
    within PRECISION (1 − |cos|, in the M inner product) of the closed-form mode."""
    K, M, exact = chain(600, stiffness, mass)
    values, vectors = lowest_modes(K, M, 20, 0.5 * exact[0])
    assert np.array_equal(values, lowest_eigenvalues(K, M, 20, 0.5 * exact[0]))
    np.testing.assert_allclose(vectors.T @ (M @ vectors), np.eye(20), rtol=0, atol=1e-13)
    index = np.arange(1, 601)
    shapes = np.sin(np.outer(index, np.arange(1, 21)) * np.pi / 601)
    shapes /= np.sqrt(np.sum(shapes * (M @ shapes), axis=0))
    assert np.max(1 - np.abs(np.sum(vectors * (M @ shapes), axis=0))) <= PRECISION


def test_double_eigenvalues_come_twice():
    """Two equal chains side by side: every eigenvalue double, and found twice."""
    K, M, exact = chain(300, 2.0, 1.5)
    twice = (scipy.sparse.block_diag([K, K]).tocsr(), scipy.sparse.block_diag([M, M]).tocsr())
    lam = lowest_eigenvalues(*twice, 40, 0.5 * exact[0])
    np.testing.assert_allclose(lam, np.repeat(exact[:20], 2), rtol=PRECISION, atol=0)


def test_no_answer_where_the_subspace_would_outgrow_the_pencil():
    """Nearly every eigenvalue of a small pencil wanted: the subspace the first check
    needs is larger than the pencil, so there is no answer (the caller solves dense)."""
    K, M, exact = chain(40, 1.0, 1.0)
    assert lowest_eigenvalues(K, M, 38, 0.5 * exact[0]) is None


def test_the_sparse_route_gives_arpacks_predictions_and_falls_back_to_the_dense_route(monkeypatch):
    """The launcher's refined mesh of 456 unknowns (above DENSE_PREDICTION): its 112 lowest
    by the Lanczos agree with ARPACK's to machine precision (scipy's eigsh on the same
    pencil) within PRECISION; where the Lanczos gives no answer, the dense route's come
    instead (within its own error: M is ill-conditioned, its Cholesky route's lowest
    are up to 1e-5 off)."""
    from scipy.sparse.linalg import eigsh

    from linmstmm import coarse_prediction
    from linmstmm.model import load_model

    model = load_model("models/mlrs/mlrs.toml")
    shift = 0.5 * coarse_prediction.coarse_predictions(model, 10, 2)[0] ** 2
    pencil = coarse_prediction.coarse_pencil(model, 33)
    assert pencil.K.shape[0] > coarse_prediction.DENSE_PREDICTION
    K, M = (scipy.sparse.csc_matrix(matrix) for matrix in (pencil.K, pencil.M))  # scaled as the sparse route's
    arpack = np.sqrt(np.sort(eigsh(K, k=112, M=M, sigma=-shift, which="LM",
                                   return_eigenvectors=False)))
    sparse = coarse_prediction.coarse_predictions(model, 112, 33, shift=shift)
    np.testing.assert_allclose(sparse, arpack, rtol=PRECISION, atol=0)
    calls = []
    monkeypatch.setattr(coarse_prediction, "lowest_eigenvalues", lambda *args: calls.append(1))
    fallback = coarse_prediction.coarse_predictions(model, 112, 33, shift=shift)
    assert calls
    np.testing.assert_allclose(fallback, arpack, rtol=1e-5, atol=0)


def test_a_dependent_block_gives_no_answer(monkeypatch):
    """A start block whose rows are dependent (a block of equal rows) cannot be
    normalised: no answer rather than a wrong one."""
    K, M, exact = chain(200, 1.0, 1.0)

    class Equal:
        def __init__(self, seed):
            pass

        def standard_normal(self, shape):
            return np.ones(shape)

    monkeypatch.setattr(block_lanczos.np.random, "default_rng", Equal)
    assert lowest_eigenvalues(K, M, 10, 0.5 * exact[0]) is None
