"""The last check of a search for the lowest ``count`` roots: the list it ends with must
hold as many roots up to its highest as the Wittrick–Williams count finds there.

A search assembles its list from many steps (predictions, pencil polish, clusters
parted by counts or circles); each certifies its own stretch, but a multiplicity read
over a circle that passed through a neighbour, or a copy a step dropped, changes the
total without a word. The count at the top catches both: an octahedral star of one beam
an arm, planes 1e-6 apart, asked for its 30 lowest at rtol 1e-12, listed 8 values in a
cluster of three double roots and lost the two highest of the 30; planes 2e-6 apart at
rtol 1e-6, six beams an arm, its search dropped a copy and came back with 17 of the 20
lowest, "only 17 exist".
"""
from __future__ import annotations

from linmstmm.roots.certify import near_widths


def check_listed(finder, found: list[float], count: int) -> None:
    """Raise RuntimeError where ``found`` (rad/s, ascending, repeated per multiplicity),
    the end of a search for the lowest ``count`` elastic roots, disagrees with the count.

    Fewer than ``count``: the count at the finder's ceiling must not find more (made with
    the late counter where the model has no other,
    :meth:`~linmstmm.roots.RootFinder.counter_for_stretch`: this is rare). Otherwise, with
    a counter already made, across the highest value r listed k times among n: the count
    just above r must find at least n (none listed that is not there; a list may end
    inside a multiple root, so more is fine), and the count just below r at most n − k
    (none missing below it). Each count is made at the narrowest width at which it
    decides, from the finder's rtol up (:func:`~linmstmm.roots.certify.near_widths`: a
    value at a loose rtol may stand that far from its root). Not checked across a value
    float64 could not place (its last step above the finder's rtol, or one of
    :attr:`~linmstmm.roots.RootFinder.unseparated`), which is refined or named after the
    search."""
    if len(found) < count:
        _check_fewer(finder, len(found))
        return
    if finder.counter is None or not found:
        return
    top = found[-1]
    if top in finder.unseparated or finder.last_step.get(top, 0.0) > finder.rtol:
        return
    listed, copies = len(found), found.count(top)
    above, below = _count_beside(finder, top, 1), _count_beside(finder, top, -1)
    if above is not None and above < listed:
        raise RuntimeError(f"the search listed {listed} roots up to {top:.12g} rad/s, where the count finds {above}")
    if below is not None and below > listed - copies:
        raise RuntimeError(f"the search listed {listed - copies} roots below {top:.12g} rad/s, where the count "
                           f"finds {below}")


def _check_fewer(finder, found: int) -> None:
    """Raise RuntimeError where a search that ended with ``found`` roots, fewer than it
    was asked for, has more below the finder's ceiling by the count; without a count
    it stands."""
    finder.counter_for_stretch()
    total = finder.stiffness_count([], None, finder.ceiling)
    if total is not None and total > found:
        raise RuntimeError(f"the search ended with {found} roots where the count finds {total} "
                           f"below {finder.ceiling:.3g} rad/s")


def _count_beside(finder, root: float, side: int) -> int | None:
    """Elastic natural frequencies below ``root`` (rad/s) moved by the narrowest of the
    finder's :func:`~linmstmm.roots.certify.near_widths` at which the count decides, up
    (``side`` +1) or down (−1); None where none does."""
    for width in near_widths(finder.rtol):
        counted = finder.stiffness_count([], None, root * (1 + side * width))
        if counted is not None:
            return counted
    return None
