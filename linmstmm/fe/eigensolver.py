"""The lowest elastic eigenpairs: Lanczos (ARPACK) on ``K⁺M`` or the dense
condensed start, polished by subspace iteration with Rayleigh–Ritz energies
computed from the element forces of the flexibility solve (:func:`fe_modes`)."""
from __future__ import annotations

import numpy as np
import scipy.linalg as la
from scipy.sparse.linalg import LinearOperator, eigsh

from linmstmm.fe.assembly import FEModel
from linmstmm.fe.condensation import _dense_start
from linmstmm.fe.flexibility import _Flexibility

#: Reduced systems at most this large take the dense eigensolver.
DENSE_LIMIT = 120
#: A direction of a subspace whose M-norm, as its basis is orthonormalised, is at most
#: this fraction of the largest is rounding, and dropped (:func:`_mass_orthonormal`).
INDEPENDENT = 1e-13
#: Polishing sweeps stop when no wanted λ changes by more than this (relative).
SWEEP_TOLERANCE = 1e-14


def _rayleigh_ritz(fe: FEModel, Y: np.ndarray, strains: np.ndarray):
    """Ritz pairs of span(Y), energies from the strains of Y.

    Y : (n_dof, b) displacements; strains : (n_strain, b) their ``D^½ G Y``
    as :meth:`_Flexibility.solve` gives them (carried through every linear
    combination of Y, never recomputed from the combined vectors).

    Returns ascending λ (rad²/s²) and mass-normalised vectors (n_dof, m);
    directions of span(Y) without mass are dropped.
    """
    for independent in (INDEPENDENT, 0.0):  # the second pass makes the first's basis orthonormal to rounding
        Y, strains = _mass_orthonormal(fe, Y, strains, independent)
    _, C = la.eigh(strains.T @ strains)
    X, strains = Y @ C, strains @ C
    masses = np.sqrt(np.einsum("ij,ij->j", X, fe.M @ X))
    X, strains = X / masses, strains / masses
    lam = np.sum(strains ** 2, axis=0)
    order = np.argsort(lam)
    return lam[order], X[:, order]


def _mass_orthonormal(fe: FEModel, Y: np.ndarray, strains: np.ndarray, independent: float):
    """(Y @ B, strains @ B): span(Y) in a basis nearly orthonormal in M, directions whose
    M-norm is at most ``independent`` times the largest dropped (rounding of the others).

    The directions are the eigenvectors of the Gram matrix Yᵀ M Y of the columns
    normalised; each is normalised by its own M-norm, computed from the combined
    vector, not by the Gram eigenvalue: that is the norm squared, lost under
    rounding below 1e-16 of the largest. Inverse iteration shrinks a stiff
    direction by λ_soft/λ_stiff per sweep (1e-11 for two masses on springs
    1e11 apart): the eigenvalue read 4e-16 where 1e-22 was right, and a cut of
    the eigenvalues at 1e-12 dropped the stiff mode.
    """
    norms = np.sqrt(np.maximum(np.einsum("ij,ij->j", Y, fe.M @ Y), 0.0))
    keep = norms > 0.0
    Y, strains = Y[:, keep] / norms[keep], strains[:, keep] / norms[keep]
    gram = Y.T @ (fe.M @ Y)
    _, directions = la.eigh(0.5 * (gram + gram.T))
    Z = Y @ directions
    norms = np.sqrt(np.maximum(np.einsum("ij,ij->j", Z, fe.M @ Z), 0.0))
    keep = norms > independent * norms.max(initial=0.0)
    combination = directions[:, keep] / norms[keep]
    return Y @ combination, strains @ combination


def _lanczos_start(fe: FEModel, flexibility, block: int) -> np.ndarray:
    """The ``block`` lowest elastic modes, approximately, by ARPACK on K⁺M."""
    n = fe.n_dof
    operator = LinearOperator((n, n), matvec=flexibility, dtype=float)
    start = np.random.default_rng(0).standard_normal(n)
    _, X = eigsh(fe.K, k=block, M=fe.M, sigma=0.0, which="LM", OPinv=operator,
                 v0=start, ncv=_lanczos_vectors(n, block))
    return X


