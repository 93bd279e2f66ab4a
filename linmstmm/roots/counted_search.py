"""The segment search by Wittrick–Williams counts: bisect a segment on the count
until each piece holds one natural frequency, and find it on det Ū_all in the
sign change that piece is.

Each count is one factorisation of the exact dynamic stiffness (about 70 µs
on the launcher, against the dozens of det evaluations of an argument-principle
count), and it needs no contour kept clear of the roots, so a piece is split
at its middle. A piece that holds one simple root is a sign-change bracket of
det (det Ū_all is real and entire on the real axis, and its rigid-body zeros
at ω = 0 are divided out by a positive factor), which the Anderson–Björck
method narrows to xtol. A narrow piece that holds several
(a multiple root, or roots closer than it) is polished as a cluster on the
matrix pencil (:meth:`RootFinder.cluster`), which must find exactly that many
inside.

A segment's ends are often roots already found (the neighbours of a stretch
the polish left troubled), where the count cannot decide (K(ω) is singular
there). Such an end is moved outward by the narrowest of
:data:`~linmstmm.roots.certify.NEAR_WIDTHS` (1e-9 … 1e-6, relative) at which
the count decides, and the roots found beyond the ends are left out (those
within the finder's same-root distance of an end are that end: the lower
stays out, the upper in); where more than one root lies that close to a moved
end, a pair astride it, the search gives up. Only for a finder that certifies
to the default rtol or finer (:attr:`RootFinder.fine_rtol`): at a looser rtol
the cluster polish inside may keep a pair closer than rtol as one double root
(its counts across are made at ±rtol), where the argument principle's search
of a stretch that ends on a member parts it (a rod with planes 1e-7 apart at
rtol 1e-6 came back with nine false double roots). At the default rtol the same
rod's troubled stretches all end on roots, and the argument-principle search
took 1,800 evaluations of det for them.

Where a count cannot decide, or a piece does not give up its roots this way,
the search answers None and the argument-principle segment search runs
(:func:`linmstmm.roots.segments.segment`).
"""

from __future__ import annotations

import numpy as np

from linmstmm.roots.certify import NEAR_WIDTHS, near_widths

#: A piece narrower than this (relative) that still holds several roots is polished
#: as a cluster on the pencil rather than halved again.
CLUSTER_WIDTH = 1e-4
#: Halvings of a segment before the search gives up (a width of 2^-60 of it is
#: far below float64's resolution of a root).
MAX_DEPTH = 60
#: Anderson–Björck steps in a one-root bracket before it is given up (it converges
#: superlinearly: about ten from a bracket a few per cent wide to 1e-14).
BRACKET_STEPS = 60


def counted_segment(finder, lo: float, hi: float) -> list[float] | None:
    """Every root in (lo, hi], rad/s, ascending, repeated per multiplicity, found by
    Wittrick–Williams counts and det Ū_all; None without a counter, or where a count
    cannot decide or a piece cannot be resolved (the caller then runs the
    argument-principle segment search)."""
    if finder.counter_for_stretch() is None:
        return None
    outward = 1 if finder.fine_rtol else 0
    (start, below), (stop, above) = _decided_end(finder, lo, -outward), _decided_end(finder, hi, outward)
    if below is None or above is None:
        return None
    found = _pieces(finder, start, stop, below, above, 0)
    if found is None:
        return None
    _record_multiplicities(finder, found)
    if (start, stop) == (lo, hi):
        return found
    if _crowded(found, lo, start) or _crowded(found, hi, stop):
        return None
    same = finder.same_root  # lo found again stays out, hi found again is in; no other beyond them
    return [root for root in found if lo * (1 + same) < root <= hi * (1 + same)]


def _record_multiplicities(finder, found: list[float]) -> None:
    """Record how often each root of ``found`` (rad/s) is repeated as its multiplicity
    (:attr:`RootFinder._counted`), in place of a circle count of it made before: the
    counts of the pieces bound these. A circle drawn about a double root before its
    neighbour 5e-8 above was found passed through that neighbour and counted 3 (an
    octahedral star, bending planes 1e-7 apart), and the check of multiplicities
    (:meth:`RootFinder._separated`) then failed to part the double root in float64."""
    for root in set(found):
        finder._counted[root] = found.count(root)
        finder._circles.pop(root, None)


def _decided_end(finder, omega: float, outward: int) -> tuple[float, int | None]:
    """(end, J(end)): ``omega`` (rad/s) where the count there decides, else ``omega``
    moved by the narrowest of NEAR_WIDTHS at which it does, down (``outward`` −1) or
    up (+1), not at all (0); J None where none decides."""
    for width in (0.0, *(NEAR_WIDTHS if outward else ())):
        end = omega * (1 + outward * width)
        count = finder.counter(end)
        if count is not None:
            return end, count
    return omega, None


def _crowded(found: list[float], end: float, moved: float) -> bool:
    """Whether more than one of ``found`` (rad/s) lies within the distance between a
    segment's ``end`` and where it was ``moved`` to (rad/s) of ``end``: a close pair
    astride the end, which the values cannot tell apart on either side (at rtol 1e-7,
    before the ends moved at the default rtol only, the pencil's cluster polish returned
    a pair 2e-8 apart as its outer member twice, and the inner one was lost). One root
    there is the end's own, or a root that far off."""
    reach = abs(moved - end)
    return sum(abs(root - end) <= reach for root in found) > 1


