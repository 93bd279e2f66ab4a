"""Predict, polish, certify: the lowest natural frequencies in few evaluations of det Ū_all.

The scan-based search of :class:`~linmstmm.roots.RootFinder` needs no prior
knowledge and spends about 25 evaluations of det Ū_all per root. Here the
roots are predicted first and each evaluation goes where a root is:

1. **predict** — the natural frequencies of a coarse finite-element model of
   the same file (:mod:`linmstmm.coarse_prediction`): a dense eigenproblem of
   a few hundred unknowns, accurate to about 1e-3 for the lowest and 1e-2 by
   the hundredth (those the caller refined by the Rayleigh functional of the exact
   dynamic stiffness to about 1e-13, :mod:`linmstmm.rayleigh`, with a bracket);
2. **polish** — where the caller asked for an ``rtol`` (from COUNTED_PREDICTION
   up), a prediction with no other within CLUSTER that counts at ±rtol across it
   certify stands as it is (:func:`_counted_predictions`);
   every other prediction by the secant method on det Ū_all
   (:func:`secant_roots`: one evaluation per step, superlinear, all roots in
   one batch per step; from a bracket's ends where it has one: a sign change
   there gives the root in two evaluations); a result that strays, shares its
   root with another, or (in a cluster) only creeps to the rounding floor goes
   to Newton on the matrix pencil (:meth:`RootFinder.polish`), and where that too
   lands on a known root, to the pencil's partner offset and then to the segment
   search of :class:`RootFinder` between the neighbouring predictions;
3. **certify** — one argument-principle count of det Ū_all with the polished
   roots divided out, from the search's floor to a gap above the last root
   wanted, must come to zero (:meth:`RootFinder.confirm_no_other_zeros`).
   Where it does not (a root the coarse model ranked out of range, one found
   twice), counts halve the range to the stretch that holds the difference and
   the segment search fills only that (:func:`_repaired`); the count is made
   again. Where predictions stood unpolished, which are no zeros of det, the
   Wittrick–Williams counts alone must certify the roots; where they cannot
   decide, the values that stood are polished before the argument principle's
   count (:func:`_stood_certified`). Where a count
   cannot be made, :func:`predicted_roots` returns None and the caller runs the
   full search. Completeness is never taken from the predictions.
"""
from __future__ import annotations

import math

import numpy as np

from linmstmm.counting import deflated
from linmstmm.multiple_predictions import coincident, other_members
from linmstmm.prediction_groups import (CLUSTER, Stood, cluster_reach, clustered, gap, gap_above, near_any,
                                        intervals_around, polished_up_to, repair_split, standing)
from linmstmm.secant import secant_roots

#: Halvings of the range by counts before a stretch that misses a root is searched whole.
REPAIR_DEPTH = 8
#: Rounds of the secant on det with the known roots divided out (:func:`_deflated_polished`).
DEFLATION_ROUNDS = 3
#: A root the deflated secant finds this close (relative) to a known one is not taken:
#: beside a multiple root, dividing out one inexact member leaves a zero a little off
#: (a tip-mass cantilever's double root at 42.4339020 rad/s came back with a second
#: member at 42.4339063); the pencil and the segment search decide there.
NEAR_KNOWN = 1e-5
#: Relative step to which the secant polishes a prediction above the roots wanted that
#: only places the certifying count's upper end (:func:`_secant_polished`): a tenth of
#: CLUSTER, the least distance above the roots wanted at which such a value stands.
PLACING = 1e-4
#: From this rtol up, where the caller asked for one (``RootFinder.unpolished``), each
#: prediction with no other within CLUSTER is first tried as it stands: where the
#: Wittrick–Williams counts at ±rtol across it find one natural frequency, it is
#: certified to rtol without an evaluation of det (:func:`_counted_predictions`).
#: The Rayleigh refinement brings the launchers' lone predictions within 5e-10
#: (most within 1e-13), so from 1e-9 they stand: rtol 1e-9 took the launcher's ten
#: lowest in no evaluation where the polish took 20. Counts narrower than 1e-9
#: are too close to the root to decide (the dense count is tried, then the polish):
#: at ±1e-10 the ten lowest took longer than polishing them.
COUNTED_PREDICTION = 1e-9