def _lanczos_vectors(n_dof: int, block: int) -> int:
    """ARPACK's ``ncv`` for ``block`` modes of an ``n_dof`` model."""
    return min(n_dof, max(2 * block + 1, 20))


def _massive_dofs(fe: FEModel) -> int:
    """DOFs that carry mass, less the rigid-body modes: at least the number of
    elastic modes and the rank of K⁺M. A Krylov space of K⁺M cannot grow past
    that rank, so ARPACK asked for more vectors than that stops ("could not build
    an Arnoldi factorization": random trees at 80 modes, 204 DOFs of which 198
    carry mass, 201 vectors)."""
    return len(fe.massive) - fe.rigid_modes.shape[1]


def _block_size(wanted: int) -> int:
    """Wanted modes plus guard vectors, so an edge cluster is not split."""
    return wanted + max(4, wanted // 4)


def _lowest_modes(fe: FEModel, flexibility, wanted: int, sweeps: int = 8):
    """The ``wanted`` lowest elastic modes, polished by subspace iteration.

    A block of :func:`_block_size` vectors is started by Lanczos (densely for
    small models) and refined by inverse iteration with Rayleigh–Ritz in the
    natural factor until the wanted λ stop changing.

    Returns ascending λ (rad²/s²) of the whole block, mass-normalised vectors
    (n_dof, m), and per λ the relative change in the last sweep (the solver
    error estimate). m is below the block size when the model has fewer
    elastic modes.
    """
    block = min(_block_size(wanted), _massive_dofs(fe))
    if block <= 0:
        X = np.zeros((fe.n_dof, 0))
    elif fe.n_dof <= DENSE_LIMIT or _lanczos_vectors(fe.n_dof, block) >= _massive_dofs(fe):
        X = _dense_start(fe, flexibility)[:, :block]
    else:
        X = _lanczos_start(fe, flexibility, block)
    if X.shape[1] == 0:
        return np.zeros(0), X, np.zeros(0)
    lam, X = _rayleigh_ritz(fe, *flexibility.solve(fe.M @ X))
    for _ in range(sweeps):
        new_lam, X = _rayleigh_ritz(fe, *flexibility.solve(fe.M @ X))
        m = min(len(lam), len(new_lam))
        change = np.abs(new_lam[:m] - lam[:m]) / new_lam[:m]
        lam, X = new_lam[:m], X[:, :m]
        if change[:wanted].max(initial=0.0) <= SWEEP_TOLERANCE:
            break
    return lam, X, change


def fe_modes(fe: FEModel, count=10, lam_max=None, at_least=0):
    """Lowest elastic eigenpairs of an assembled model.

    Parameters
    ----------
    count : int or None, the lowest ``count`` modes.
    lam_max : float or None, all modes with ω² <= lam_max (rad²/s²).
        Both given: whichever stops first; neither: the lowest 10.
    at_least : int, return at least this many (if the model has them).

    Returns
    -------
    lam : (m,) ascending ω², rad²/s².
    X : (n_dof, m) mass-normalised reduced mode shapes.
    solver_error : (m,) relative change of λ in the last polishing sweep.
    """
    flexibility = _Flexibility(fe)
    wanted = max(count or 10, at_least)
    while True:
        lam, X, change = _lowest_modes(fe, flexibility, wanted)
        found_all = len(lam) < _block_size(wanted)
        if count is not None or lam_max is None or found_all or lam[wanted - 1] > lam_max:
            break
        wanted *= 2
    keep = len(lam) if count is None else max(count, at_least)
    if lam_max is not None:
        keep = min(keep, max(np.searchsorted(lam, lam_max, side="right"), at_least))
    return lam[:keep], X[:, :keep], change[:keep]
