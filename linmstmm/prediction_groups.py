"""Which predictions a predicted search polishes, which stand alone or as they are, and the gaps between them.

Shared by the search itself (:mod:`linmstmm.predicted`) and the refinement of its
predictions (:mod:`linmstmm.rayleigh`), which refines those the search polishes that
no other prediction stands close to. The search also places its certifying count's
upper end (:func:`gap_above`), its segment searches (:func:`intervals_around`), where it
halves a stretch it repairs (:func:`repair_split`) and
its pencil's reach in a cluster (:func:`cluster_reach`) by the predictions' positions,
and takes a root it finds within rtol of a value that stood for that value (:class:`Stood`).
"""
from __future__ import annotations

import numpy as np

#: Predictions closer than this (relative) are a cluster: a member's secant result
#: stands only where it converged to xtol (see :func:`linmstmm.predicted._secant_polished`).
CLUSTER = 1e-3
#: Predictions above the count-th are polished only within this (relative) of it;
#: the others only place the certifying count's upper end in the gap above it
#: (the coarse model is within about 1e-2 of every root it predicts).
NEAR_COUNT = 2e-2


def clusters(predictions: np.ndarray) -> list[list[int]]:
    """Indices of ``predictions`` (ascending) grouped where neighbours are within CLUSTER."""
    groups: list[list[int]] = []
    values = predictions.tolist()
    for i, omega in enumerate(values):
        if groups and omega - values[groups[-1][-1]] <= CLUSTER * omega:
            groups[-1].append(i)
        else:
            groups.append([i])
    return groups


def near_any(root: float, roots: list[float], same: float) -> bool:
    """True if ``root`` is within ``same`` (relative) of one of ``roots``."""
    return any(abs(r - root) <= same * root for r in roots)


def clustered(predictions: np.ndarray) -> list[bool]:
    """(m,): which of ``predictions`` (ascending) share a cluster (:func:`clusters`) with another."""
    return [len(group) > 1 for group in clusters(predictions) for _ in group]


def polished_up_to(predictions: np.ndarray, count: int) -> int:
    """How many of ``predictions`` (ascending, rad/s; at least ``count``) a search for the
    lowest ``count`` polishes: those up to NEAR_COUNT above the count-th (the others only
    place its certifying count's upper end)."""
    return int(np.searchsorted(predictions, predictions[count - 1] * (1 + NEAR_COUNT), side="right"))


def standing(counter, predictions: list[float], indices, width: float) -> list[bool]:
    """For each of ``indices`` into ``predictions`` (rad/s), whether the Wittrick–Williams
    counts at ``predictions[i]`` (1 ∓ ``width``) find one natural frequency across it, so
    that a root lies within ``width`` (relative) of it, as it stands. ``counter``: the
    model's :class:`~linmstmm.wittrick_williams.ModeCounter`; it remembers its answers, so a
    second call at the same values and width counts nothing again (hence one place
    forms these frequencies: the refinement asks first, the search again). All counted
    in one batch where the counter can (``prefetch``)."""
    prefetch = getattr(counter, "prefetch", None)
    if prefetch is not None:
        prefetch([predictions[i] * (1 + sign * width) for i in indices for sign in (-1, 1)])
    stands = []
    for i in indices:
        below, above = counter(predictions[i] * (1 - width)), counter(predictions[i] * (1 + width))
        stands.append(below is not None and above is not None and above - below == 1)
    return stands


class Stood:
    """The values that stood unpolished (``stood``, rad/s; None: none may) and the ``rtol``
    the counts across each certified: the one root within rtol of such a value is its
    root, wherever a polish finds it. :meth:`absorbed` puts a root found so in the
    value's place: the pencil and the deflated secant take known roots for exact, and
    a value only within rtol of its root (one the coarse model gave, 7e-6 off), divided
    out, left a zero beside its pole, which the deflated secant took for a known root,
    or the pencil, landing there, for a new one (varied model 41's twenty lowest at
    rtol 1e-4: the segment search ran, 48 evaluations, 26 so; random ring 9's forty
    lowest: one root taken twice, then every value polished again, 370, 55 so). No two
    values that stood share a root: they stand CLUSTER apart, and rtol is 1e-4 at most."""

    def __init__(self, stood: set[float] | None, rtol: float):
        self.values, self.rtol = stood, rtol

    def absorbed(self, root: float, roots: list[float]) -> None:
        """Put ``root`` (rad/s) in ``roots`` in place of the value that stood for it, if any."""
        if not self.values:
            return
        for value in [v for v in self.values if v != root and abs(root - v) <= self.rtol * v and v in roots]:
            roots[roots.index(value)] = root
            self.values.discard(value)