def predicted_roots(finder, predictions: np.ndarray, count: int, spans: np.ndarray | None = None):
    """The lowest ``count`` or more roots (rad/s, repeated per multiplicity) from
    ``predictions``, certified: every root up to the end of the certifying count
    (a gap above the count-th, so a multiple root there comes whole).

    finder : the :class:`~linmstmm.roots.RootFinder` of the model (its
    determinant, pencil, counts and segment search). predictions : (m,) rad/s,
    a few more than ``count`` (those above place the count's upper end in a
    gap). spans : (m,) relative half-widths of brackets that hold refined ones'
    roots (:func:`linmstmm.rayleigh.refined_predictions`), 0 (None: all) where none.
    Returns the roots, or None where a count cannot be made or does not come to zero
    (the caller then searches). Records each secant root's last step in
    ``finder.last_step``. Where a prediction stood unpolished (:func:`_counted_predictions`),
    the roots must pass the Wittrick–Williams counts alone (:func:`_stood_certified`).
    """
    predictions = np.asarray(predictions, dtype=float)
    spans = np.zeros(predictions.size) if spans is None else np.asarray(spans, dtype=float)
    order = np.argsort(predictions, kind="stable")
    order = order[predictions[order] > 0]
    predictions, spans = predictions[order], spans[order]
    if predictions.size < count:
        return None
    return _certified(finder, predictions, count, set(), spans)


def _certified(finder, predictions: np.ndarray, count: int, stood: set[float] | None,
               spans: np.ndarray) -> list[float] | None:
    """The roots :func:`predicted_roots` returns (rad/s), or None: from ``predictions``
    (ascending, positive; with their brackets' ``spans``), with those that counts
    certify as they stand taken so, and added to ``stood``, unless it is None."""
    wanted = polished_up_to(predictions, count)
    roots = _polished(finder, predictions, [], 0, wanted, stood, count, spans)
    if roots is not None and len(roots) < count < predictions.size:  # some predicted twice: as many more
        more = min(wanted + count - len(roots), predictions.size)
        more = polished_up_to(predictions, more)
        roots = _polished(finder, predictions, roots, wanted, more, stood, more, spans)
        wanted = more
    if roots is None:
        return None
    beyond = list(predictions[wanted:])
    if len(roots) < count <= len(roots) + len(beyond):
        # The polish lost some (onto a neighbour's root: a rod's pairs 1e-5 apart lost
        # three of its 30 lowest, and the full search took 29,453 evaluations): the
        # predictions not polished stand in for them to place the count's upper end,
        # and counts find them below it.
        roots = _repaired(finder, roots, None, gap_above(sorted(roots + beyond), count, finder.same_root, []),
                          REPAIR_DEPTH)
    if roots is None or len(roots) < count:
        return None
    if stood:
        return _stood_certified(finder, predictions, spans, roots, stood, count, beyond)
    return _cut(*_closed(finder, roots, count, beyond))


def _stood_certified(finder, predictions: np.ndarray, spans: np.ndarray, roots: list[float], stood: set[float],
                     count: int, beyond: list[float]) -> list[float] | None:
    """:func:`_certified`'s roots (rad/s) from ``roots``, among which some values ``stood``
    unpolished; the predictions ``beyond`` them place the certifying count's end.

    A value that stood (:func:`_counted_predictions`) is no zero of det: the argument
    principle's count, with it divided out, takes it for any root missing. So the
    Wittrick–Williams counts alone must certify the roots (those counts are made
    already). Where they find roots missing or misplaced (the end placed above a root
    the polish lost), the roots are repaired as they are (:func:`_closed`) and the
    counts alone asked again. Where those cannot decide (a count by a close pair), or
    still disagree, the values that stood are polished (:func:`_stood_polished`) before
    the argument principle's count; where one does not settle, every prediction is."""
    upper = gap_above(roots, count, finder.same_root, beyond)
    missing = finder.stiffness_other_zeros(roots, None, upper)
    if missing == 0:
        return _cut(roots, upper)
    if missing is not None:
        repaired, upper = _closed(finder, roots, count, beyond)
        if repaired is not None:
            certified = _cut(repaired, upper)
            if finder.stiffness_other_zeros(certified, None, upper) == 0:
                return certified
            roots = repaired
    roots = _stood_polished(finder, predictions, spans, roots, stood)
    if roots is None:
        return _certified(finder, predictions, count, None, spans)
    return _cut(*_closed(finder, roots, count, beyond))


