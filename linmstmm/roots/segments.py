"""The segment search: segment by segment upwards, a count, a scan of the segment
and bisection on the count until every root it holds is found."""

from __future__ import annotations

import numpy as np

from linmstmm.counting import count_zeros
from linmstmm.roots.brackets import quiet_minima
from linmstmm.roots.counted_search import counted_segment
from linmstmm.roots.settings import FIRST_SEGMENT_RATIO, SCAN_OCTAVES


def roots_in(finder, grid, expected: int) -> list[float]:
    """Roots inside (grid[0], grid[-1]) reached from the scan, up to ``expected`` of them.

    Polishing starts in every sign change (roots of odd multiplicity; see
    :meth:`_bracketed`), then from local minima of log|det| without a sign
    change (roots of even multiplicity, close pairs), deepest first, as
    many as the count says are still missing.
    """
    sign, log_abs = finder.log_det(grid)
    found: list[float] = []
    brackets = np.flatnonzero(sign[:-1] * sign[1:] < 0)
    for members in finder._bracketed(grid[brackets], grid[brackets + 1],
                                   log_abs[brackets + 1] - log_abs[brackets]):
        finder._merge(found, members, grid[0], grid[-1])
    minima = quiet_minima(sign, log_abs)
    minima = [i for i in minima[np.argsort(log_abs[minima] - np.maximum(log_abs[minima - 1],
                                                                        log_abs[minima + 1]))]
              if not any(grid[i - 1] < r < grid[i + 1] for r in found)]
    missing = expected - len(found)
    if missing > 0 and minima:
        for members in finder.clusters(grid[minima[:2 * missing]]):
            finder._merge(found, members, grid[0], grid[-1])
    return sorted(found)


def split_point(finder, lo, hi) -> float:
    """A point in the middle half of (lo, hi) where |det| is largest: far from any root."""
    trial = lo + (hi - lo) * np.linspace(0.3, 0.7, 9)
    return float(trial[np.argmax(finder.log_det(trial)[1])])


def isolate(finder, lo, hi, expected, found, depth=0) -> list[float]:
    """Bisect (lo, hi] on the root count until every root is found.

    found : roots already found (anywhere). Returns the roots in (lo, hi].
    Where (lo, hi] is narrower than CERTIFIED_WIDTH and float64 still finds
    fewer roots than the count (random ring 12 at 4822.65 Hz: a sign change
    that regula falsi on det could not narrow), they are all reported at its
    middle and recorded in :attr:`unseparated`. Where the finder certifies to a
    looser rtol, bisection stops where (lo, hi] is narrower than that, and its
    roots are reported at its middle, each within rtol of it (the second
    launcher's pair 3e-6 apart at 5.8 krad/s took 9,000 evaluations and an
    mpmath refinement at rtol 1e-4 to be told apart). More roots found than the
    count are bisected on it too: a part it finds empty drops what was found
    there (random loops 32 at 80 modes: Newton settled at two points in an
    interval holding one root, and the search raised), and a narrow part
    with one root found takes the count's multiplicity. Raises RuntimeError
    if the count cannot be met otherwise.
    """
    inside = sorted(r for r in found if lo < r <= hi)
    narrow = hi - lo < finder.CERTIFIED_WIDTH * hi
    if len(inside) == expected:
        return inside
    if len(inside) < expected and finder.rtol > finder.CERTIFIED_WIDTH and hi - lo < finder.rtol * hi:
        return [(lo + hi) / 2] * expected  # a looser rtol asked for: each is within it of the middle
    if len(inside) < expected and narrow:
        middle = (lo + hi) / 2  # the count encloses them: within CERTIFIED_WIDTH / 2 of it
        finder.unseparated[middle] = (expected, (hi - lo) / 2)
        return [middle] * expected
    if len(inside) > expected and expected == 0:
        return []  # the count says none: what Newton settled on here is not a root
    if len(inside) > expected and narrow and len(set(inside)) == 1:
        return inside[:1] * expected  # one root, its multiplicity misread: the count's
    if depth > 60 or (len(inside) > expected and narrow):
        raise RuntimeError(f"cannot separate the {expected} roots in ({lo:.12g}, {hi:.12g}) "
                           f"rad/s in float64 (found {len(inside)}): det Ū_all is not accurate enough there, "
                           "and --digits only refines the roots float64 has found")
    found = list(found)
    if len(inside) < expected:
        (sign_lo, sign_hi), (log_lo, log_hi) = finder.log_det(np.array([lo, hi]))
        if sign_lo * sign_hi < 0:  # with the bracket's own fallback where Newton cannot reach its root
            for members in finder._bracketed(np.array([lo]), np.array([hi]), np.array([log_hi - log_lo])):
                finder._merge(found, members, lo, hi)
        else:
            finder._merge(found, finder.cluster((lo + hi) / 2), lo, hi)
        inside = sorted(r for r in found if lo < r <= hi)
        if len(inside) == expected:
            return inside
    middle = finder._split_point(lo, hi)
    roots = []
    for a, b in ((lo, middle), (middle, hi)):
        roots += finder._isolate(a, b, _root_count(finder, a, b), found, depth + 1)
    return sorted(roots)