def gap(predictions: list[float], i: int) -> float:
    """Distance from prediction i of ``predictions`` (ascending) to its nearest
    neighbour, one of the two beside it (its own size if alone)."""
    beside = [abs(predictions[j] - predictions[i]) for j in (i - 1, i + 1) if 0 <= j < len(predictions)]
    return min(beside) if beside else predictions[i]


def gap_above(roots: list[float], count: int, same: float, beyond: list[float]) -> float:
    """Upper end of the certifying count: between the count-th root and the next
    distinct one (farther than ``same``, relative: a multiple root the count cuts
    is counted whole), a root or one of the unpolished predictions ``beyond`` (rad/s),
    or a little above the last if there is none."""
    last = roots[count - 1]
    above = [r for r in [*roots[count:], *beyond] if r > last * (1 + same)]
    return float(np.sqrt(last * min(above))) if above else float(last * (1 + CLUSTER))


def cluster_reach(predictions: np.ndarray, start: float) -> float:
    """Half the distance, rad/s, from the cluster of ``predictions`` (ascending) that
    holds ``start`` to the nearest prediction outside it (``start`` itself if none)."""
    group = next(g for g in clusters(predictions) if predictions[g[0]] <= start <= predictions[g[-1]])
    outside = np.r_[predictions[:group[0]], predictions[group[-1] + 1:]]
    if not outside.size:
        return float(start)
    return 0.5 * float(np.min(np.minimum(np.abs(outside - predictions[group[0]]),
                                         np.abs(outside - predictions[group[-1]]))))


def repair_split(inside: list[float], widest: bool) -> float:
    """Where (rad/s) :func:`linmstmm.predicted._repaired` halves a stretch holding the
    distinct known roots ``inside`` (ascending, three or more).

    With ``widest`` (a search certifying to the default rtol): the geometric middle
    of the widest gap (relative) between neighbours among its middle half, not beside
    a close pair: the count 5e-8 from each of a pair 1e-7 apart cannot decide, and the
    argument principle counted in its place (494 evaluations of det for a rod's 30
    lowest). Else the middle of the median gap, even inside a close pair: at a looser
    rtol both searches of a stretch that holds a whole pair closer than rtol (the
    counted one, whose counts across a cluster are made at ±rtol, and the argument
    principle's) may keep it as one double root (that rod at rtol 1e-6: nine false
    double roots), where a split between the members parts it."""
    if not widest:
        return float(np.sqrt(inside[len(inside) // 2 - 1] * inside[len(inside) // 2]))
    quarter = len(inside) // 4
    gaps = range(max(quarter, 1), len(inside) - quarter)
    k = max(gaps, key=lambda i: inside[i] / inside[i - 1])
    return float(np.sqrt(inside[k - 1] * inside[k]))


def intervals_around(troubled: list[float], predictions: np.ndarray, roots: list[float]) -> list[tuple]:
    """Disjoint intervals (lo, hi], rad/s, each holding troubled predictions and
    reaching halfway (geometrically) to the nearest prediction on either side that
    is neither among them nor within CLUSTER of one (the other prediction of a
    double root is inside: an edge between the two lay on the root, and rounding
    alone, the model's units, decided which side its one counted copy fell), and
    below down to the nearest known root (``roots``, rad/s) under the prediction:
    the segment search runs there. (The coarse model's predictions lie above the
    roots they predict: the second of a close pair can lie below the halfway point
    between their predictions.)"""
    intervals: list[list[float]] = []
    troubled_set = set(troubled)
    for start in sorted(troubled):
        outside = [p for p in predictions if p not in troubled_set and abs(p - start) > CLUSTER * start]
        below = [p for p in outside if p < start]
        above = [p for p in outside if p > start]
        lo = np.sqrt(start * below[-1]) if below else start / 2
        under = [r for r in roots if r < start]
        if under:
            lo = min(lo, max(under) * (1 + CLUSTER * 1e-3))
        hi = np.sqrt(start * above[0]) if above else start * 1.5
        if intervals and lo <= intervals[-1][1]:
            intervals[-1][1] = max(intervals[-1][1], hi)
        else:
            intervals.append([lo, hi])
    return [(float(lo), float(hi)) for lo, hi in intervals]
