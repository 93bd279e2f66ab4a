"""The lowest eigenvalues of a large sparse symmetric pencil, and their Ritz vectors, by
block shift-invert Lanczos.

For K x = λ M x (K symmetric positive semi-definite, M positive definite, both
sparse) and a shift s >= 0 (0 only where K is positive definite), the operator
A = (K + s M)⁻¹ M is self-adjoint in the M inner product, and its largest
eigenvalues θ = 1 / (λ + s) are the pencil's lowest λ. One sparse LU factor of
K + s M (SuperLU, symmetric mode) serves every step; each step solves for a
whole block of vectors in one call, orthogonalises the new block against the
last two (the Lanczos recurrence) and once more against every earlier one
(full reorthogonalisation: no spurious copies), and normalises it in the M
inner product (Cholesky). The Rayleigh quotient T of the basis gives the Ritz
values; the subspace grows until each wanted one is within PRECISION of an
eigenvalue. Their Ritz vectors, the basis times T's eigenvectors, come where asked
for (:func:`lowest_modes`).

The accuracy asked for is that of a prediction, not of machine precision: a
residual r of a Ritz value θ puts an eigenvalue within r of θ, and within r²/g
where the others are g or more away (Kato–Temple, g taken from the Ritz
values); the lesser of the two is the error estimate. Blocks of several vectors
find multiple eigenvalues up to the block's size, which a single-vector Lanczos
(ARPACK's) finds only by rounding.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg

#: Vectors per block: one solve for all of them (SuperLU's cost per vector falls from
#: 50 µs alone to 22 µs in fours on the second launcher's 1,284 unknowns), and
#: multiple eigenvalues found up to this multiplicity.
BLOCK = 4
#: Estimated error of a Ritz value, relative to it, at which it is taken (see the
#: module's note): far below the predicting meshes' own error (1e-3 by the hundredth).
#: Not looser, though only the secant's paths depend on it: from predictions 1e-5
#: off they took 1.4 % more evaluations over both launchers' 50 to 120 lowest, and
#: launcher 2's hundred lowest strayed to a root float64 could not certify (a pair
#: 4e-7 apart, refined in mpmath: 1.3 s), as with 1e-6 and 1e-7; from 1e-8, as from
#: ARPACK's, only its 120 lowest did.
PRECISION = 1e-8
#: The subspace's size, per wanted eigenvalue, at its first convergence check: the
#: launchers' predicting meshes needed 1.5 (90 wanted) to 1.7 (68 wanted); each
#: check costs a dense eigensolve of the Rayleigh quotient (2 ms at 180).
FIRST_CHECK = 1.7
#: The subspace's largest size, per wanted eigenvalue (and at least FEWEST_MOST), beyond
#: which there is no answer: its basis is allocated at that size (n of them on a pencil
#: of n unknowns took n² floats, 3.2 GB on 20,000), and the launchers' meshes converge
#: by 1.7 per wanted.
MOST_PER_WANTED = 8
FEWEST_MOST = 64
#: Between checks the subspace grows by this fraction of itself (at least a block).
GROWTH = 0.125
#: A new block whose M-norms' Cholesky factor has a diagonal ratio below this is
#: numerically dependent on the basis (the Krylov space is nearly invariant): no answer.
DEPENDENT = 1e-7


def lowest_eigenvalues(K, M, count: int, shift: float, seed: int = 0) -> np.ndarray | None:
    """The ``count`` lowest eigenvalues of the pencil (K, M), or None where this
    method gives no answer.

    Parameters
    ----------
    K, M : scipy.sparse matrix, shape (n, n)
        Symmetric; M positive definite, K + shift M positive definite. Any units
        (the eigenvalues come in K's over M's).
    count : int
        Eigenvalues wanted, 1 <= count < n.
    shift : float
        In the eigenvalues' units, >= 0: the operator is (K + shift M)⁻¹ M.
    seed : int
        The random start block's seed (the same start, the same answer, every run).

    Returns
    -------
    numpy.ndarray, shape (count,), ascending; or None where the subspace would
    outgrow the pencil (or MOST_PER_WANTED vectors per wanted eigenvalue) before
    converging, K + shift M is singular, or the basis becomes numerically dependent.
    """
    converged = _converged(K, M, count, shift, seed)
    return None if converged is None else np.sort(1.0 / converged[0] - shift)


def lowest_modes(K, M, count: int, shift: float, seed: int = 0) -> tuple[np.ndarray, np.ndarray] | None:
    """:func:`lowest_eigenvalues` with their Ritz vectors: (eigenvalues (count,),
    ascending; vectors (n, count), M-orthonormal, one per column), or None where
    that gives no answer.

    A Ritz vector whose value is within PRECISION of an eigenvalue lies about the
    square root of that from the eigenvector (of a simple eigenvalue), which the
    predictions' Rayleigh refinement takes from there (:mod:`linmstmm.rayleigh`).
    The arguments are :func:`lowest_eigenvalues`'.
    """
    converged = _converged(K, M, count, shift, seed)
    if converged is None:
        return None
    theta, coefficients, basis = converged  # θ descending: the eigenvalues ascending
    return 1.0 / theta - shift, basis.T @ coefficients


def _converged(K, M, count: int, shift: float, seed: int):
    """(the ``count`` largest Ritz values θ (count,), descending; their coefficients on
    the basis (m, count); the M-orthonormal basis (m, n), one vector per row) once each
    is within PRECISION of an eigenvalue of (K + shift M)⁻¹ M; None where
    :func:`lowest_eigenvalues` gives no answer (its arguments)."""
    from scipy.sparse.linalg import splu  # imported where used: the command line starts without it

    n = K.shape[0]
    capacity = min(n - n % BLOCK, max(MOST_PER_WANTED * count, FEWEST_MOST) // BLOCK * BLOCK)
    check = max(int(FIRST_CHECK * count), count + BLOCK)
    if check > capacity:
        return None
    try:
        factor = splu((K + shift * M).tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                      options={"SymmetricMode": True})
    except RuntimeError:  # exactly singular
        return None
    basis, m_basis = np.empty((capacity, n)), np.empty((capacity, n))
    rayleigh = np.zeros((capacity, capacity))  # its upper triangle
    block = np.random.default_rng(seed).standard_normal((BLOCK, n))
    size = 0
    while size + BLOCK <= capacity:
        m_block = (M @ block.T).T
        lower = _m_normalising_factor(block, m_block)
        if lower is None:
            return None
        if size >= check:
            theta, coefficients, error = _ritz_values(rayleigh[:size, :size], lower, count)
            if np.all(error <= PRECISION * theta):
                return theta, coefficients, basis[:size]
            check = size + max(BLOCK, int(GROWTH * size))
        inverse = scipy.linalg.lapack.dtrtri(lower, lower=1)[0]
        rows = slice(size, size + BLOCK)
        basis[rows], m_basis[rows] = inverse @ block, inverse @ m_block
        block = _orthogonalised(factor.solve(m_basis[rows].T).T, basis, m_basis, rayleigh, size)
        size += BLOCK
    return None


def _m_normalising_factor(block: np.ndarray, m_block: np.ndarray) -> np.ndarray | None:
    """L, lower triangular (b, b), with ``block`` M ``block``ᵀ = L Lᵀ (rows (b, n),
    ``m_block`` their images under M); None where the rows are numerically dependent."""
    gram = block @ m_block.T
    try:
        lower = np.linalg.cholesky(gram)
    except np.linalg.LinAlgError:
        return None
    diagonal = np.abs(np.diag(lower))
    return lower if diagonal.min() > DEPENDENT * diagonal.max() else None


def _orthogonalised(images: np.ndarray, basis: np.ndarray, m_basis: np.ndarray,
                    rayleigh: np.ndarray, size: int) -> np.ndarray:
    """The operator's ``images`` (b, n) of the basis's newest block (rows ``size`` on),
    less their M-projection on the basis's first ``size + b`` rows: first on the
    last two blocks (the recurrence), then on all (full reorthogonalisation). The
    projections' coefficients are the new block's columns of the Rayleigh quotient,
    added into ``rayleigh``."""
    top = size + images.shape[0]
    recent = slice(max(size - images.shape[0], 0), top)
    local = m_basis[recent] @ images.T
    images = images - local.T @ basis[recent]
    full = m_basis[:top] @ images.T
    images -= full.T @ basis[:top]
    rayleigh[:top, size:top] += full
    rayleigh[recent, size:top] += local
    return images


def _ritz_values(rayleigh: np.ndarray, lower: np.ndarray, count: int):
    """(the ``count`` largest Ritz values θ (count,), descending; their vectors'
    coefficients on the basis (m, count); each one's error estimate (count,)) of the
    basis whose Rayleigh quotient's upper triangle is ``rayleigh`` (m, m), m > count:
    the error the lesser of its residual's M-norm r (the next block's factor
    ``lower`` (b, b) applied to its Ritz vector's coefficients on the newest block)
    and r² over the distance to the nearest other Ritz value."""
    theta, vectors = scipy.linalg.eigh(rayleigh, lower=False, driver="evd")
    theta, vectors = theta[::-1], vectors[:, ::-1][:, :count]
    residual = np.linalg.norm(lower.T @ vectors[-lower.shape[0]:], axis=0)
    apart = -np.diff(theta)
    gap = np.minimum(np.append(np.inf, apart[:count - 1]), apart[:count])
    return theta[:count], vectors, np.minimum(residual, residual ** 2 / np.maximum(gap, np.finfo(float).tiny))
