"""Eigenspaces of Ū_all: at a natural frequency ω the null space of Ū_all(ω)
holds the boundary unknowns z̄ of the modes, a whole basis for a repeated
frequency (roots closer than SAME_FREQUENCY are one), found on Ū_all scaled
by its neighbours at ω(1 ± SCALE_PROBE).
"""
from __future__ import annotations

import numpy as np
import scipy.linalg

from linmstmm.deduction import Deduction
from linmstmm.nullspace import NULL_TOLERANCE, characteristic_frequencies, equilibration, own_units_start

#: Frequencies closer than this (relative) are one repeated frequency.
SAME_FREQUENCY = 1e-9
#: Relative frequency offset of the matrices that scale Ū_all for its null space.
SCALE_PROBE = 1e-3
#: Entries of the Ū_all matrices :func:`null_bases` asks for in one call, at most
#: (unless one eigenspace's three need more): 32 MB in float64.
BATCH_ENTRIES = 1 << 22


def _group(omegas) -> list[tuple[float, int]]:
    """(ω, multiplicity) from an ascending list that repeats each root per multiplicity."""
    groups: list[tuple[float, int]] = []
    for omega in omegas:
        if groups and abs(omega - groups[-1][0]) <= SAME_FREQUENCY * omega:
            groups[-1] = (groups[-1][0], groups[-1][1] + 1)
        else:
            groups.append((float(omega), 1))
    return groups


def _whole_last_eigenspace(finder, omegas: np.ndarray) -> np.ndarray:
    """``omegas`` (rad/s, ascending) with the last root repeated up to its multiplicity.

    The multiplicity is the finder's count of roots around it
    (:meth:`~linmstmm.roots.RootFinder.multiplicity`), as the mpmath
    refinement of a root cut by the count takes it; the roots before it are
    left exactly as found.
    """
    last = omegas[-1]
    present = int(np.count_nonzero(np.abs(omegas - last) <= SAME_FREQUENCY * last))
    wanted = finder.multiplicity(last, sorted(set(omegas))) or present
    return np.r_[omegas, np.full(max(wanted - present, 0), last)]


