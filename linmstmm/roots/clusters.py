"""Clusters of close roots and multiplicities: every root Newton reaches around
one, how many roots sit at each (the pencil's near-zero offsets, confirmed by a
count over a small circle), and multiple roots split into the distinct ones of a cluster."""

from __future__ import annotations

from collections import Counter

import numpy as np

from linmstmm.counting import count_zeros_many
from linmstmm.roots.settings import CIRCLE_MAX_POINTS, CIRCLE_POINTS

#: How many times smaller than its own circle a multiple root is counted over again
#: (:func:`tight_counts`): a multiple root keeps its count there, a cluster does not.
TIGHTER = 100


def clusters(finder, starts, confirm: bool = True) -> list[list[float]]:
    """For each start, every root in the cluster around the root nearest it, ascending.

    The multiplicity of a polished root comes from :meth:`_multiplicities`
    (the offsets μ of the linearised pencil, confirmed by a root count;
    the singular values of a 60×60 Ū_all are too spread to count on);
    the other small real offsets are polished in turn and kept when they
    reach another root (farther than SPLIT: closer ones are the same,
    possibly multiple, root, and their offsets seen from it may show a
    higher multiplicity than the first arrival's did: a double root of a
    loop rigid in five directions showed its second offset only within
    1e-13 of the root). Without ``confirm`` the multiplicities are read
    from the offsets alone (see :meth:`_multiplicities`) and the member
    starts go to :attr:`deferred_members` (a simple root's pencil can show
    a spurious near offset: polishing every one cost MLRS 6 ms).
    """
    polished = finder.polish(starts, early=not confirm)
    near = beside(finder, polished) if confirm else [[] for _ in polished]
    groups, members_from = [], []
    for (centre, mu), multiplicity, others in zip(polished, finder._multiplicities(polished, confirm, near), near):
        if centre is None:
            groups.append([])
            continue
        groups.append([centre] * multiplicity + others)
        real = mu[np.abs(mu.imag) <= 1e-6 * np.abs(mu)].real
        outside = np.abs(real) >= finder.SPLIT * centre
        if confirm:
            near = real[outside & (np.abs(real) < finder.CLUSTER_WINDOW * centre)]
            members_from += [(len(groups) - 1, centre - offset) for offset in near]
        else:  # polished only if the caller's closing count finds one missing
            near = real[outside & (np.abs(real) < finder.DEFERRED_WINDOW * centre)]
            finder.deferred_members += [(centre - offset, centre) for offset in near]
    if members_from:
        returned = []  # members that came back to a root of their group: more evidence
        for (g, _), result in zip(members_from, finder.polish([s for _, s in members_from])):
            member = result[0]
            if member is None:
                continue
            if all(abs(member - r) > finder.SPLIT * r for r in groups[g]):
                groups[g].append(member)
            else:
                returned.append((g, min(groups[g], key=lambda r: abs(r - member)), result))
        for (g, root, _), multiplicity in zip(returned, finder._multiplicities([r for *_, r in returned],
                                                                            confirm)):
            groups[g] += [root] * (multiplicity - groups[g].count(root))
    return [sorted(group) for group in groups]


