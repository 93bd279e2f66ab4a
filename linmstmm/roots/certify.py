"""Certification: the closing count that the roots found are all there are (the
Wittrick–Williams count, else the argument principle on det with them divided
out), and the recovery of those a count says are missing."""

from __future__ import annotations

from bisect import bisect_left, bisect_right
from collections import Counter

import numpy as np

from linmstmm.counting import count_zeros, count_zeros_many, deflated
from linmstmm.roots.listed_zeros import not_zeros
from linmstmm.roots.settings import DEFLATED_MAX_POINTS, DEFLATED_POINTS

#: Relative half-widths, narrowest first, of the counts that give a root's
#: multiplicity (:func:`counted_multiplicities`): the narrowest is float64's own
#: certification of a root (CERTIFIED_STEP); wider ones where the count there
#: cannot decide, at the price of a refinement in mpmath. A finder certifying to a
#: looser rtol starts at its rtol (:func:`near_widths`).
NEAR_WIDTHS = (1e-9, 1e-8, 1e-7, 1e-6)


def confirmed(finder, found: list[float], count: int | None, omega_max: float | None = None,
               cap: float = np.inf):
    """The lowest ``count`` of ``found`` (or all up to omega_max) if one count from
    the floor says there are no others below them; None otherwise.
    ``cap``: the count stops there at the latest (rad/s; above the count-th root).
    Multiplicities above one inside the count are counted over circles first
    (:meth:`_settled`)."""
    found = finder._settled(found, count, omega_max, cap)
    upper = finder._count_top(found, count, omega_max)
    if upper is None or (count is not None and len(found) >= count and found[count - 1] >= cap):
        return None
    upper = min(upper, cap)
    below = [r for r in found if r < upper]
    return below[:count] if finder.confirm_no_other_zeros(found, upper) else None


def cut_at(finder, found: list[float], omega_max: float | None) -> list[float]:
    """The roots of ``found`` (rad/s, ascending, complete up to omega_max or beyond)
    that lie below ``omega_max`` (None: all): as many of the lowest as the
    Wittrick–Williams count finds natural frequencies below it, where it decides,
    else those whose values are. A prediction that stood unpolished
    (:func:`~linmstmm.predicted._counted_predictions`) is known to rtol only: its
    value can lie across omega_max from its root."""
    if omega_max is None:
        return found
    below = stiffness_count(finder, [], None, omega_max)
    return found[:below] if below is not None else [w for w in found if w <= omega_max]


def settled(finder, found: list[float], count: int | None, omega_max: float | None,
             cap: float = np.inf) -> list[float]:
    """``found`` with every multiplicity above one below the closing count's top (and
    ``cap``) counted over a circle (:meth:`_recounted`), again while that moves the
    top up. The closing count sees zeros less the roots divided out: a simple root
    read as double from a spurious near-zero pencil offset would cancel a missing
    root (a random tree at 40 modes read one as fivefold, with four missing, and
    passed; MLRS above 400 Hz read 53 of 78 roots as double)."""
    while True:
        found = finder._as_counted(found)
        top = min(finder._count_top(found, count, omega_max) or np.inf, cap)
        doubtful = sorted({r for r in found if r < top and r not in finder._counted and found.count(r) > 1})
        if not doubtful:
            return found
        found = finder._recounted(found, doubtful)


def count_top(finder, found: list[float], count: int | None, omega_max: float | None):
    """Top of the closing count: midway between the count-th root and the next one
    found (1 % above it if none), or omega_max, whichever is lower; omega_max with
    fewer than ``count`` found, None without it."""
    if count is None or len(found) < count:
        return omega_max
    top = found[count - 1]
    above = [r for r in found if r > top * (1 + finder.SAME_ROOT)]
    by_count = (top + above[0]) / 2 if above else top * 1.01
    return by_count if omega_max is None else min(by_count, omega_max)