def null_bases(deduction: Deduction, eigenspaces: list[tuple[float, int]], plain=None) -> np.ndarray:
    """(Σ dimensions, N) the :func:`_null_basis` of each (ω rad/s, dimension) of
    ``eigenspaces``, in order, one above the other.

    Ū_all at every frequency they look at comes from one call: ``plain`` (a compiled
    determinant's :meth:`~linmstmm.determinant.CompiledDeterminant.plain_matrix`, the
    same to rounding and some ten times faster) where given, else ``deduction.matrix``
    (one batch of the numpy carry, vectorised over the frequencies); at ω = 0 always
    the latter.
    """
    bases = [np.zeros((0, deduction.full_order))]
    start = own_units_start(deduction)  # the same for every eigenspace
    batch = max(1, BATCH_ENTRIES // max(3 * deduction.order ** 2, 1))  # eigenspaces a call serves
    for first in range(0, len(eigenspaces), batch):
        part = eigenspaces[first:first + batch]
        probes = np.concatenate([_probes(deduction, omega) for omega, _ in part])
        matrices = np.empty((probes.size, deduction.order, deduction.order))
        by_carry = np.repeat([plain is None or omega == 0 for omega, _ in part], 3)
        for source, chosen in ((deduction.matrix, by_carry), (plain, ~by_carry)):
            if chosen.any():
                matrices[chosen] = source(probes[chosen])
        bases += [_null_basis(deduction, omega, matrices[3 * k:3 * k + 3], dimension, start)
                  for k, (omega, dimension) in enumerate(part)]
    return np.concatenate(bases)


def _probes(deduction: Deduction, omega: float) -> np.ndarray:
    """(3,) rad/s: ``omega`` and the two frequencies that scale Ū_all there (:func:`_null_basis`)."""
    near = omega if omega > 0 else SCALE_PROBE * min(characteristic_frequencies(deduction.topology))
    return np.array([omega, near * (1 - SCALE_PROBE), near * (1 + SCALE_PROBE)])


def _null_basis(deduction: Deduction, omega: float, matrices: np.ndarray, dimension: int, start) -> np.ndarray:
    """(dimension, N) basis of the null space of Ū_all(omega), on all N unknowns, from
    ``matrices`` (3, N', N'): Ū_all (less released unknowns) at the three frequencies
    of :func:`_probes`, omega first; ``start``: the deduction's
    :func:`~linmstmm.nullspace.own_units_start`.

    Works on the equilibrated matrix S = ``rows · Ū · cols`` (the basis is
    mapped back by ``cols``), whose scales come from Ū at ω(1 ± SCALE_PROBE) (at
    ω = 0 from SCALE_PROBE times the model's own frequency scale, as each ω² term
    vanishes there: a free ring's six rigid-body modes were hidden so),
    balanced from the model's own units (the same in any units):
    at the root itself an entry that vanishes there (cos kL of a rod at
    resonance) would be blown up to ~1 when alone in its row, hiding the
    singularity. The SVD of S gives the left and right singular vectors u, v
    of the ``dimension`` smallest singular values; the basis then solves the
    bordered system [[S, u], [vᵀ, 0]] [x; λ] = [0; I]. The SVD alone mixes all
    columns with errors eps ‖S‖ / σ_next, and σ_next is as small as
    1/cosh(βL) for a beam; elimination keeps blocks that do not couple
    (bending, torsion) exactly apart. Released (statically indeterminate)
    unknowns are zero. Raises RuntimeError if any of the ``dimension``
    singular values is not below NULL_TOLERANCE × the largest.
    """
    matrix, below, above = matrices
    rows, cols = equilibration(np.maximum(np.abs(below), np.abs(above)), start=start)
    scaled = rows[:, None] * matrix * cols
    u, sigma, vh = np.linalg.svd(scaled)
    worst = sigma[sigma.size - dimension] / sigma[0]
    if worst > NULL_TOLERANCE:
        raise RuntimeError(f"ω = {omega:.12g} rad/s is not a natural frequency with a null space "
                           f"of dimension {dimension}: relative singular value {worst:.3g}")
    n = sigma.size
    try:
        basis = _bordered_null_vectors(scaled, u, vh, dimension)
    except np.linalg.LinAlgError:  # other near-null directions than the root's: all of them, then the root's
        near = int(np.sum(sigma < NULL_TOLERANCE * sigma[0]))
        basis = _closest_null_vectors(_bordered_null_vectors(scaled, u, vh, near), u[:, n - near:], scaled,
                                      rows[:, None] * (above - below) * cols, dimension)
    full = np.zeros((dimension, deduction.full_order))
    full[:, np.delete(np.arange(n + len(deduction.released_columns)), deduction.released_columns)] = (
        np.linalg.qr(basis)[0].T * cols)
    return full


def _bordered_null_vectors(scaled: np.ndarray, u: np.ndarray, vh: np.ndarray, k: int) -> np.ndarray:
    """(N, k) null vectors of ``scaled`` (N, N) from the bordered system [[S, u], [vᵀ, 0]]
    on its last ``k`` left and right singular vectors (``u``, ``vh`` of its SVD).
    Raises LinAlgError where that system is singular."""
    n = scaled.shape[0]
    bordered = np.block([[scaled, u[:, n - k:]], [vh[n - k:], np.zeros((k, k))]])
    return np.linalg.solve(bordered, np.eye(n + k, k, -n))[:n]


def _closest_null_vectors(candidates: np.ndarray, left: np.ndarray, scaled: np.ndarray,
                          change: np.ndarray, dimension: int) -> np.ndarray:
    """(N, dimension): the combinations of ``candidates`` (N, k), k > dimension near-null
    vectors of the equilibrated Ū_all ``scaled`` (N, N), that belong to the root itself.

    Far above a beam's first modes the blocks of Ū_all of its other deformations are
    nearly singular too (a bending block's smallest singular value is about 1/cosh βL
    of its largest), below NULL_TOLERANCE, so the SVD offers their directions with
    the root's own. Newton's offsets tell them apart: on the candidates (projected on
    the near-null left vectors ``left`` (N, k)), the generalized eigenvalues μ of
    (Ū_all, ``change``) are the steps to the nearest root along each (``change``: the
    equilibrated Ū_all(ω(1 + p)) − Ū_all(ω(1 − p)), proportional to dŪ/dω). The
    root's own have μ ≈ 0; a nearly singular block's μ is the distance to its own
    root, or infinite. The ``dimension`` smallest are taken.
    """
    pencil = left.conj().T @ scaled @ candidates, left.conj().T @ change @ candidates
    mu, vectors = scipy.linalg.eig(*pencil)
    mu = np.where(np.isfinite(mu), np.abs(mu), np.inf)
    chosen = vectors[:, np.argsort(mu)[:dimension]]
    # (a real pencil's eigenvectors of real μ are real: LAPACK's, packed as complex)
    return candidates @ (chosen.real if np.isrealobj(scaled) else chosen)
