"""Sign-change brackets of a scan: narrowed all at once, and the roots (with their
clusters) that Newton reaches from them; the quiet minima of log|det| where a
root of even multiplicity shows no sign change."""

from __future__ import annotations

import numpy as np


def shrink_brackets(finder, lo, hi, width: float = 1e-4) -> np.ndarray:
    """Midpoints of sign-change brackets (lo_i, hi_i) narrowed to ``width``·hi (:meth:`_narrowed`)."""
    lo, hi = finder._narrowed(lo, hi, width)
    return (lo + hi) / 2


def narrowed(finder, lo, hi, width: float, log_det=None):
    """Sign-change brackets (lo_i, hi_i) narrowed to ``width``·hi, all at once: (lo, hi).

    Each round evaluates, for every bracket (a, b) at once, the regula falsi
    point x (where the line through ±|det| at the ends crosses zero, from
    log|det| so nothing overflows), x ± 1e-4 (b − a), x ± 1e-2 (b − a) and
    NARROWING_SECTIONS − 1 equally spaced points; the bracket becomes the
    narrowest sign change among them. Near a simple root x is off by
    O((b − a)²), so a bracket shrinks up to 1e4-fold per round, and at least
    NARROWING_SECTIONS-fold anywhere. A round costs one evaluation of det
    whatever its size (MLRS: 1.1 ms, plus 0.07 ms a point): one point per
    round (Illinois regula falsi) took ten rounds where this takes three.
    ``log_det``: of another function (default: det Ū_all's).
    """
    log_det = finder.log_det if log_det is None else log_det
    lo, hi = np.array(lo, dtype=float), np.array(hi, dtype=float)
    if lo.size == 0:
        return lo, hi
    sign, log_abs = log_det(np.r_[lo, hi])
    sign = np.real(sign)
    sign_lo, sign_hi, log_lo, log_hi = sign[:lo.size], sign[lo.size:], log_abs[:lo.size], log_abs[lo.size:]
    width = max(width, 4 * np.finfo(float).eps)
    moving = np.ones(lo.size, dtype=bool)
    sections = np.arange(1, finder.NARROWING_SECTIONS) / finder.NARROWING_SECTIONS
    while True:
        active = np.flatnonzero(moving & (hi - lo > width * hi))
        if active.size == 0:
            return lo, hi
        a, b = lo[active], hi[active]
        w = (b - a)[:, None]
        fraction = 1 / (1 + np.exp(np.clip(log_hi[active] - log_lo[active], -700, 700)))
        x = (a + (b - a) * fraction)[:, None]
        inside = np.sort(np.clip(np.concatenate([x + w * [-1e-2, -1e-4, 0.0, 1e-4, 1e-2],
                                                 a[:, None] + w * sections], axis=1),
                                 a[:, None] + 1e-6 * w, b[:, None] - 1e-6 * w), axis=1)
        sign_x, log_x = log_det(inside.ravel())
        points = np.concatenate([a[:, None], inside, b[:, None]], axis=1)
        signs = np.concatenate([sign_lo[active, None], np.real(sign_x).reshape(inside.shape),
                                sign_hi[active, None]], axis=1)
        logs = np.concatenate([log_lo[active, None], log_x.reshape(inside.shape), log_hi[active, None]], axis=1)
        steps = np.where(signs[:, :-1] * signs[:, 1:] < 0, np.diff(points, axis=1), np.inf)
        k = np.argmin(steps, axis=1)
        rows = np.arange(active.size)
        lo[active], hi[active] = points[rows, k], points[rows, k + 1]
        sign_lo[active], sign_hi[active] = signs[rows, k], signs[rows, k + 1]
        log_lo[active], log_hi[active] = logs[rows, k], logs[rows, k + 1]
        moving[active] = (lo[active] != a) | (hi[active] != b)  # rounding left no point inside


def bracketed(finder, lo, hi, log_ratio, confirm: bool = True, needed: int | None = None,
               known=()) -> list[list[float]]:
    """The cluster of the root in each sign-change bracket (lo_i, hi_i].

    Newton starts where the straight line through |det| at the two ends
    (log_ratio = log|det(hi)| − log|det(lo)|) crosses zero; a bracket
    whose Newton lands outside it is narrowed to 1e-4 and tried again
    (a root it reached instead is kept: it is a root too). A root Newton
    still cannot reach (the orthonormalised basis can absorb a root whose
    column is all but one small component, e.g. a weak torsion mode next to
    stiff bending, so that the pencil does not show it) is taken from the
    bracket narrowed to ``xtol`` by regula falsi on det itself, as a
    simple root (a sign change: odd multiplicity; a count sees a triple one).
    With ``needed``, only the lowest ``needed`` roots (``known`` ones among them)
    matter: a bracket Newton missed above them is left out (:meth:`_needed`).
    """
    starts = lo + (hi - lo) / (1 + np.exp(np.clip(log_ratio, -700, 700)))
    groups = finder.clusters(starts, confirm)
    missed = [i for i, group in enumerate(groups) if not any(lo[i] < r <= hi[i] for r in group)]
    if missed and needed is not None:
        kept = finder._needed(missed, lo, hi, [r for group in groups for r in group] + list(known), needed)
        finder.left_out += [(lo[i], hi[i]) for i in missed if i not in kept]
        missed = kept
    return groups + finder._narrowed_groups(lo[missed], hi[missed], groups, confirm)


