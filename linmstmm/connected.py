"""Whether the elements of a model form one connected structure: each reached
from every other through the points they share (a boundary condition holds a
point; it joins nothing)."""
from __future__ import annotations


def unreached(joined) -> list:
    """The elements not reached from the first one through shared points.

    Parameters
    ----------
    joined : sequence of (str, sequence of str)
        Each element's name and the points it joins (a rigid body's ports, a
        beam's or spring's ends), in order.

    Returns
    -------
    list of (str, sequence of str)
        The entries of ``joined`` apart from the first one's structure, in
        order (empty for a connected model).
    """
    if not joined:
        return []
    reached, points = {0}, set(joined[0][1])
    grown = True
    while grown:
        grown = False
        for i, (_, ends) in enumerate(joined):
            if i not in reached and points.intersection(ends):
                reached.add(i)
                points.update(ends)
                grown = True
    return [entry for i, entry in enumerate(joined) if i not in reached]