def _stood_polished(finder, predictions: np.ndarray, spans: np.ndarray, roots: list[float],
                    stood: set[float]) -> list[float] | None:
    """``roots`` (rad/s) with the values among them that ``stood`` unpolished polished by
    the secant on det (from their brackets' ``spans``), ascending; None where one of
    them does not settle.

    Where the Wittrick–Williams counts alone cannot certify roots among which some
    stood (the rod with planes 1e-7 apart, 30 lowest at rtol 1e-9: a count by a pair
    cannot decide), only those need to be det's zeros for the argument principle:
    polishing every prediction again, the pairs' on the pencil too, took 6,310
    evaluations; polishing the six that stood, 3,159 in all (the default, 3,164).
    The values that stood are those recorded, not those a root equals: a secant root
    from a bracket about a refined prediction can be that prediction to the bit
    (taking it for one that stood made the same rod's 60 lowest polish twice, 9,088
    evaluations for 4,544)."""
    values, others = predictions.tolist(), list(roots)
    among = [value for value in stood if value in others]  # (one above the count's end is no root)
    for value in among:
        others.remove(value)
    indices = np.array([i for i, value in enumerate(values) if value in among], dtype=np.int64)
    found, unsettled = _secant_polished(finder, predictions, clustered(predictions), indices, others,
                                        len(values), spans)
    return None if unsettled else sorted(others + found)


def _cut(roots: list[float] | None, upper: float) -> list[float] | None:
    """``roots`` (rad/s) up to ``upper`` (rad/s), the certifying count's end; None stays None."""
    return None if roots is None else [r for r in roots if r <= upper]


def _closed(finder, roots: list[float], count: int, beyond: list[float]) -> tuple[list[float] | None, float]:
    """(``roots`` (rad/s), repaired where needed, or None; the certifying count's upper
    end, rad/s, up to which they are certified), the end placed in a gap above the ``count``-th by
    :func:`~linmstmm.prediction_groups.gap_above`, with the predictions ``beyond`` them,
    not polished: the argument principle's count with them divided out, and where it
    does not come to zero, the stretch that holds the difference searched
    (:func:`_repaired`) and the count made again."""
    upper = gap_above(roots, count, finder.same_root, beyond)
    # The predictions not polished above the count's contour, divided out too, change
    # no count but smooth its phase near the contour's upper end.
    beyond = [p for p in beyond if p > upper]
    if not finder.confirm_no_other_zeros(roots + beyond, upper):
        # A root the coarse model did not predict in range (or one polished twice):
        # halve by counts to the stretch that holds it and search only there.
        roots = _repaired(finder, roots, None, upper, REPAIR_DEPTH)
        if roots is None or len(roots) < count:
            return None, upper
        upper = gap_above(roots, count, finder.same_root, beyond)
        if not finder.confirm_no_other_zeros(roots + beyond, upper):
            return None, upper
    return roots, upper


def _polished(finder, predictions: np.ndarray, roots: list[float], start: int, stop: int,
              stood: set[float] | None, wanted: int, spans: np.ndarray):
    """``roots`` (rad/s) and the roots of ``predictions[start:stop]``, ascending: as they
    stand where counts certify them to a loose rtol (unless ``stood`` is None; those added
    to ``stood``), else by the secant (from
    their brackets' ends where ``spans`` has one), then the pencil, then the segment search
    around those both left troubled. None where a count of that search cannot be made (the
    full search decides). A root the pencil or the deflated secant finds within rtol of
    a value that stood is that value's root (:class:`Stood`)."""
    in_cluster = clustered(predictions)  # the same for the counts and the secant
    standing, indices = (_counted_predictions(finder, predictions, in_cluster, start, stop) if stood is not None
                         else ([], np.arange(start, stop)))
    if stood is not None:
        stood.update(standing)
    leaders, followers = coincident(predictions, indices, finder.counter is not None)
    grouped = {*leaders.tolist(), *followers.tolist()}
    alone = np.array([i for i in indices.tolist() if i not in grouped], dtype=np.int64)
    found, unsettled = _secant_polished(finder, predictions, in_cluster, alone, list(roots) + standing, wanted,
                                        spans)
    stood_for = Stood(stood, finder.rtol)
    found, troubled = _pencil_polished(finder, list(roots) + standing + found,
                                       unsettled + [float(p) for p in predictions[leaders]], stood_for)
    if finder.counter is None:  # no counts to give a multiple root's members: a circle's, else each polished
        found, followers = other_members(finder, found, predictions, leaders, followers)
        troubled, followers = troubled + [float(p) for p in predictions[followers]], followers[:0]
    found, troubled = _deflated_polished(finder, found, troubled, predictions, stood_for)
    for lo, hi in intervals_around(troubled + [float(p) for p in predictions[followers]], predictions, found):
        counted = _completed_by_counts(finder, found, lo, hi)
        if counted is not None:
            found = counted
            continue
        try:
            found = [r for r in found if not lo < r <= hi] + finder.segment(lo, hi)
        except RuntimeError:
            return None
    return sorted(found)