def narrowed_groups(finder, lo, hi, groups, confirm: bool = True) -> list[list[float]]:
    """The clusters of the roots in sign-change brackets (lo_i, hi_i] that Newton
    missed from their first start: from the bracket narrowed to 1e-4, and, where
    that reaches no root inside either (nor did any of ``groups``), the bracket
    narrowed to xtol as a simple root (see :meth:`_bracketed`)."""
    if lo.size == 0:
        return []
    more = finder.clusters(finder.shrink_brackets(lo, hi), confirm)
    still = [i for i in range(lo.size) if not any(lo[i] < r <= hi[i] for group in groups + more for r in group)]
    return more + [[root] for root in finder._bracket_roots(lo[still], hi[still])]


def needed(finder, missed, lo, hi, roots, needed: int) -> list:
    """The ``missed`` brackets (indices into lo, hi) that may hold one of the lowest
    ``needed`` roots, given the ``roots`` found: those below the ``needed``-th of
    the distinct roots found, the tops of the missed brackets with no root found
    inside (each holds one of its own: a sign change), and the
    :attr:`deferred_members` that may lead to other roots (:meth:`_member_starts`:
    a close pair's other member, which no sign change shows). The members are
    likely roots, not certain ones: a bracket left out that holds one of the
    lowest ``needed`` roots is what the closing count finds missing, and its
    repairs locate it (MLRS 40 modes: five of the ten brackets Newton missed lay
    above the 40th root, 43.5 Hz, from 52.8 to 137 Hz, and narrowing them cost
    226 evaluations of det).
    Multiplicities are not relied on: they may be read from offsets alone."""
    roots = sorted(set(roots))
    empty = [i for i in missed if not any(lo[i] < r <= hi[i] for r in roots)]
    bounds = sorted(roots + [hi[i] for i in empty] + finder._member_starts(roots))
    if len(bounds) < needed:
        return missed
    return [i for i in missed if lo[i] < bounds[needed - 1]]


def bracket_roots(finder, lo, hi, log_det=None) -> list[float]:
    """One simple root in each sign-change bracket (lo_i, hi_i), the bracket narrowed
    to xtol (:meth:`_narrowed`); its width is recorded as the root's :attr:`last_step`."""
    a, b = finder._narrowed(lo, hi, finder.xtol, log_det)
    for root, uncertainty in zip((a + b) / 2, (b - a) / b):
        finder.last_step[root] = uncertainty
    return list((a + b) / 2)


def merge(finder, found: list[float], members, lo, hi) -> None:
    """Add the roots of a cluster inside (lo, hi] to ``found``, each distinct root once.

    Equal entries of ``members`` are one root's multiplicity and go in
    together; a root within SPLIT of one already found is that root (its
    multiplicity was settled by :meth:`_multiplicities`). A multiplicity
    counted over a circle that reaches out of (lo, hi] may hold a root outside:
    it is counted again over a circle inside (a rod's pair 1e-7 apart across a
    segment's end came in as a double root at rtol 1e-6, and the segment's other
    root, 3e-3 below, was taken as found).
    """
    for value in sorted(set(m for m in members if lo < m <= hi)):
        if not any(abs(value - r) <= finder.SPLIT * r for r in found):
            copies = members.count(value)
            if copies > 1 and finder._circles.get(value, 0.0) >= min(value - lo, hi - value):
                copies = finder.multiplicities([value], [lo, hi])[0] or 1
                finder._counted[value] = copies
            found += [value] * copies


def polished(finder, starts, found: list[float], confirm: bool = True) -> list[float]:
    """``found`` with the roots (and their clusters) Newton reaches from ``starts``."""
    return finder._with_groups(found, finder.clusters(starts, confirm))


def with_groups(finder, found: list[float], groups) -> list[float]:
    """``found`` (left as it is) with each group's roots merged in (:meth:`_merge`), ascending."""
    found = list(found)
    for members in groups:
        finder._merge(found, members, finder.floor, np.inf)
    return sorted(found)


def quiet_minima(sign, log_abs) -> np.ndarray:
    """Indices of a scan's interior local minima of log|det| with no sign change on
    either side: where a root of even multiplicity or a close pair may hide."""
    inner = np.arange(1, len(sign) - 1)
    return inner[(log_abs[inner] < log_abs[inner - 1]) & (log_abs[inner] < log_abs[inner + 1])
                 & (sign[inner - 1] == sign[inner]) & (sign[inner] == sign[inner + 1])]