def centre_multiplicities(finder, polished, confirm: bool = True, near=None) -> list[int]:
    """How many roots sit at each polished centre, given its pencil offsets mu, and
    ``near``: for each, the distinct roots found within SPLIT of it (:func:`beside`),
    which its circle leaves out.

    A root of multiplicity m leaves m offsets near zero, split by rounding
    to about √eps and not always real (7 arms of NAFEMS FV2: up to 6e-5).
    Where more than one offset is below SPLIT·ω, a root count over a circle
    of radius SPLIT·ω (less, if another root is nearer) decides; all those
    counts share one evaluation per refinement round. The circle holds one
    root (of some multiplicity m) at its centre and no other within twice
    its radius, so the phase turns smoothly by mπ over the half circle and
    CIRCLE_POINTS starting points (refined where log det changes fast) suffice.
    Without ``confirm`` the number of offsets below SPLIT·ω is taken as it
    is: for a caller that counts all its roots at the end anyway.
    """
    if not confirm:
        return [1 if centre is None else max(int(np.sum(np.abs(mu) < finder.SPLIT * centre)), 1)
                for centre, mu in polished]
    multiplicities = [1] * len(polished)
    asked, intervals = [], []
    for i, (centre, mu) in enumerate(polished):
        if centre is None:
            continue
        size = np.abs(mu)
        within = min([finder.SPLIT * centre] + [abs(other - centre) / 2 for other in (near[i] if near else [])])
        if np.sum(size < within) <= 1:
            continue
        farther = size[size >= finder.SPLIT * centre]
        radius = min(within, farther.min() / 2 if farther.size else np.inf)
        asked.append(i)
        intervals.append((centre - radius, centre + radius))
    counts = (count_zeros_many(finder.log_det, intervals, max_points=CIRCLE_MAX_POINTS, initial_points=CIRCLE_POINTS)
              if asked else [])
    for i, count in zip(asked, counts):
        multiplicities[i] = 1 if isinstance(count, RuntimeError) else max(count, 1)
    finder._counted.update((polished[i][0], multiplicities[i]) for i in asked)
    finder._circles.update((polished[i][0], (hi - lo) / 2) for i, (lo, hi) in zip(asked, intervals))
    return multiplicities


def cluster(finder, omega: float) -> list[float]:
    """Every root in the cluster around the root nearest ``omega`` (see :meth:`clusters`)."""
    return finder.clusters([omega])[0]


def recounted(finder, found: list[float], roots) -> list[float]:
    """``found`` with the multiplicity of each of ``roots`` (distinct, in ``found``)
    counted over a small circle (all circles in one count; see :meth:`_multiplicities`)
    instead of read from its pencil offsets, which can show spurious near-zero ones
    or (a Newton stopped early) miss a double root's second one. Where a circle
    cannot be counted the root is taken as simple: an unconfirmed multiplicity could
    hide a missing root from the closing count, a missing one cannot."""
    finder._counted.update((r, count or 1) for r, count in zip(roots, finder.multiplicities(roots, sorted(set(found)))))
    return finder._as_counted(found)


def as_counted(finder, found: list[float]) -> list[float]:
    """``found`` with each root repeated as often as a circle count gave it (:attr:`_counted`),
    the others as often as they are."""
    return sorted(r for r in set(found) for _ in range(finder._counted.get(r, found.count(r))))


def circle_radius(finder, root: float, others) -> float:
    """Radius (rad/s) of the circle that counts the multiplicity of ``root``: SPLIT·ω,
    less where a root of ``others`` is nearer (half the distance)."""
    return min([finder.SPLIT * root] + [abs(root - other) / 2 for other in others if other != root])


def multiplicities(finder, roots, others=()) -> list:
    """How many roots sit at each of ``roots`` (rad/s, roots found), counted over a
    circle of radius SPLIT·ω, less where a root of ``others`` is nearer (all
    circles in one count; see :meth:`_multiplicities`); None where the count
    cannot be made."""
    if not len(roots):
        return []
    radii = [finder._circle_radius(r, others) for r in roots]
    finder._circles.update(zip(roots, radii))
    counts = count_zeros_many(finder.log_det, [(r - radius, r + radius) for r, radius in zip(roots, radii)],
                              max_points=CIRCLE_MAX_POINTS, initial_points=CIRCLE_POINTS)
    return [None if isinstance(c, RuntimeError) else max(c, 1) for c in counts]


def unseparated_among(finder, roots) -> dict:
    """The :attr:`unseparated` entries of ``roots`` (rad/s), ascending."""
    return {r: finder.unseparated[r] for r in sorted(set(roots)) if r in finder.unseparated}