def _counted_predictions(finder, predictions: np.ndarray, in_cluster: list[bool], start: int,
                         stop: int) -> tuple[list[float], np.ndarray]:
    """(predictions certified as they stand, rad/s; indices of the others, ascending):
    those of ``predictions[start:stop]`` alone (no other prediction within CLUSTER:
    False in ``in_cluster``, :func:`clustered` of ``predictions``)
    across which the Wittrick–Williams counts at ±rtol find one natural frequency (so
    a root lies within rtol of it), where the finder may list roots unpolished
    (:attr:`RootFinder.unpolished`) to COUNTED_PREDICTION or looser; none otherwise.
    A prediction taken so has the finder's rtol as its last step
    (:attr:`RootFinder.last_step`). The counts are the certifying count's first ones
    across these values: it makes them once.

    A value that stands is known to rtol only, where the rest of the search tells
    roots apart far more finely, so a cluster's members are not tried: a double
    root's two predictions standing for it missed the count that tells a multiple
    root from a cluster (1e-6 around it), and a close pair's lower member, predicted
    within rtol of the upper root, stood for that root, which the secant then found
    again as a new one (thousands of evaluations and a refinement in mpmath where
    the default rtol took a few hundred).
    """
    counter = finder.counter
    if counter is None or not finder.unpolished or finder.rtol < COUNTED_PREDICTION or start >= stop:
        return [], np.arange(start, stop)
    values, width = predictions.tolist(), finder.rtol
    tried = [i for i in range(start, stop) if not in_cluster[i]]
    stands = {i for i, stood in zip(tried, standing(counter, values, tried, width)) if stood}
    for i in stands:
        finder.last_step[values[i]] = width
    return ([values[i] for i in sorted(stands)],
            np.array([i for i in range(start, stop) if i not in stands], dtype=np.int64))


def _secant_polished(finder, predictions: np.ndarray, in_cluster: list[bool], indices: np.ndarray,
                     known: list[float], wanted: int, spans: np.ndarray) -> tuple[list[float], list[float]]:
    """(roots, unsettled predictions): ``predictions[indices]`` by the secant on det
    (the others are their neighbours only; ``in_cluster``: :func:`clustered` of
    ``predictions``); one that lands on a ``known`` root (rad/s) is unsettled, and
    one alone with a bracket in ``spans`` starts from its ends, polished in full.
    Cluster members too: the launcher's pairs 1e-4 apart at 5.7-21 krad/s are
    predicted to 2e-5, where Newton on the pencil does not converge. A result
    stands where it stayed within half the gap to the neighbouring prediction,
    alone on its root, and converged to xtol for a cluster member (a multiple
    root's det keeps its sign: the secant creeps to the rounding floor there), to
    the finder's rtol for the others (a secant that stalled above it on a noisy det,
    1.3e-9 on a ring's 10th root with the default rtol, goes to the pencil).

    A prediction from the ``wanted``-th up (index ``wanted`` or more) alone in no
    cluster only places the certifying count's upper end in the gap above the roots
    wanted (:func:`~linmstmm.prediction_groups.gap_above`): it is polished to PLACING
    only, and stands so where it lies more than CLUSTER above every root polished in
    full (and ``known``), which all settled; otherwise it is polished again in full, from where it came (the
    secant's steps are the same to either tolerance: one that does not settle to
    PLACING would not to xtol either).
    """
    if not indices.size:  # every prediction stood, or went to the pencil
        return [], []
    spans = np.where(np.array(in_cluster, dtype=bool)[indices], 0.0, spans[indices])
    placing = np.array([i >= wanted and not in_cluster[i] for i in indices.tolist()]) & (spans == 0)
    found, steps = secant_roots(finder.log_det, predictions[indices],
                                np.where(placing, PLACING, finder.xtol), finder.UNCERTAIN, spans)
    settled = _settled(finder, predictions, in_cluster, indices, found, steps, placing, known)
    if placing.any():
        full = ~placing
        top = max([*found[full & settled].tolist(), *known], default=0.0)
        clear = found > top * (1 + CLUSTER) if settled[full].all() else np.zeros(found.size, dtype=bool)
        redo = placing & settled & ~clear
        if redo.any():
            found[redo], steps[redo] = secant_roots(finder.log_det, found[redo], finder.xtol, finder.UNCERTAIN)
            placing &= ~redo
            settled = _settled(finder, predictions, in_cluster, indices, found, steps, placing, known)
    kept = np.flatnonzero(settled)
    for k in kept:
        finder.last_step[found[k]] = steps[k]
    return [found[k] for k in kept], [float(predictions[i]) for i, stands in zip(indices, settled) if not stands]


