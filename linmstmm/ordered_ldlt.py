"""A fill-reducing elimination order of a symmetric matrix with a fixed sparsity
pattern, and the plan of its LDLᵀ factorisation without pivoting in that order.

The reduced dynamic stiffness D(ω) of :mod:`linmstmm.wittrick_williams` has the
same pattern at every ω (springs, rigid bodies and one element per beam): the
72 and 96 unknowns of the bundled launchers have 684 and 872 nonzeros. Eliminated
in a minimum-degree order, the factor L has 326 and 476 entries below the
diagonal (the dense factorisation works on 2,556 and 4,560), and the plan made
here once per pattern lets :func:`linmstmm._stiffness_kernels.ordered_count`
assemble and factorise D(ω) on those entries alone (971 and 1,568 updates).

Without pivoting the factorisation may meet a small pivot; the compiled count
then falls back on the dense Bunch–Kaufman factorisation (see there). By
Sylvester's law of inertia the order does not change the count.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from linmstmm._ordering_kernels import minimum_degree, plan_slots


@dataclass(frozen=True)
class EliminationPlan:
    """LDLᵀ of an (n, n) symmetric pattern in a fixed order, as the compiled count
    takes it.

    The entries of L's pattern (the pattern and its fill, lower triangle, diagonal
    included) are "slots", column by column in the elimination order, each
    column's diagonal first.

    Attributes
    ----------
    order : (n,) int64
        The unknowns in the order they are eliminated.
    starts : (n + 1,) int64
        Slots of the k-th eliminated column: ``starts[k]`` (its diagonal) to
        ``starts[k + 1]``.
    rows : (slots,) int64
        Elimination step of each slot's row.
    high, low : (slots,) int64
        The slot's entry of the matrix as (high, low) original indices, high ≥ low.
    updates : (n + 1,) int64
        Pointers into ``targets``, one range per elimination step.
    targets : (pairs,) int64
        For step k and each pair (a, b), b ≤ a, of its off-diagonal slots in
        order: the slot of (rows[a], rows[b]) that ``L[a] d L[b]`` is taken from.
    """

    order: np.ndarray
    starts: np.ndarray
    rows: np.ndarray
    high: np.ndarray
    low: np.ndarray
    updates: np.ndarray
    targets: np.ndarray


def elimination_plan(pattern: np.ndarray) -> EliminationPlan:
    """The :class:`EliminationPlan` of the symmetric boolean (n, n) ``pattern`` in
    its :func:`~linmstmm._ordering_kernels.minimum_degree` order
    (:func:`~linmstmm._ordering_kernels.plan_slots` lays out its slots).

    Parameters
    ----------
    pattern : (n, n) bool
        Where the matrix may be nonzero (symmetric).

    Returns
    -------
    EliminationPlan
    """
    order, joined = minimum_degree(pattern.astype(np.int64))
    starts, rows, high, low, updates, targets = plan_slots(order, joined)
    return EliminationPlan(order=order, starts=starts, rows=rows, high=high, low=low, updates=updates, targets=targets)
