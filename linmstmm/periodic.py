"""Repeated cells: a run of identical elements carried by powers of its cell matrix.

A chain of N identical links (a spring–mass chain, a row of equal bays)
repeats the same p elements R times. Carrying the state through them one
element at a time costs R·p steps per evaluation; the cell's transfer
matrix C(ω) = U_p ⋯ U_1 raised by repeated squaring needs about log2 R
products, and the state takes one product per set bit of R.

Squaring forms C^(2^j) without the orthonormalisation that keeps decaying
solutions alive in the element-by-element carry, so a power is used only
while that is harmless. Transfer matrices of conservative elements are
symplectic, Pᵀ J P = J (J the energy pairing of the state), and the pairing
growth max (|P|ᵀ |J| |P|) over the paired entries of J says how much
cancellation that identity needs: relative rounding errors ε in P's entries
become errors ε·growth in it. It is 1 for the identity and for a pure
stretch diag(λ, 1/λ) (which loses nothing), and grows like λ² where growing
and decaying solutions mix, as they do when decaying digits are lost.
Powers beyond PAIRING_LIMIT are not formed; if the cell itself exceeds it,
the run is carried element by element as before.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from linmstmm.elements.frames import FORCE_INDEX, SYMPLECTIC_FORM

#: Largest pairing growth of a power used: at most four digits of the
#: decaying solutions, as GROWTH² does in the element-by-element carry.
PAIRING_LIMIT = 1e4
#: Shortest run (repetitions of its cell) worth powering.
MIN_REPETITIONS = 8
#: Longest cell looked for, elements.
MAX_PERIOD = 4
#: Entries of an element's :func:`signatures`.
SIGNATURE_SIZE = 17
#: Cells whose signatures agree to this (relative to each quantity's size) are equal.
SAME = 1e-14


@dataclass(frozen=True)
class Run:
    """``repetitions`` copies of the elements ``cell`` (topology ids, in carry
    order) starting at position ``start`` of the carry order."""

    start: int
    cell: tuple
    repetitions: int

    @property
    def stop(self) -> int:
        """Position in the carry order just after the run."""
        return self.start + len(self.cell) * self.repetitions


def find_runs(topology) -> list[Run]:
    """Runs of a repeated cell of single-input rigid bodies, springs and junctions
    (not joints: a released direction adds an unknown and a row of its own).

    Inside a run every element's only input is the previous element's output,
    and equal cells have equal :func:`signatures` (to 1e-14 of each quantity's
    own size): the data their transfer matrices are made of. Runs are taken
    greedily along the carry order: at each position the run covering the most
    elements (the shortest cell among equals), if any, and on after its end.
    """
    order = topology.order
    ordered = [topology.elements[e] for e in order]
    size = len(order)
    chained = np.array([element.kind != "beam" and len(element.inputs) == 1
                        and not (element.kind == "spring" and element.record.released.size)
                        for element in ordered], dtype=bool)
    entered = [element.ports[element.inputs[0]].link for element in ordered]  # each element's first input
    follows = np.array([False] + [link[0] == "element" and link[1] == before
                                  for link, before in zip(entered[1:], order)], dtype=bool)
    values, scales = signatures(ordered, chained)
    chained_from, following_from = _streaks(chained, size + 1), _streaks(follows, size + 1)
    covered, period_of = np.zeros(size, dtype=int), np.zeros(size, dtype=int)
    for period in range(1, min(MAX_PERIOD, size - 1) + 1):
        # good[j]: element j + period repeats element j and is chained to its predecessor
        tolerance = SAME * np.maximum(scales[:-period], scales[period:])
        good = (np.all(np.abs(values[:-period] - values[period:]) <= tolerance, axis=1)
                & chained[period:] & follows[period:])
        repetitions = 1 + _streaks(good, size)[:size] // period
        # a cell at i: chained elements i .. i + period - 1, each after the one before
        cell = (chained_from[:size] >= period) & (following_from[1:] >= period - 1)
        cover = np.where(cell & (repetitions >= MIN_REPETITIONS), repetitions * period, 0)
        longer = cover > covered
        covered[longer], period_of[longer] = cover[longer], period
    runs, starts = [], np.flatnonzero(covered)
    i = 0
    while (k := np.searchsorted(starts, i)) < starts.size:
        i, period = int(starts[k]), int(period_of[starts[k]])
        runs.append(Run(i, tuple(order[i:i + period]), int(covered[i]) // period))
        i += int(covered[i])
    return runs


def _streaks(good: np.ndarray, length: int) -> np.ndarray:
    """(length,) int: at j, how many consecutive entries of ``good`` (bool, (n,), n < length)
    are True from j on; 0 from n on. Counted on the reversed array, where it is the
    distance back to the last False (a loop over a 10,000-body chain's entries took
    tens of milliseconds per period)."""
    reversed_good = good[::-1]
    position = np.arange(good.size)
    last_false = np.maximum.accumulate(np.where(reversed_good, -1, position)) if good.size else position
    streak = np.zeros(length, dtype=int)
    streak[:good.size] = (position - last_false)[::-1]
    return streak


def signatures(elements, chained) -> tuple[np.ndarray, np.ndarray]:
    """(values, scales), each (n, SIGNATURE_SIZE): what each element's transfer matrix is
    made of, and the size each value is compared at.

    A rigid body: mass (kg), inertia about its mass centre (kg m²), mass centre and
    output port from the input port (m); a spring: compliances 1/k (0 where rigid)
    and its axes. Differences of positions, not positions: a chain's cells far from
    the origin are equal to their size, not to the origin's distance. Elements not
    ``chained`` get NaN (equal to nothing); the first entry tells the kinds apart.
    The records' arrays are gathered in lists and converted once (a chain has
    thousands: one numpy call per element took most of the time).
    """
    values = np.full((len(elements), SIGNATURE_SIZE), np.nan)
    scales = np.zeros((len(elements), SIGNATURE_SIZE))
    kinds = [element.kind if ok else "" for element, ok in zip(elements, chained.tolist())]
    rigid = [i for i, kind in enumerate(kinds) if kind == "rigid"]
    if rigid:
        bodies = [elements[i] for i in rigid]
        start = np.array([body.ports[body.inputs[0]].position for body in bodies], dtype=float)
        arms = np.hstack([np.array([body.record.com for body in bodies], dtype=float) - start,
                          np.array([body.ports[body.output].position for body in bodies], dtype=float) - start])
        mass = np.array([body.record.mass for body in bodies], dtype=float)
        inertia = np.array([body.record.inertia for body in bodies], dtype=float).reshape(len(bodies), 9)
        values[rigid] = np.hstack([np.ones((len(rigid), 1)), mass[:, None], inertia, arms])
        scales[rigid, 1:] = np.hstack([np.abs(mass)[:, None],
                                       np.repeat(np.abs(inertia).max(axis=1, keepdims=True), 9, axis=1),
                                       np.repeat(np.abs(arms).max(axis=1, keepdims=True), 6, axis=1)])
    spring = [i for i, kind in enumerate(kinds) if kind == "spring"]
    if spring:
        records = [elements[i].record for i in spring]
        compliance = 1 / np.array([record.k for record in records], dtype=float)
        axes = np.array([record.axes for record in records], dtype=float).reshape(len(spring), 9)
        values[spring] = np.hstack([np.full((len(spring), 1), 2.0), compliance, axes, np.zeros((len(spring), 1))])
        scales[spring, 1:16] = np.hstack([np.repeat(np.abs(compliance).max(axis=1, keepdims=True), 6, axis=1),
                                          np.ones((len(spring), 9))])
    junction = [i for i, kind in enumerate(kinds) if kind == "junction"]
    values[junction] = 0.0
    values[junction, 0] = 3.0
    return values, scales


def pairing_growth(power: np.ndarray) -> np.ndarray:
    """(n,) max over the paired entries (a, FORCE_INDEX[a]) of |P|ᵀ |J| |P|, for a
    stack (n, 12, 12) of symplectic matrices (dimensionless: each term pairs a
    displacement with a force)."""
    size = np.abs(power)
    pairing = np.swapaxes(size, 1, 2) @ np.abs(SYMPLECTIC_FORM) @ size
    return pairing[:, np.arange(6), FORCE_INDEX].max(axis=1)


def carry_run(cell_matrix: np.ndarray, repetitions: int, matrix: np.ndarray, settle):
    """State (n, 12, k) carried through ``repetitions`` cells, or None if the cell
    itself is too ill-conditioned to power (carry element by element then).

    cell_matrix : (n, 12, 12) C(ω). settle : callable (n, 12, k) -> (n, 12, k),
    applied after each product (the carry's growth check and orthonormalisation).
    """
    if np.max(pairing_growth(cell_matrix)) > PAIRING_LIMIT:
        return None
    powers = [cell_matrix]
    while 2 ** len(powers) <= repetitions:
        square = powers[-1] @ powers[-1]
        if np.max(pairing_growth(square)) > PAIRING_LIMIT:
            break
        powers.append(square)
    remaining = repetitions
    for j in range(len(powers) - 1, -1, -1):
        while remaining >= 2 ** j:
            matrix = settle(powers[j] @ matrix)
            remaining -= 2 ** j
    return matrix