def _settled(finder, predictions: np.ndarray, in_cluster: list[bool], indices: np.ndarray, found: np.ndarray,
             steps: np.ndarray, placing: np.ndarray, known: list[float]) -> np.ndarray:
    """(n,) bool: which secant results ``found`` (rad/s) of ``predictions[indices]``, with
    their last relative ``steps``, stand (:func:`_secant_polished`; ``placing``: those
    polished to PLACING only)."""
    values, same = predictions.tolist(), finder.same_root
    roots = found.tolist()
    bounds = [PLACING if loose else finder.xtol if in_cluster[i] else finder.rtol
              for i, loose in zip(indices.tolist(), placing.tolist())]
    settled = [not math.isnan(root) and abs(root - values[i]) <= 0.5 * gap(values, i)
               and step <= bound and not near_any(root, known, same)
               for i, root, step, bound in zip(indices.tolist(), roots, steps.tolist(), bounds)]
    for i in [k for k, stands in enumerate(settled) if stands]:  # two that settled on one root: neither stands
        twins = [k for k, stands in enumerate(settled) if stands and abs(roots[k] - roots[i]) <= same * roots[i]]
        if len(twins) > 1:
            for k in twins:
                settled[k] = False
    return np.array(settled, dtype=bool)


def _completed_by_counts(finder, found: list[float], lo: float, hi: float):
    """``found`` (rad/s) complete in (lo, hi) by Wittrick–Williams counts alone: as it
    is where they find nothing missing, with the multiplicities they count where
    that makes it complete (:meth:`RootFinder.counted_multiplicities`); None where
    they cannot decide or something else is missing (the segment search then runs)."""
    if finder.stiffness_other_zeros(found, lo, hi) != 0:
        found = finder.counted_multiplicities(found, lo, hi)
        if finder.stiffness_other_zeros(found, lo, hi) != 0:
            return None
    return sorted(found)


def _pencil_polished(finder, roots: list[float], starts: list[float],
                     stood_for: Stood) -> tuple[list[float], list[float]]:
    """(roots, troubled starts): ``starts`` by Newton on the pencil, which steps to the
    nearest root whatever its neighbours. One that lands on a root already found
    tries the partner the pencil's next offset there points at; the rest are
    troubled (a multiple root, or two roots closer than a count's contour sees:
    random loops 57 had its 40th and 41st 9.7e-6 apart, certified as one double
    root): the segment search takes the stretch around them."""
    roots, troubled, partners = list(roots), [], []
    if not starts:
        return roots, troubled

    def taken(root) -> bool:
        """Whether ``root`` (rad/s, or None) is new, then added; first in place of a value that stood for it."""
        if root is None:
            return False
        stood_for.absorbed(root, roots)
        if near_any(root, roots, finder.same_root):
            return False
        roots.append(root)
        return True

    for start, (root, offsets) in zip(starts, finder.polish(starts)):
        if taken(root):
            continue
        partner = None if root is None else _partner(root, offsets, finder.same_root, finder.NEWTON_REACH)
        if partner is None:
            troubled.append(start)
        else:
            partners.append((start, partner))
    for (start, _), (root, _) in zip(partners, finder.polish([p for _, p in partners])):
        if not taken(root):
            troubled.append(start)
    return roots, troubled


