"""Compiled making of the sparse count's elimination plan
(:func:`linmstmm.ordered_ldlt.elimination_plan`), made for every compiled
Wittrick–Williams counter of a new pattern:

* :func:`minimum_degree` — the elimination order of D(ω)'s pattern (any order
  gives the same count);
* :func:`plan_slots` — the slots of L's pattern in that order and the updates of
  each elimination step, in one pass where numpy took a dozen calls on (n, n)
  arrays (60-90 µs of the launchers' first counter build);
* :func:`count_patterns`, :func:`pattern_with_beams`, :func:`beam_slots` and
  :func:`slot_terms` — where D(ω) may be nonzero, its pattern with the entries
  the beams reach, where each beam's entries go among the slots, and the
  springs' and bodies' terms there
  (:func:`linmstmm.wittrick_williams.sparse_plan`);
* :func:`beams_plan` — the plan of a pattern with the beams' entries and the
  beams' slots in it, those kernels in one call.

tests/test_sparse_count.py derives each in numpy and compares.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from linmstmm._compile_notice import announce_compiles

announce_compiles()  # one line on stderr if this run compiles (linmstmm._compile_notice)


@njit(cache=True)
def minimum_degree(pattern):
    """Minimum-degree elimination: at each step the unknown joined to the fewest
    others left (the lowest index among equals) is eliminated, and the others it
    is joined to are joined to each other (the fill).

    Parameters
    ----------
    pattern : (n, n) int64
        1 where the symmetric matrix may be nonzero, else 0.

    Returns
    -------
    order : (n,) int64
        The unknowns in the order eliminated.
    joined : (n, n) int64
        Row k: 1 at the unknowns k was joined to when it was eliminated (the
        pattern of its column of L below the diagonal).
    """
    n = pattern.shape[0]
    live = pattern.copy()
    joined = np.zeros((n, n), dtype=np.int64)
    degree = np.zeros(n, dtype=np.int64)
    for i in range(n):
        live[i, i] = 0
        for j in range(n):
            degree[i] += live[i, j]
    order, near = np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64)
    for step in range(n):
        k = 0
        for i in range(n):
            if degree[i] < degree[k]:
                k = i
        order[step] = k
        degree[k] = n + 1  # eliminated: above any degree
        count = 0
        for i in range(n):
            if live[k, i]:
                joined[k, i] = 1
                near[count] = i
                count += 1
        # each unknown joined to k loses k and gains the others joined to it (the
        # degrees kept up to date entry by entry: the counts a recount would give)
        for a in range(count):
            i = near[a]
            live[i, k] = 0
            degree[i] -= 1
            for b in range(count):
                j = near[b]
                if j != i and not live[i, j]:
                    live[i, j] = 1
                    degree[i] += 1
    return order, joined


@njit(cache=True)
def plan_slots(order, joined):
    """The slots of an :class:`~linmstmm.ordered_ldlt.EliminationPlan` eliminating in
    ``order`` (n,) the pattern whose rows of ``joined`` (n, n) mark the unknowns each
    one was joined to when eliminated (:func:`minimum_degree`).

    Slots run step by step: step a's diagonal, then each unknown joined to it, by
    ascending step. For every step k and each pair (s, t), t ≤ s, of its off-diagonal
    slots, s ascending and t ascending for each s, the target is the slot of
    (rows[s], rows[t]).

    Returns
    -------
    starts : (n + 1,) int64. rows : (slots,) int64, the step of each slot's row.
    high, low : (slots,) int64, its entry (high ≥ low) in the original indices.
    updates : (n + 1,) int64. targets : (pairs,) int64.
    """
    n = order.size
    step_of = np.empty(n, dtype=np.int64)
    step_of[order] = np.arange(n)
    # each step's own slot and those of the steps joined to it (read along the joins'
    # rows, then put in ascending order)
    starts = np.zeros(n + 1, dtype=np.int64)
    for a in range(n):
        count = 1
        for u in range(n):
            if u != order[a] and joined[order[a], u] > 0:
                count += 1
        starts[a + 1] = starts[a] + count
    slots = starts[n]
    rows, steps = np.empty(slots, dtype=np.int64), np.empty(slots, dtype=np.int64)
    lookup = np.full((n, n), -1, dtype=np.int64)
    met = np.empty(n, dtype=np.int64)
    for a in range(n):
        met[0], count = a, 1
        for u in range(n):
            if u != order[a] and joined[order[a], u] > 0:
                place = count  # insertion: the steps ascending
                while place > 0 and met[place - 1] > step_of[u]:
                    met[place] = met[place - 1]
                    place -= 1
                met[place] = step_of[u]
                count += 1
        for q in range(count):
            rows[starts[a] + q], steps[starts[a] + q] = met[q], a
            lookup[met[q], a] = starts[a] + q
    updates = np.zeros(n + 1, dtype=np.int64)
    for k in range(n):
        pairs = 0
        for s in range(starts[k], starts[k + 1]):
            if rows[s] != k:
                pairs += s - starts[k]
        updates[k + 1] = updates[k] + pairs
    targets = np.empty(updates[n], dtype=np.int64)
    t = 0
    for s in range(slots):
        k = steps[s]
        if rows[s] != k:
            for b in range(starts[k] + 1, s + 1):
                targets[t] = lookup[rows[s], rows[b]]
                t += 1
    high, low = np.empty(slots, dtype=np.int64), np.empty(slots, dtype=np.int64)
    for s in range(slots):
        first, second = order[rows[s]], order[steps[s]]
        high[s], low[s] = max(first, second), min(first, second)
    return starts, rows, high, low, updates, targets


@njit(cache=True)
def count_patterns(static, mass, maps, local_pattern):
    """Where D(ω) may be nonzero, in two parts: the springs' and bodies' entries, and
    each beam's (:func:`linmstmm.wittrick_williams.sparse_plan`).

    Parameters
    ----------
    static, mass : (n, n) float64
        The springs' stiffness and the bodies' mass, reduced.
    maps : (n_beams, 12, k) float64
        Each beam's map from the reduced DOFs it touches to its local ones.
    local_pattern : (12, 12) float64
        1.0 where a beam's local dynamic stiffness may be nonzero, else 0.0.

    Returns
    -------
    pattern : (n, n) bool
        ``static != 0 or mass != 0``.
    beam_pattern : (n_beams, k, k) bool
        Where ``map.T @ local @ map`` may be nonzero: some term |map[a, i]| > 0,
        local_pattern[a, c] > 0, |map[c, j]| > 0 (any other entry is a sum of zeros).
    """
    n = static.shape[0]
    pattern = np.empty((n, n), dtype=np.bool_)
    for i in range(n):
        for j in range(n):
            pattern[i, j] = static[i, j] != 0 or mass[i, j] != 0
    n_beams, local, k = maps.shape
    beam_pattern = np.zeros((n_beams, k, k), dtype=np.bool_)
    for b in range(n_beams):
        for a in range(local):
            for c in range(local):
                if local_pattern[a, c] > 0:
                    for i in range(k):
                        if np.abs(maps[b, a, i]) > 0:
                            for j in range(k):
                                if np.abs(maps[b, c, j]) > 0:
                                    beam_pattern[b, i, j] = True
    return pattern, beam_pattern


@njit(cache=True)
def pattern_with_beams(pattern, beam_pattern, columns):
    """(n, n) bool: ``pattern`` (n, n) bool with every entry (columns[b, i], columns[b, j])
    where ``beam_pattern`` (n_beams, k, k) is True (both below n: n pads), made symmetric."""
    n = pattern.shape[0]
    joined = pattern.copy()
    for b in range(columns.shape[0]):
        for i in range(columns.shape[1]):
            for j in range(columns.shape[1]):
                if beam_pattern[b, i, j] and columns[b, i] < n and columns[b, j] < n:
                    joined[columns[b, i], columns[b, j]] = True
    for i in range(n):
        for j in range(i):
            either = joined[i, j] or joined[j, i]
            joined[i, j], joined[j, i] = either, either
    return joined


@njit(cache=True)
def beam_slots(high, low, beam_pattern, columns, n):
    """(n_beams, k, k) int64: where entry (i, j) of each beam's map goes among the slots
    (``high``, ``low``) of a plan of :func:`pattern_with_beams`: its slot in the lower
    triangle, slots + its slot in the upper one, −1 for padding (a column n) and for
    entries ``beam_pattern`` leaves out."""
    lookup = np.full((n, n), -1, dtype=np.int64)
    for s in range(high.size):
        lookup[high[s], low[s]] = s
    placed = np.full(beam_pattern.shape, -1, dtype=np.int64)
    for b in range(columns.shape[0]):
        for i in range(columns.shape[1]):
            for j in range(columns.shape[1]):
                a, c = columns[b, i], columns[b, j]
                if beam_pattern[b, i, j] and a < n and c < n:
                    placed[b, i, j] = lookup[max(a, c), min(a, c)] + (high.size if a < c else 0)
    return placed


@njit(cache=True)
def slot_terms(static, mass, high, low):
    """(4, slots): ``static`` and ``mass`` (n, n) at the slots (``high``, ``low``) in the
    lower triangle, then in the upper one (0.0 on the diagonal)."""
    terms = np.zeros((4, high.size))
    for s in range(high.size):
        i, j = high[s], low[s]
        terms[0, s], terms[1, s] = static[i, j], mass[i, j]
        if i > j:
            terms[2, s], terms[3, s] = static[j, i], mass[j, i]
    return terms


@njit(cache=True)
def beams_plan(pattern, beam_pattern, columns):
    """The :class:`~linmstmm.ordered_ldlt.EliminationPlan` of ``pattern`` (n, n) bool with
    the entries the beams reach (:func:`pattern_with_beams`), as
    :func:`~linmstmm.ordered_ldlt.elimination_plan` makes it, and the beams' slots in it
    (:func:`beam_slots`), in one call.

    Returns
    -------
    order, starts, rows, high, low, updates, targets : int64 arrays
        The plan's fields, in that order.
    placed : (n_beams, k, k) int64
        :func:`beam_slots` of the plan.
    """
    order, joined = minimum_degree(pattern_with_beams(pattern, beam_pattern, columns).astype(np.int64))
    starts, rows, high, low, updates, targets = plan_slots(order, joined)
    return order, starts, rows, high, low, updates, targets, beam_slots(high, low, beam_pattern, columns,
                                                                       pattern.shape[0])