def recovered(finder, found: list[float], upper: float, count: int | None = None):
    """(``found`` with the roots below ``upper`` that the closing count says are
    missing, the cap for the closing count that follows (rad/s)).

    They are located by geometric bisection from :attr:`root_free_below` up,
    down to eighths of an octave, on counts of det with the ``found`` roots
    divided out (:func:`~linmstmm.counting.deflated`; all intervals of one
    level in one batched count). With ``count``, an
    interval with at least ``count`` roots (found or missing) below it is
    not split further: its roots are above the count-th, and the closing
    count is capped at its lower end. The intervals that
    hold some are scanned densely, and det on that scan with the found roots
    divided out has sign changes and quiet minima of the missing roots alone,
    again with each pass's roots divided out (:meth:`_rescanned`: of a close pair
    missing in one scan step, one shows only once the other is found; random
    floating_loops 3 at 80 modes fell back to the segment search, 1.4 s more).
    ``found`` as it was if a count cannot be made.
    """
    reduced = deflated(finder.log_det, [r for r in found if r < upper])
    try:
        missing = count_zeros(reduced, finder.floor, upper, max_points=DEFLATED_MAX_POINTS)
    except RuntimeError:
        return found, upper
    floor = min(finder.root_free_below, upper)  # the bisection starts above what a count found empty
    pending, leaves, cap = [(floor, upper, missing)] if missing else [], [], upper
    while pending:
        kept, level_cap = finder._below_count(leaves + pending, found, count, upper)
        cap = min(cap, level_cap)
        leaves, pending = [part for part in leaves if part in kept], [part for part in pending if part in kept]
        leaves += [part for part in pending if part[1] / part[0] <= 2 ** 0.125]
        wide = [part for part in pending if part[1] / part[0] > 2 ** 0.125]
        middles = [np.sqrt(lo * hi) for lo, hi, _ in wide]
        lower = (count_zeros_many(reduced, [(lo, mid) for (lo, _, _), mid in zip(wide, middles)],
                                  max_points=DEFLATED_MAX_POINTS) if wide else [])
        if any(isinstance(c, RuntimeError) for c in lower):
            return found, upper
        pending = [part for (lo, hi, k), mid, c in zip(wide, middles, lower)
                   for part in ((lo, mid, c), (mid, hi, k - c)) if part[2] > 0]
    if not leaves:
        return found, cap
    grid = np.concatenate([np.geomspace(lo, hi, 16 * k + 17) for lo, hi, k in leaves])
    return finder._rescanned(found, [(grid, *finder.log_det(grid))], upper), cap


def below_count(parts, found: list[float], count: int | None, upper: float):
    """(the (lo, hi, missing) ``parts`` that may hold one of the lowest ``count``
    roots, the lower end of the first that cannot, else ``upper``): a part
    with ``count`` roots below it, found or missing, cannot."""
    kept, missing_below = [], 0
    for lo, hi, missing in sorted(parts):
        if count is not None and sum(r < lo for r in found) + missing_below >= count:
            return kept, lo
        kept.append((lo, hi, missing))
        missing_below += missing
    return kept, upper


def confirm_no_other_zeros(finder, known: list[float], upper: float) -> bool:
    """True if (floor, upper) holds no zeros of det Ū_all but ``known``.

    The count runs on det with the known roots divided out (:func:`~linmstmm.counting.deflated`),
    so its phase turns only for zeros not in ``known`` (or by −π for a
    ``known`` one that is not a zero) and DEFLATED_POINTS starting points
    suffice where counting them all took four times as many. Known
    roots above ``upper`` are divided out too: outside the contour they
    change nothing, and the next root just above ``upper`` no longer turns
    the phase fast near the contour's end (MLRS 20 modes: three refinement
    rounds fewer). False also where it cannot count: the segment search then
    decides (and says so if it cannot either).
    """
    return finder.other_zeros(known, None, upper) == 0