def _deflated_polished(finder, roots: list[float], starts: list[float], predictions: np.ndarray,
                       stood_for: Stood) -> tuple[list[float], list[float]]:
    """(roots, troubled starts): ``starts`` by the secant on det with every known root
    divided out (:func:`~linmstmm.counting.deflated`), in rounds of DEFLATION_ROUNDS at
    most, each adding the roots it finds to those divided out.

    A close pair's second member is then the only zero near its prediction: the
    launcher's pairs 1e-4 apart at 11-16 krad/s, where the secant and the pencil on
    det both land on the first, took the segment search 2,000-3,000 evaluations
    each. A result stands where it converged to xtol within half the gap from its
    prediction's cluster to the predictions outside it (the coarse model predicts
    both members high: the second can lie below the first's prediction); one equal
    to a known root (a
    multiple root, or a known one a little off: dividing it out leaves a zero
    beside the pole) stays troubled. Two of one round on one root: the lower start
    keeps it. The certifying count checks every root and multiplicity either way.
    """
    roots, starts = list(roots), list(starts)
    for _ in range(DEFLATION_ROUNDS):
        if not starts:
            break
        found, steps = secant_roots(deflated(finder.log_det, roots), np.array(starts), finder.xtol, 0.0)
        left, this_round = [], []
        for start, root, step in zip(starts, found, steps):
            if not np.isnan(root):  # converged (NaN otherwise): the root of a value it is within rtol of
                stood_for.absorbed(float(root), roots)
            if (np.isnan(root) or step > finder.xtol or abs(root - start) > cluster_reach(predictions, start)
                    or near_any(root, roots, NEAR_KNOWN) or near_any(root, this_round, finder.same_root)):
                left.append(start)
            else:
                this_round.append(float(root))
                finder.last_step[float(root)] = step
        roots += this_round
        if len(left) == len(starts):
            break
        starts = left
    return roots, starts


def _repaired(finder, roots: list[float], lo: float, hi: float, depth: int):
    """``roots`` with those in (lo, hi] made complete (lo None: from the search's
    floor): a count of det with the known ones divided out; where it is not zero,
    halved at a known root's gap and counted again, down to ``depth`` halvings or
    two known roots, where the segment search takes the stretch. None where a
    count cannot be made, or where more are missing than known (the predictions
    were not the lowest roots: random loops with bending planes 7e9 apart had 874
    more below the count's top; the full search decides)."""
    extra = finder.other_zeros(roots, lo, hi)
    if extra is None or extra > len(roots):
        return None
    if extra != 0:  # a member of a multiple root the pencil did not see, or a value that is no root
        counted = finder.counted_multiplicities(roots, lo, hi)
        if counted != roots:
            roots, extra = counted, finder.other_zeros(counted, lo, hi)
            if extra is None:
                return None
    if extra == 0:
        return roots
    lo = finder.floor if lo is None else lo
    inside = sorted({r for r in roots if lo < r <= hi})  # distinct: a count on a multiple root cannot decide
    if depth == 0 or len(inside) <= 2:
        outside = [r for r in roots if not lo < r <= hi]
        try:
            return sorted(outside + finder.segment(lo, hi))
        except RuntimeError:  # a count there cannot be made: the full search decides
            return None
    middle = repair_split(inside, finder.fine_rtol)
    roots = _repaired(finder, roots, lo, middle, depth - 1)
    return None if roots is None else _repaired(finder, roots, middle, hi, depth - 1)


def _partner(root: float, offsets: np.ndarray, same: float, reach: float) -> float | None:
    """The nearest other root the pencil at ``root`` sees (its smallest real offset
    beyond ``same`` and within ``reach``, relative), or None."""
    real = offsets[(np.abs(offsets.imag) <= 1e-6 * np.abs(offsets)) & (np.abs(offsets) > same * root)
                   & (np.abs(offsets) <= reach * root)].real
    return float(root - real[np.argmin(np.abs(real))]) if real.size else None