def multiplicity(finder, root: float, others=()) -> int | None:
    """How many roots sit at ``root`` (rad/s, a root found): the circle count already
    made for it while finding the roots, else the natural frequencies within the
    circle :meth:`multiplicities` would count over (:func:`_counts_within`: the
    Wittrick–Williams count across it where it decides, some 40 evaluations of det
    fewer than the argument principle, which counts where it does not); None where
    neither can be made."""
    if finder._counted.get(root):
        return finder._counted[root]
    radius = finder._circle_radius(root, others)
    finder._circles[root] = radius
    count = _counts_within(finder, [root], [radius])[0]
    return None if count is None else max(count, 1)


def separated(finder, roots: list[float]) -> list[float]:
    """``roots`` with each multiple one that is a cluster of distinct roots split into them.

    Roots closer than SPLIT are counted as one multiple root (a circle of that
    radius holds them all). Each multiple root is counted again over a circle
    TIGHTER times smaller (:func:`tight_counts`), by the Wittrick–Williams counts
    at the two ends of its diameter on the real axis, where every natural
    frequency lies, and by the argument principle where they cannot decide (all
    those in one count; some 20 evaluations of det each: a symmetric rod's ten
    lowest spent 104 of their 138 on them): a multiple root keeps its count, a
    cluster does not, and its
    members are then isolated by bisection on the count within the first
    circle (:meth:`_isolate`). A random loop's double root and the simple one
    1.9e-5 above it had come back as one triple root.
    Where float64 cannot separate them they stay together, and
    :attr:`unseparated` says so (root -> (multiplicity, radius, rad/s)):
    ``natural_frequencies`` then separates them in mpmath
    (:func:`~linmstmm.precision.separated_cluster`), or names them in its note.
    First, a multiple root whose pencil shows a distinct root nearby is split
    into them where a count that leaves that root out finds fewer copies
    (:func:`_apart_by_offsets`).
    """
    tally = Counter(roots)
    multiple = _multiple(finder, tally)
    if not multiple:  # every root simple: nothing to split
        return roots
    roots = _apart_by_offsets(finder, roots, {r: max(tally[r], finder._counted.get(r, 1)) for r in multiple})
    tally = Counter(roots)
    distinct, multiple = sorted(tally), _multiple(finder, tally)
    if not multiple:
        return roots
    radii = [finder._circle_radius(r, distinct) for r in multiple]
    tight, _ = tight_counts(finder, multiple, distinct)
    separated, placed = list(roots), set()
    for r, radius, count in zip(multiple, radii, tight):
        if r in placed:
            continue  # placed anew with its cluster (:func:`_cluster_isolated`)
        m = finder._counted.get(r, tally[r])  # (``roots`` may end inside a multiple root)
        if count == m or (r == distinct[-1] and count is not None and count >= tally[r]):
            continue  # the highest may have more around it beyond the roots found, which m counted
        if not finder.fine_rtol and _held_within_rtol(finder, r, tally[r]):
            continue  # a looser rtol asked for: each copy is a root within it
        try:
            members = finder._isolate(r - radius, r + radius, m, [r])
        except RuntimeError:
            finder.unseparated[r] = (m, radius)
            continue
        if len(members) < tally[r]:  # the others lie beyond the circle, nearer a neighbour
            separated, replaced = _cluster_isolated(finder, separated, r)
            placed |= replaced
            continue
        separated = [x for x in separated if x != r] + members[:tally[r]]
    return sorted(separated)


def _cluster_isolated(finder, roots: list[float], root: float) -> tuple[list[float], set[float]]:
    """(``roots`` with those of the cluster about ``root`` placed anew; the values replaced):
    every root within SPLIT of ``root``, and SPLIT beyond the outermost of them, found again
    by bisection on the count of that stretch (:meth:`RootFinder._isolate`). For a multiple
    root whose copies the bisection within half the distance to its neighbour does not
    find: an octahedral star of 20 beams an arm, planes 1e-8 apart, listed one root of a
    cluster of three double roots 5e-9 apart five times; the circle about it held two, and
    the search for its 22 lowest came back with 21, the 21st 5e-9 off. Raises RuntimeError
    where the stretch cannot be counted or its roots cannot be found in float64."""
    reach = finder.SPLIT * root
    near = [x for x in roots if abs(x - root) <= reach]
    lo, hi = min(near) - reach, max(near) + reach
    expected = _counts_within(finder, [(lo + hi) / 2], [(hi - lo) / 2])[0]
    if expected is None:
        raise RuntimeError(f"float64 could not count the cluster of roots near {root / (2 * np.pi):.10g} Hz")
    replaced = {x for x in roots if lo < x <= hi}
    members = finder._isolate(lo, hi, expected, sorted(set(roots)))  # each found once: the copies are in doubt
    return [x for x in roots if x not in replaced] + members, replaced