def other_zeros(finder, known: list[float], lo: float | None, hi: float) -> int | None:
    """Zeros of det Ū_all in (lo, hi) less those in ``known`` (negative where a known
    one is not a zero); lo None: the floor. None where the count cannot be made.

    The Wittrick–Williams count (:attr:`RootFinder.counter`, real
    factorisations, exact for the same model) answers where it can decide:
    the natural frequencies in (lo, hi) less the known ones there, and where
    that is zero, every known root checked with its multiplicity by a count
    across it (:func:`misplaced`), so that a known value that is not a root
    cannot stand in for a missing one. Elsewhere (or for a finder without a
    counter) the argument principle counts det with the known roots divided out.
    """
    counted = stiffness_other_zeros(finder, known, lo, hi)
    if counted is not None:
        return counted
    try:
        extra = count_zeros(deflated(finder.log_det, known), finder.floor if lo is None else lo, hi,
                            max_points=DEFLATED_MAX_POINTS, initial_points=DEFLATED_POINTS)
    except RuntimeError:
        return None
    if extra != 0:
        return extra
    # The count is (zeros missing) − (known values that are no zeros): a value that is no
    # root (a secant stopped at an extremum of det, no sign change across it) cancels a
    # missing root, and the list passed with a root replaced by it. Each known value is
    # checked, as misplaced() checks them in the Wittrick–Williams branch.
    wrong = not_zeros(finder, known, lo, hi, near_widths(finder.rtol)[0])
    return None if wrong is None else -wrong


def stiffness_other_zeros(finder, known: list[float], lo: float | None, hi: float) -> int | None:
    """:func:`other_zeros` by Wittrick–Williams counts alone; None where they cannot decide.

    The count over (lo, hi) is made in one batch with the first counts across each
    known root there (:func:`misplaced`): those are needed wherever it finds none
    missing, as it nearly always does, and where it does not, a later count across
    the same roots takes them."""
    if finder.counter is None:
        return None
    start, ordered = 0.0 if lo is None else lo, sorted(known)
    roots, near = sorted({r for r in known if start < r < hi}), near_widths(finder.rtol)
    opening = _opening(ordered, [(root, _widths(finder, root, ordered, near)) for root in roots])
    _counted_at(finder.counter, [hi, *([] if lo is None else [lo]), *_ends(opening)])
    counted = stiffness_count(finder, known, lo, hi)
    if counted is None or counted != 0:
        return counted
    wrong = misplaced(finder, ordered, roots, opening)
    return None if wrong is None else -wrong


def misplaced(finder, ordered: list[float], roots: list[float], opening: list[tuple]) -> int | None:
    """How far the multiplicities of the known roots ``ordered`` (rad/s, ascending, with
    repeats) are from the Wittrick–Williams counts across each of ``roots`` (distinct,
    ascending; a value that is no root has none), whose first counts are ``opening``
    (:func:`_opening`): the sum of the differences at the narrowest width the count
    decides, 0 when every one holds at some width. None where a count cannot decide. A
    root that a narrower count contradicts and a wider one holds lies that far from where
    float64 put it, whatever its last step said: that width becomes its last step
    (:attr:`RootFinder.last_step`), and the caller refines it in mpmath (a root of the
    second launcher at 13.25 krad/s, polished 1.5e-9 high, was reported as certified
    before)."""
    wrong = 0
    first, held = _counted_widths(finder, ordered, opening)
    for root in roots:
        if root not in first:
            return None
        if root not in held:
            wrong += abs(first[root][0] - _known_within(ordered, root, first[root][1]))
        elif held[root] > first[root][1]:  # a narrower count disagreed: float64 placed it that far off
            finder.last_step[root] = max(finder.last_step.get(root, 0.0), held[root])
    return wrong