def _root_count(finder, lo: float, hi: float) -> int:
    """Roots of det Ū_all in (lo, hi]: the Wittrick–Williams count where it decides (two
    factorisations), else the argument principle's (tens to hundreds of evaluations of
    det beside a close pair: a cantilever's pair 2.5e-6 apart took 5,800 of them to
    isolate at rtol 1e-6)."""
    counted = finder.stiffness_count([], lo, hi)
    return count_zeros(finder.log_det, lo, hi) if counted is None else counted


class SearchAtDefaultRtol(Exception):
    """A search at an rtol looser than the default reached a stretch of roots its
    Wittrick–Williams counts cannot search (:func:`segment`): the caller makes the whole
    search again at the default rtol (:func:`linmstmm.solve.solve_roots`). Not a
    RuntimeError, which the steps of a search catch to try another way: the
    argument-principle search of such a stretch took up to 60,000 evaluations of det on
    clustered roots, where the default rtol's counts, whose ends move off the roots
    (:mod:`~linmstmm.roots.counted_search`), searched it in a few thousand."""


def segment(finder, lo: float, hi: float, expected: int | None = None) -> list[float]:
    """Every root in (lo, hi], rad/s, ascending, repeated per multiplicity.

    By Wittrick–Williams counts where they decide
    (:func:`~linmstmm.roots.counted_search.counted_segment`: bisection on the
    count, each root from its sign change) and agree with ``expected``; where they
    do not and the finder certifies to a looser rtol than the default, it raises
    :class:`SearchAtDefaultRtol`. Else the
    argument-principle count says how many there are; a scan with at
    least ``points_per_root`` points per counted root finds them; bisection
    on the count finds any the scan missed. A segment wider than
    SCAN_OCTAVES (the first one starts at the floor) is split by a count
    first, so an empty bottom is not scanned point by point.
    """
    counted = counted_segment(finder, lo, hi)
    if counted is not None and (expected is None or len(counted) == expected):
        return counted
    if not finder.fine_rtol and finder.counter is not None:
        raise SearchAtDefaultRtol(f"the counts cannot search ({lo:.12g}, {hi:.12g}] rad/s at rtol {finder.rtol:g}")
    if expected is None:
        expected = count_zeros(finder.log_det, lo, hi)
    if expected == 0:
        return []
    if hi / lo > 2.0 ** SCAN_OCTAVES:
        middle = hi / 2.0 ** SCAN_OCTAVES
        below = count_zeros(finder.log_det, lo, middle)
        return finder.segment(lo, middle, below) + finder.segment(middle, hi, expected - below)
    octaves = max(np.log2(hi / lo), 1.0)
    points = max(octaves * finder.points_per_octave, finder.points_per_root * expected)
    grid = np.geomspace(lo, hi, int(np.ceil(points)) + 1)
    return finder._isolate(lo, hi, expected, finder._roots_in(grid, expected))


def lowest(finder, lo: float, hi: float, needed: int | None) -> list[float]:
    """The roots in (lo, hi], or only enough of the lowest to give ``needed``.

    A segment holding far more roots than needed is halved (geometrically)
    and its upper half searched only if the lower one falls short.
    """
    expected = count_zeros(finder.log_det, lo, hi)
    if needed is not None and expected > 2 * needed + 4 and hi > lo * (1 + 1e-3):
        middle = float(np.sqrt(lo * hi))
        lower = finder._lowest(lo, middle, needed)
        return lower if len(lower) >= needed else lower + finder._lowest(middle, hi, needed - len(lower))
    return finder.segment(lo, hi, expected)


def next_top(lo: float, roots: list[float], count: int | None) -> float:
    """Top of the next segment: four times ``lo``, or less if the roots found so
    far say ``count`` is reached sooner (a beam's ω_n grows like n², a
    chain's like n: the n² guess overshoots, which costs less than a miss)."""
    if count is None or len(roots) < 2:
        return 4 * lo
    guess = roots[-1] * ((count + 2) / len(roots)) ** 2
    return min(4 * lo, max(1.25 * lo, guess))


def search(finder, count: int | None, omega_max: float | None) -> list[float]:
    """Elastic roots (rad/s) ascending, each repeated per multiplicity.

    The lowest ``count``, or all up to ``omega_max``, with none missed:
    each scanned segment is checked against the root count. Scans
    upwards from the floor, the first segment up to FIRST_SEGMENT_RATIO ×
    scale. Fewer than ``count`` come back if there are no more below the
    ceiling.
    """
    roots: list[float] = []
    start = FIRST_SEGMENT_RATIO * finder.scale
    lo, hi = finder.floor, min(start, omega_max) if omega_max else start
    while True:
        try:
            roots += finder._lowest(lo, hi, None if count is None else count - len(roots))
        except RuntimeError as error:
            if not roots or lo < 100 * roots[-1]:
                raise
            # Far above the last root of a discrete model, Ū_all is dominated by
            # inertia (ω² m / k beyond 1e15): stop there and say so.
            finder.note = (f"the search stopped at {lo:.4g} rad/s, {lo / roots[-1]:.2g} times the highest, "
                         f"where inertia swamps det Ū_all ({error})")
            break
        done_by_count = count is not None and len(roots) >= count
        done_by_range = omega_max is not None and hi >= omega_max
        if done_by_count or done_by_range or hi >= finder.ceiling:
            break
        lo, hi = hi, finder._next_top(hi, roots, count)
        if omega_max is not None:
            hi = min(hi, omega_max)
    return roots[:count] if count is not None else roots