def _held_within_rtol(finder, root: float, copies: int) -> bool:
    """Whether the count within the finder's rtol of ``root`` (rad/s) finds at least its
    ``copies``, so that each is a natural frequency within rtol of it. An octahedral star
    whose bending planes are 2e-6 apart, at rtol 1e-6: a root listed twice was one root
    and another 0.95e-6 below it; the tight count found one, the bisection within half
    the distance to the root below found only that one, and the other copy was dropped:
    19 roots, where the count asked for 20 (and found them within rtol)."""
    held = _counts_within(finder, [root], [finder.rtol * root])[0]
    return held is not None and held >= copies


def tight_counts(finder, centres: list[float], distinct: list[float]) -> tuple[list[int | None], list[float]]:
    """(the natural frequencies within each tight circle about ``centres`` (rad/s), or
    None where the count cannot be made; the circles' radii, rad/s): radius
    :meth:`RootFinder._circle_radius` among the roots ``distinct`` over TIGHTER, where
    a multiple root keeps its count and a cluster does not (:func:`separated`).
    Each circle is counted once per search (:func:`_counts_within`, all new ones in
    one count), however often it is asked for."""
    radii = [finder._circle_radius(c, distinct) / TIGHTER for c in centres]
    kept = finder._tight_counts
    asked = [(c, r) for c, r in zip(centres, radii) if (c, r) not in kept]
    if asked:
        kept.update(zip(asked, _counts_within(finder, [c for c, _ in asked], [r for _, r in asked])))
    return [kept[c, r] for c, r in zip(centres, radii)], radii


def beside(finder, polished) -> list[list[float]]:
    """For each polished (centre, offsets μ) of :meth:`polish`: the distinct roots
    closer than SPLIT that Newton reaches from its real offsets beyond rtol.

    At a root of multiplicity m the pencil shows m offsets within rounding of zero
    (1e-16 of ω at a cantilever's double roots; up to 6e-5 at the 7 arms of NAFEMS
    FV2): Newton from those comes back to the centre. A real offset to a distinct
    root stays put under Newton: from there it reaches that root, and a count over
    a circle holding both would read the two as one double root (a cantilever's
    bending pairs 1e-6 and 1e-7 apart came out as double roots 1e-6 from one
    member, and one with a root 3e-3 below it missing).
    """
    starts, owners = [], []
    for i, (centre, mu) in enumerate(polished):
        if centre is None:
            continue
        real = mu[np.abs(mu.imag) <= 1e-6 * np.abs(mu)].real
        ahead = real[(np.abs(real) > finder.rtol * centre) & (np.abs(real) < finder.SPLIT * centre)]
        starts += (centre - ahead).tolist()
        owners += [i] * ahead.size
    near: list[list[float]] = [[] for _ in polished]
    for i, (root, _) in zip(owners, finder.polish(starts) if starts else []):
        centre = polished[i][0]
        if (root is not None and finder.rtol * centre < abs(root - centre) < finder.SPLIT * centre
                and all(abs(root - other) > finder.rtol * other for other in near[i])):
            near[i].append(root)
    return near


def offsets_of(finder, roots: list[float], least: list[int]) -> dict[float, np.ndarray]:
    """root (rad/s) -> the pencil's offsets there: those its polish kept
    (:attr:`RootFinder.offsets_at`) where they hold at least ``least`` (one per root)
    values, else found now, all those in one call (:meth:`RootFinder._offsets`)."""
    missing = [r for r, n in zip(roots, least) if finder.offsets_at.get(r, np.zeros(0)).size < n]
    found = dict(zip(missing, finder._offsets(np.array(missing)) if missing else []))
    return {r: found[r] if r in found else finder.offsets_at[r] for r in roots}