def _counted_widths(finder, ordered: list[float], opening: list[tuple]) -> tuple[dict, dict]:
    """({root: (count, width)} at the narrowest width where the count across it decides,
    {root: width} at the narrowest where it holds the known roots ``ordered`` (rad/s,
    ascending, with repeats) there), for each root over its widths (:func:`_widths`),
    narrowest first, until one holds, from its first count in ``opening``
    (:func:`_opening`): what :func:`_counts_near` gives root by root.

    A count across a root is made as two, J at its lower end and then at its upper
    end, each a batch for all the roots at that step (:func:`_counted_at`); where J
    at the lower end cannot be decided, the upper end is not counted, and the
    root's next width is (the second launcher's lowest root: its counts at ±1e-9
    are both undecided, each after the dense factorisation too, 0.1 ms apiece).
    Widths with a known root on an end (:func:`_on_an_end`) say nothing and are
    not counted."""
    first, held, pending = {}, {}, opening
    while pending:
        counts = _counted_at(finder.counter, _ends(pending))
        following = []
        for (root, widths, level, below), count in zip(pending, counts):
            if count is not None and below is None:  # the lower end decided: the upper end next
                following.append((root, widths, level, count))
                continue
            if count is not None:
                width = widths[level]
                first.setdefault(root, (count - below, width))
                if count - below == _known_within(ordered, root, width):
                    held[root] = width
                    continue
            following += _opening(ordered, [(root, widths)], level + 1)
        pending = following
    return first, held


def _opening(ordered: list[float], across: list[tuple[float, list[float]]], level: int = 0) -> list[tuple]:
    """The first count still to make across each (root, widths) of ``across`` (rad/s;
    relative, narrowest first: :func:`_widths`), at the narrowest of its widths from
    ``level`` on with no known root of ``ordered`` (rad/s, ascending) on an end
    (:func:`_on_an_end`): (root, widths, that width's index, None) for J at its
    lower end (:func:`_ends`); none for a root without such a width."""
    opening = []
    for root, widths in across:
        for clear in range(level, len(widths)):
            if not _on_an_end(ordered, root, widths[clear]):
                opening.append((root, widths, clear, None))
                break
    return opening


def _ends(pending: list[tuple]) -> list[float]:
    """Where (rad/s) each count of ``pending`` (root, widths, level, J at the lower end or
    None before it is counted: :func:`_opening`) counts next: the lower end of its
    width, then the upper end."""
    return [root * (1 - widths[level]) if below is None else root * (1 + widths[level])
            for root, widths, level, below in pending]


def _counted_at(counter, omegas: list[float]) -> list[int | None]:
    """``counter``'s answers at each of ``omegas`` (rad/s): a
    :class:`~linmstmm.wittrick_williams.ModeCounter` counts those not counted yet in one
    batch (:meth:`~linmstmm.wittrick_williams.ModeCounter.at`), another callable is
    asked one by one."""
    at = getattr(counter, "at", None)
    return at(omegas) if at is not None else [counter(omega) for omega in omegas]


def _clear_of_neighbours(ordered: list[float], root: float, widths: list[float], least: float) -> list[float]:
    """``widths`` (relative, narrowest first: the near widths :func:`_widths` keeps) and, before
    them, half the relative gap from ``root`` to the nearest other of the known roots
    ``ordered`` (rad/s, ascending) where that root sits on an end of the narrowest
    count (:func:`_on_an_end`: that count then says nothing, and without a narrower
    one no count decides). A narrower count certifies more, not less; it is not
    offered below ``least`` (:func:`_least_width`: a root known less closely; the second
    launcher's pair 1.1e-4 apart at rtol 1e-4: each on the end of the other's ±rtol
    count, so that the argument principle decided, for 124 evaluations)."""
    if not _on_an_end(ordered, root, widths[0]):
        return widths
    below, above = bisect_left(ordered, root) - 1, bisect_right(ordered, root)
    gap = min(abs(ordered[k] - root) for k in (below, above) if 0 <= k < len(ordered)) / root
    return [0.5 * gap, *widths] if least <= 0.5 * gap < widths[0] else widths