def _pieces(finder, lo: float, hi: float, below: int, above: int, depth: int) -> list[float] | None:
    """The roots in (lo, hi] given the counts J(lo) = ``below`` and J(hi) = ``above``."""
    expected = above - below
    if expected == 0:
        return []
    if expected < 0 or depth > MAX_DEPTH:
        return None
    if expected == 1:
        root = _bracketed_root(finder, lo, hi)
        if root is not None:
            return [root]
    elif hi - lo < finder.CERTIFIED_WIDTH * hi:
        return None  # float64 cannot tell them apart: the segment search reports them together
    members = []
    if expected > 1 and hi - lo < CLUSTER_WIDTH * hi:
        members = sorted(r for r in finder.cluster(0.5 * (lo + hi)) if lo < r <= hi)
        if len(members) == expected and not _split_across(finder, members):
            return members
        held = _held_by_one(finder, members, lo, hi, expected)
        if held is not None:
            return held
    middle, at_middle = _split(finder, lo, hi, sorted(set(members)))
    if at_middle is None:
        return None
    lower = _pieces(finder, lo, middle, below, at_middle, depth + 1)
    upper = None if lower is None else _pieces(finder, middle, hi, at_middle, above, depth + 1)
    return None if upper is None else lower + upper


def _split(finder, lo: float, hi: float, distinct: list[float]) -> tuple[float, int | None]:
    """(a point inside (lo, hi), J there; None where no count there decides): the middle,
    else the points halfway between neighbours of ``distinct`` (rad/s, ascending: the
    pencil's roots inside), the farthest from them. Within a cluster the count cannot
    decide near its roots: an octahedral star's two double roots 5e-8 apart (bending
    planes 1e-7 apart) left the middle of their piece 1.2e-7 wide undecided."""
    for point in [0.5 * (lo + hi)] + [0.5 * (a + b) for a, b in zip(distinct, distinct[1:])]:
        count = finder.counter(point)
        if count is not None:
            return point, count
    return 0.5 * (lo + hi), None


def _held_by_one(finder, members: list[float], lo: float, hi: float, expected: int) -> list[float] | None:
    """[root] * ``expected`` where the pencil's ``members`` (rad/s) in the piece (lo, hi]
    are one root it took with another multiplicity, and the counts find the piece's
    ``expected`` roots all within the finder's rtol of it: J over (root (1 − rtol), root
    (1 + rtol)] is ``expected``, and so is J over the union of that with the piece, so
    the two hold the same roots. None otherwise.

    The pencil of a cluster can see one double root of it six times (an octahedral star
    with bending planes 1e-6 apart, double roots 5e-7 apart): the piece around it
    cannot be halved where the count cannot decide, 1e-9 from the root."""
    if len(set(members)) != 1:
        return None
    root = members[0]
    near_lo, near_hi = root * (1 - finder.rtol), root * (1 + finder.rtol)
    around = finder.stiffness_count([], near_lo, near_hi)
    union = finder.stiffness_count([], min(lo, near_lo), max(hi, near_hi))
    return [root] * expected if around == expected and union == expected else None


def _split_across(finder, members: list[float]) -> bool:
    """True where the counts across a root repeated in ``members`` (rad/s), at the
    narrowest of the certifying widths where they decide
    (:func:`~linmstmm.roots.certify.near_widths`), show fewer than its multiplicity:
    a close pair the pencil took for one multiple root (it merges offsets below
    SPLIT), which bisection must then part. A cantilever's pair 2.5e-6 apart at rtol
    1e-6 came back as a double root at the lower one, the other 2.5 rtol off; one
    1e-6 apart at the default rtol, where the counts at ±1e-9 beside a root cannot
    decide, 1000 rtol off. Where no width decides, the members stand as the pencil
    found them."""
    for root in sorted(set(members)):
        multiplicity = members.count(root)
        for width in near_widths(finder.rtol) if multiplicity > 1 else ():
            counted = finder.stiffness_count([], root * (1 - width), root * (1 + width))
            if counted is not None:
                if counted < multiplicity:
                    return True
                break
    return False


def _bracketed_root(finder, lo: float, hi: float) -> float | None:
    """The one simple root in (lo, hi], from the sign change of det there, by Brent's
    method (:func:`scipy.optimize.brentq`: bisection where interpolation does not
    pay, so it keeps the bracket and converges superlinearly) to the finder's xtol;
    None where det does not change sign. The final bracket's width (relative) is
    recorded as the root's :attr:`~linmstmm.roots.RootFinder.last_step`."""
    from scipy.optimize import brentq  # imported where used: the command line starts without it

    (sign_lo, sign_hi), (log_lo, log_hi) = finder.log_det(np.array([lo, hi]))
    if not np.real(sign_lo * sign_hi) < 0:
        return None
    reference = max(log_lo, log_hi)  # det at ω is sign · exp(log|det| − reference): no overflow
    known = {lo: np.real(sign_lo) * np.exp(log_lo - reference), hi: np.real(sign_hi) * np.exp(log_hi - reference)}

    def det(omega):
        if omega in known:  # brentq asks for the ends first
            return float(known[omega])
        (sign,), (log_abs,) = finder.log_det(np.array([omega]))
        return float(np.real(sign) * np.exp(log_abs - reference))

    tolerance = max(finder.xtol, 4 * np.finfo(float).eps)
    root, outcome = brentq(det, lo, hi, xtol=np.finfo(float).tiny, rtol=tolerance, maxiter=BRACKET_STEPS,
                           full_output=True, disp=False)
    if not outcome.converged:
        return None
    finder.last_step[float(root)] = tolerance
    return float(root)