def _apart_by_offsets(finder, roots: list[float], copies: dict[float, int]) -> list[float]:
    """``roots`` with each multiple one whose pencil shows a distinct root beside it
    (:func:`beside`) split: that root takes one of its copies, unless a count across
    the multiple root that leaves it out finds all the copies there
    (:func:`_holds_its_copies`): it is then a root beside it, not one of them. The
    counts of :func:`separated` only say how many roots a circle holds. ``copies``:
    each multiple root of ``roots`` (:func:`_multiple`) -> how many roots sit there."""
    multiple = sorted(copies)
    offsets = offsets_of(finder, multiple, [copies[r] for r in multiple])
    split = list(roots)
    for r, near in zip(multiple, beside(finder, [(r, offsets[r]) for r in multiple])):
        near = [member for member in near if not any(abs(member - other) <= finder.rtol * other for other in split)]
        if near and _holds_its_copies(finder, r, split.count(r), near + [x for x in split if x != r]):
            continue
        for member in near:  # (each not a root found already)
            if split.count(r) > 1:
                split.remove(r)
            finder._counted[r] = max(finder._counted.get(r, copies[r]) - 1, 1)  # one copy fewer than it had
            split.append(member)
    return sorted(split)


def _multiple(finder, tally: Counter) -> list[float]:
    """The roots of ``tally`` (root rad/s -> how often a list holds it) that are multiple,
    ascending: held more than once, or counted so over a circle (:attr:`RootFinder._counted`:
    a list cut at a count may hold one copy of a root counted as multiple)."""
    counted = finder._counted
    return sorted(r for r, m in tally.items() if m > 1 or counted.get(r, 1) > 1)


def _holds_its_copies(finder, root: float, listed: int, near: list[float]) -> bool:
    """Whether ``root`` (rad/s) holds the copies a list has of it, ``listed``, on its own:
    a count over half the distance to the nearest of the roots ``near`` (rad/s: those
    beside it, and the list's others, so that the circle passes through none) finds at
    least as many, so those lie outside what gave it its multiplicity
    and take none of its copies. That count becomes its multiplicity
    (:attr:`RootFinder._counted`), so that a later count of it over a wider circle does
    not take them in.

    A cantilever with equal bending planes whose first torsion root lies 2e-5 above
    a bending double root, asked for a count that ends on the double root: the
    torsion root, found beside it but above the roots asked for, took one of its
    copies, and the double root was reported once, the torsion root in its place, or
    refined in mpmath as a simple root that never settled. Likewise an octahedral star
    (bending planes 1e-5 apart) whose 20 lowest end on a double root with two more
    double roots 5e-6 and 1e-5 above it: its wider circle counted six, the count
    beside it two, and the highest took one of its two copies (a wrong 20th by 1e-5).
    """
    radius = min(abs(member - root) for member in near) / 2
    held = _counts_within(finder, [root], [radius])[0]
    if held is None or held < listed:
        return False
    finder._counted[root] = held
    finder._circles[root] = radius
    return True


def _counts_within(finder, centres: list[float], radii: list[float]) -> list[int | None]:
    """The natural frequencies within ``radii`` (rad/s) of ``centres`` (rad/s), one per
    centre: the Wittrick–Williams count across each, where it decides, else the
    argument principle over the circle (all those in one count); None where neither
    can be made."""
    counts = [finder.stiffness_count([], c - radius, c + radius) for c, radius in zip(centres, radii)]
    undecided = [i for i, count in enumerate(counts) if count is None]
    circles = count_zeros_many(finder.log_det, [(centres[i] - radii[i], centres[i] + radii[i]) for i in undecided],
                               max_points=CIRCLE_MAX_POINTS, initial_points=CIRCLE_POINTS) if undecided else []
    for i, count in zip(undecided, circles):
        counts[i] = None if isinstance(count, RuntimeError) else count
    return counts
