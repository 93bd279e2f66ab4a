"""What each unknown of Ū_all is: the state vector's row it stands in, and its label.

The unknowns (:mod:`linmstmm.deduction`) are six per boundary end (a free
displacement, or the force of a fixed component), twelve per loop cut (the
state on side 0) and one per released direction of a joint (the jump across it),
in that order.
"""
from __future__ import annotations

import numpy as np

from linmstmm.elements.frames import FORCE_INDEX
from linmstmm.model import COMPONENTS

#: The twelve entries of a state vector (displacements, rotations, moments, forces).
STATE_NAMES = ("X", "Y", "Z", "Θx", "Θy", "Θz", "Mx", "My", "Mz", "Qx", "Qy", "Qz")


def boundary_state_rows(boundaries) -> list[list[int]]:
    """The state vector's row each boundary end's six unknowns stand in.

    Parameters
    ----------
    boundaries : list of linmstmm.topology.Boundary
        The boundary ends.

    Returns
    -------
    list of list of int
        Per end, six rows: a free displacement's own (component c), a fixed one's
        force (FORCE_INDEX[c]); found for all ends at once (read entry by entry from
        the fixed masks it was half a launcher's deduction).
    """
    if not boundaries:
        return []
    fixed = np.array([boundary.fixed for boundary in boundaries], dtype=bool)
    return np.where(fixed, FORCE_INDEX, np.arange(6)).tolist()


def column_labels(topology, boundary_rows: list, jump_elements) -> list[str]:
    """A label per unknown, e.g. ``"tyre1.Qz"``, ``"cut p3.Mx"``, ``"pin.Δrz"``, in order.

    Parameters
    ----------
    topology : linmstmm.topology.Topology
        The model's deduced structure.
    boundary_rows : list of list of int
        :func:`boundary_state_rows` of its boundary ends.
    jump_elements : iterable of int
        The joints with released directions, in order (each element's jumps are
        labelled by its released directions).

    Returns
    -------
    list of str
    """
    labels = [f"{boundary.label}.{STATE_NAMES[row]}"
              for boundary, rows in zip(topology.boundaries, boundary_rows) for row in rows]
    labels += [f"cut {cut.point}.{name}" for cut in topology.cuts for name in STATE_NAMES]
    for e in jump_elements:
        element = topology.elements[e]
        labels += [f"{element.name}.Δ{COMPONENTS[d]}" for d in element.record.released]
    return labels