def _on_an_end(ordered: list[float], root: float, width: float) -> bool:
    """Whether one of the known roots ``ordered`` (rad/s, ascending) lies within a tenth
    of ``width`` of an end of the count across ``root`` (relative ±``width``): which
    side of it the root lies is then not known, and the count there says nothing
    about it (a rod's pair exactly 1e-7 apart: a duplicate of one member and the
    other on the end made the count at 1e-7 hold)."""
    band, low, high = 0.1 * width * root, root * (1 - width), root * (1 + width)
    return (bisect_left(ordered, low + band) > bisect_left(ordered, low - band)
            or bisect_left(ordered, high + band) > bisect_left(ordered, high - band))


def _known_within(ordered: list[float], root: float, width: float) -> int:
    """How many of the known roots ``ordered`` (rad/s, ascending, with repeats) lie
    within ±``width`` (relative) of ``root``, ends excluded: its own multiplicity, and
    a close neighbour's that the same count sees."""
    return bisect_left(ordered, root * (1 + width)) - bisect_right(ordered, root * (1 - width))


def stiffness_count(finder, known: list[float], lo: float | None, hi: float) -> int | None:
    """Natural frequencies in (lo, hi) less those in ``known``, by the Wittrick–Williams
    count J(hi) − J(lo) (:class:`~linmstmm.wittrick_williams.ModeCounter`); lo None:
    from zero, less the rigid-body modes. None without a counter or where it
    cannot decide."""
    if finder.counter is None:
        return None
    upper = finder.counter(hi)
    lower = finder.rigid_body_modes() if lo is None else finder.counter(lo)
    if upper is None or lower is None:
        return None
    start = 0.0 if lo is None else lo
    return upper - lower - sum(start < r < hi for r in known)


def counted_multiplicities(finder, roots: list[float], lo: float | None, hi: float) -> list[float]:
    """``roots`` (rad/s, repeated per multiplicity) with each distinct one in (lo, hi)
    repeated as often as the Wittrick–Williams count finds natural frequencies
    within the narrowest of its widths that decides (:func:`_count_near`, over the
    same :func:`_widths` as the certificate's, half the gap to a neighbour on a
    count's end first): a member of a
    multiple root the pencil did not see is added, a value that is no root
    dropped. Roots where the count cannot decide stay as they are; so do all
    without a counter. A member added at a width above the finder's rtol is known
    only that closely: the width becomes the root's last step
    (:attr:`RootFinder.last_step`), and the caller refines it in mpmath."""
    if finder.counter is None:
        return roots
    start, counted = 0.0 if lo is None else lo, []
    ordered = sorted(roots)
    for root in sorted(set(roots)):
        have = roots.count(root)
        if start < root < hi:
            near = _count_near(finder, root, ordered)
            if near is not None:
                # the count sees close neighbours too: this root holds what they leave
                counted_here = near[0] - (_known_within(ordered, root, near[1]) - have)
                if counted_here > have and near[1] > finder.rtol:
                    finder.last_step[root] = max(finder.last_step.get(root, 0.0), near[1])
                have = max(counted_here, 0)
        counted += [root] * have
    return counted


def _count_near(finder, root: float, ordered: list[float]) -> tuple[int, float] | None:
    """(natural frequencies within ±width of ``root``, width (relative)) at the
    narrowest width of :func:`_counts_near` where the count decides and no root of
    ``ordered`` (rad/s, ascending) lies on an end (:func:`_on_an_end`); None where
    none does."""
    return next(((count, width) for count, width in _counts_near(finder, root, ordered)
                 if count is not None and not _on_an_end(ordered, root, width)), None)


def _counts_near(finder, root: float, ordered: list[float]):
    """(natural frequencies within ±width of ``root`` or None where the count cannot
    decide, width) for each of its :func:`_widths` among the known roots ``ordered``
    (rad/s, ascending), narrowest first."""
    for width in _widths(finder, root, ordered):
        below, above = finder.counter(root * (1 - width)), finder.counter(root * (1 + width))
        yield (None if below is None or above is None else above - below), width


