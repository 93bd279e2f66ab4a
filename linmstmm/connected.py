"""Whether the elements of a model form one connected structure: each reached
from every other through the points they share (a boundary condition holds a
point; it joins nothing)."""
from __future__ import annotations

from linmstmm.union_find import components


def unreached(joined) -> list:
    """The elements not reached from the first one through shared points.

    The points each element joins are one component (:func:`linmstmm.union_find.components`),
    in time about linear in the number of elements: a 10,000-body chain's check took
    38 s when each pass over the elements reached one more of them.

    Parameters
    ----------
    joined : sequence of (str, sequence of str)
        Each element's name and the points it joins (a rigid body's ports, a
        beam's or spring's ends), in order; at least one point each.

    Returns
    -------
    list of (str, sequence of str)
        The entries of ``joined`` apart from the first one's structure, in
        order (empty for a connected model).
    """
    if not joined:
        return []
    number: dict[str, int] = {}
    for _, ends in joined:
        for point in ends:
            number.setdefault(point, len(number))
    edges = [(number[ends[0]], number[point]) for _, ends in joined for point in ends[1:]]
    part = components(len(number), edges)
    first = part[number[joined[0][1][0]]]
    return [entry for entry in joined if part[number[entry[1][0]]] != first]
