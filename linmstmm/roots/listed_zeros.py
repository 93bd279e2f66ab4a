"""Whether each value a list of roots holds is a zero of det Ū_all, with the multiplicity
the list gives it, where no Wittrick–Williams count decides.

The argument-principle closing count (:func:`~linmstmm.roots.certify.other_zeros`) runs
on det with the listed values divided out, so it counts (zeros missing) − (listed values
that are no zeros): a value where the secant stopped at an extremum of det, no root
there, cancels the root it stands in for, and the list passes. :func:`not_zeros` tells
such a value from a root.
"""
from __future__ import annotations

from bisect import bisect_left, bisect_right

import numpy as np

from linmstmm.counting import count_zeros_many
from linmstmm.roots.settings import DEFLATED_MAX_POINTS


def not_zeros(finder, known: list[float], lo: float | None, hi: float, least: float) -> int | None:
    """How far the known values in (lo, hi) are from being zeros of det Ū_all with their
    multiplicities: the sum over the distinct ones of |zeros counted across them − times
    listed|; None where a count cannot be made.

    A value listed once is checked across ±w (:func:`_sign_width`: ``least``, the
    narrowest relative half-width of this finder's counts across a root, or four times
    the value's last step, at most a quarter of the gap to the next known value): a sign
    change of det there passes it on two evaluations, a contour count over that width
    decides the others. A value listed m > 1 times stands for the m zeros that the
    circle of its multiplicity holds (:meth:`RootFinder.multiplicities`: a pair 3e-5
    apart read as one double root, which :func:`~linmstmm.roots.clusters.separated`
    splits later): it passes where that circle's count gave m, else it is counted over
    that circle now."""
    start, ordered = (finder.floor if lo is None else lo), sorted(known)
    distinct = sorted(set(ordered))
    roots = [r for r in distinct if start < r < hi]
    simple = [(r, _sign_width(finder, r, ordered, least)) for r in roots if ordered.count(r) == 1]
    doubtful = []
    if simple:
        sign, _ = finder.log_det(np.array([r * (1 + s * w) for r, w in simple for s in (-1, 1)]))
        sign = np.asarray(sign).real.reshape(-1, 2)
        doubtful = [(r, w * r) for (r, w), (below, above) in zip(simple, sign) if below * above >= 0]
    doubtful += [(r, finder._circles.get(r) or finder._circle_radius(r, distinct)) for r in roots
                 if ordered.count(r) > 1 and finder._counted.get(r) != ordered.count(r)]
    if not doubtful:
        return 0
    counts = count_zeros_many(finder.log_det, [(r - radius, r + radius) for r, radius in doubtful],
                              max_points=DEFLATED_MAX_POINTS)
    if any(isinstance(c, RuntimeError) for c in counts):
        return None
    return sum(abs(c - ordered.count(r)) for (r, _), c in zip(doubtful, counts))


def _sign_width(finder, root: float, ordered: list[float], least: float) -> float:
    """Relative half-width across which :func:`not_zeros` looks for the sign change of det
    at a simple known ``root`` (rad/s) among the known roots ``ordered`` (rad/s, ascending):
    ``least`` (relative), or four times the root's last step where that is wider, at most a
    quarter of the gap to its nearest neighbour."""
    i = bisect_left(ordered, root)
    gap = min((abs(ordered[k] - root) for k in (i - 1, bisect_right(ordered, root)) if 0 <= k < len(ordered)),
              default=root) / root
    return min(max(least, 4 * finder.last_step.get(root, 0.0)), 0.25 * gap)