def _widths(finder, root: float, ordered: list[float], near: list[float] | None = None) -> list[float]:
    """The relative half-widths of the counts across ``root`` (rad/s), narrowest first,
    for both the certificate (:func:`_counted_widths`) and the multiplicities
    (:func:`_count_near`): those of ``near`` (:func:`near_widths` of the finder's rtol
    where None) no narrower than :func:`_least_width` (for a root float64 could not
    certify, last step above the finder's rtol, :attr:`RootFinder.last_step`: four
    times that step, so it is counted where it may lie and refined in mpmath later;
    a certified root is held to the narrowest: the second launcher's root at
    4.90 krad/s, last step 7.3e-10, was 2.5e-9 off), and before them half the gap to
    a neighbour among the known roots ``ordered`` (rad/s, ascending, with repeats)
    that sits on an end of the narrowest (:func:`_clear_of_neighbours`)."""
    least = _least_width(finder, root)
    widths = [w for w in (near_widths(finder.rtol) if near is None else near) if w >= least] or [least]
    return _clear_of_neighbours(ordered, root, widths, least)


def _least_width(finder, root: float) -> float:
    """The narrowest relative half-width a count across ``root`` may have: four times
    its last step where float64 could not certify it (above the finder's rtol), else 0
    (a certified root is held to the narrowest)."""
    step = finder.last_step.get(root, 0.0)
    return 4 * step if step > finder.rtol else 0.0


def near_widths(rtol: float) -> list[float]:
    """Relative half-widths of the counts across a root of a finder certifying to
    ``rtol``, narrowest first: NEAR_WIDTHS from ``rtol`` up (``rtol`` itself where it
    is looser than the narrowest, alone where it is looser than all)."""
    narrowest = max(rtol, NEAR_WIDTHS[0])
    return [narrowest] + [width for width in NEAR_WIDTHS if width > narrowest]


def placed_by_counts(finder, found: list[float]) -> list[float]:
    """``found`` (rad/s, ascending) with each simple root float64 could not certify (its
    last step above rtol: det Ū_all too noisy there, or a count across it contradicted
    where float64 put it, :func:`misplaced`) placed by bisection on the
    Wittrick–Williams count instead (:func:`_bisected`), where the counts decide; the
    others as they are, for ``natural_frequencies`` to refine in mpmath. The count
    is exact for the model whatever det's rounding: the second launcher's root at
    2.1 kHz, 1e-9 off in float64 at its 100 lowest, took 320 ms in mpmath, and
    takes six counts (0.2 ms) so."""
    if finder.counter is None:
        return found
    placed, tally = list(found), Counter(found)
    for root in sorted(tally):
        if finder.last_step.get(root, 0.0) > finder.rtol and tally[root] == 1:
            bisected = _bisected(finder, root, finder.last_step[root])
            if bisected is not None:
                value, step = bisected
                placed[placed.index(root)] = value
                finder.last_step[value] = step
    return sorted(placed)


def _bisected(finder, root: float, step: float) -> tuple[float, float] | None:
    """(the natural frequency within ±4 ``step`` (relative) of ``root``, rad/s, to the
    finder's rtol: the middle of the last bracket; its half-width, relative) by
    bisection on J(ω), where the bracket holds that one alone and every count
    decides; None elsewhere."""
    lo, hi = root * (1 - 4 * step), root * (1 + 4 * step)
    below, above = finder.counter(lo), finder.counter(hi)
    if below is None or above is None or above - below != 1:
        return None
    while hi - lo > 2 * finder.rtol * lo:
        middle = (lo + hi) / 2
        count = finder.counter(middle)
        if count is None:
            return None
        lo, hi = (middle, hi) if count == below else (lo, middle)
    return (lo + hi) / 2, (hi - lo) / (lo + hi)
