"""The numpy reference count's inertia of D(ω): its negative eigenvalues by LAPACK's
Bunch–Kaufman LDLᵀ (``?sytrf``), equilibrated so that the decision does not depend on
the units (:func:`negative_eigenvalues`); mirrored by the compiled
:func:`linmstmm._stiffness_kernels.count`. Used by
:class:`~linmstmm.wittrick_williams.ModeCounter`."""
from __future__ import annotations

import numpy as np
import scipy.linalg.lapack as lapack

#: A pivot of the equilibrated D(ω) below this, relative to the largest term that entered it, is
#: rounding: ω is at a natural frequency to float64's eyes, and the count is left undecided; D(ω) is
#: also counted shifted by ± this much, and the two counts must agree. Well above the
#: factorisation's own rounding (order n·eps, 2e-14 for the launcher's 72 unknowns). At 1e-11 the
#: counts ±1e-9 beside 5 of the launcher's 10 lowest roots were undecided (they were certified at
#: ±1e-8); at 1e-12 all 10 decide. Beside the 8 lowest roots of 77 random and varied models (6,130
#: counts 1e-9 to 1e-5 from them) 1e-11, 1e-12 and 1e-13 all gave no wrong count, leaving 2,333,
#: 1,639 and 1,189 undecided.
SINGULAR_PIVOT = 1e-12


def negative_eigenvalues(matrix: np.ndarray, magnitude: np.ndarray) -> int | None:
    """Negative eigenvalues of the symmetric ``matrix`` (Bunch–Kaufman LDLᵀ), or None
    where a pivot is rounding. Equilibrated first by the diagonal of ``magnitude``
    (the scale of every term that entered), a congruence that a change of units
    scales exactly as it scales the matrix: the pivots, and so the decision, are
    the same in every unit system (scaling by the rows' largest entries is not)."""
    if matrix.size == 0:
        return 0
    scale = magnitude.diagonal()
    if not np.all(scale > 0):
        return None                                   # a DOF with neither stiffness nor mass
    weights = 1.0 / np.sqrt(scale)
    equilibrated = matrix * weights[:, None] * weights[None, :]
    # rounding is relative to the largest term that entered, which may lie off the diagonal
    singular = SINGULAR_PIVOT * float((magnitude * weights[:, None] * weights[None, :]).max())
    shift = singular * np.eye(len(scale))
    counts = [factorised_inertia(shifted, singular) for shifted in (equilibrated + shift, equilibrated - shift)]
    # the same count shifted both ways: no eigenvalue within rounding of zero (a small
    # eigenvalue need not show as a small pivot)
    return counts[0] if counts[0] == counts[1] else None


def factorised_inertia(matrix: np.ndarray, singular: float) -> int | None:
    factor, pivots, info = lapack.dsytrf(matrix, lower=1)
    if info < 0:
        raise ValueError(f"dsytrf: argument {-info} is invalid")
    return None if info > 0 else block_inertia(factor, pivots, singular)


def block_inertia(factor: np.ndarray, pivots: np.ndarray, singular: float) -> int | None:
    """Negative eigenvalues of the block-diagonal D of LAPACK's ``?sytrf`` (lower),
    None where a 1 × 1 pivot or a 2 × 2 block's eigenvalue is below ``singular``.

    ``pivots`` (n,) is sytrf's ipiv: positive at a 1 × 1 pivot, negative on both rows
    of a 2 × 2 block, so that a run of negative entries is a run of blocks, each
    starting at an even offset into the run. All blocks at once (a Python loop over
    them cost the numpy count 2 ms in 21 on the launcher)."""
    diagonal = factor.diagonal()
    single = pivots > 0
    if single.all():  # 1 × 1 pivots only (the common case)
        return None if np.min(np.abs(diagonal)) < singular else int(np.sum(diagonal < 0))
    index = np.arange(len(pivots))
    run_start = np.maximum.accumulate(np.where(single, index + 1, 0))  # of the run of blocks a row is in
    first = ~single & ((index - run_start) % 2 == 0)                   # the rows that start a 2 × 2 block
    k = index[first]
    a, b, c = diagonal[k], factor[k + 1, k], diagonal[k + 1]
    half_trace, root = (a + c) / 2, np.hypot((a - c) / 2, b)
    eigenvalues = np.concatenate([diagonal[single], half_trace - root, half_trace + root])
    if np.min(np.abs(eigenvalues)) < singular:
        return None
    return int(np.sum(eigenvalues < 0))
