"""The walk of the carry by the compiled kernel (:func:`linmstmm._walk_kernels.walk`):
its inputs made from a deduction, and its answer made into a program's arrays and
constants.

numba is loaded on the first call, not on import, so that the numpy engine, which
never compiles a program, never starts it.
"""
from __future__ import annotations

import numpy as np

from linmstmm.program_constants import Constants

#: Element kinds as the kernel takes them (compiled into its cache, as the link codes
#: below: after a change, see :mod:`linmstmm._walk_kernels`).
RIGID, SPRING, JUNCTION, BEAM_ELEMENT = 0, 1, 2, 3
_KIND_CODES = {"rigid": RIGID, "spring": SPRING, "junction": JUNCTION, "beam": BEAM_ELEMENT}
_KIND_NAMES = {code: kind for kind, code in _KIND_CODES.items()}
#: Input links as the kernel takes them: the open state of an element, a side of a cut
#: that does not close the carry (entered with its other side's state), a selection (a
#: boundary end, a closing cut's side).
FROM_ELEMENT, FROM_CUT, FROM_TIP = 0, 1, 2


def compiled_walk(deduction, final_carries: int) -> tuple[dict, Constants, tuple]:
    """The program of ``deduction``'s carry, walked by the compiled kernel.

    Parameters
    ----------
    deduction : Deduction
        The deduced system, any indeterminate unknowns released.
    final_carries : int
        :data:`linmstmm.godunov.FINAL_CARRIES`.

    Returns
    -------
    fields : dict
        The Program's ``slot_rows``, ``slot_width``, ``slot_columns``, ``operations``,
        ``terms``, ``places``, ``places_start``, ``matrices`` (K, 12, 12, the
        model's numbers in them), ``orthos``, ``ortho_blocks``, ``root``,
        ``root_row``, ``geometric_rows`` and ``row_kinds``, as the Python walk
        (:func:`linmstmm.program._walked`) lays them out.
    constants : Constants
        Where the model's numbers go among the matrices.
    beams : tuple of int
        Element index of each BEAM record.
    """
    arrays, selections = _walk_input(deduction)
    (slot_rows, slot_width, slot_columns, operations, terms, places, places_start, orthos, ortho_blocks, root,
     root_row, geometric_rows, row_kinds, matrix_sets, beams, carries, other_inputs,
     joints) = _walked(arrays, final_carries, ROOM_AN_INPUT * arrays[3].shape[0])
    constants = _constants(carries, other_inputs, joints)
    matrices = np.zeros((matrix_sets.size, 12, 12))
    selected = np.flatnonzero(matrix_sets)
    for k, code in zip(selected.tolist(), matrix_sets[selected].tolist()):
        selection = selections[abs(code) - 1]
        matrices[k, :, :selection.shape[1]] = selection if code > 0 else -selection
    constants.fill(deduction, matrices)
    fields = dict(slot_rows=slot_rows, slot_width=slot_width, slot_columns=slot_columns, operations=operations,
                  terms=terms, places=places, places_start=places_start, matrices=matrices, orthos=orthos,
                  ortho_blocks=ortho_blocks, root=int(root), root_row=int(root_row), geometric_rows=geometric_rows,
                  row_kinds=row_kinds)
    return fields, constants, tuple(beams.tolist())


#: The walk's first room (:func:`linmstmm._walk_kernels.walk`) per input of an element: on
#: the launchers and the bundled and random models at most 8 are used.
ROOM_AN_INPUT = 16


def _walked(arrays: tuple, final_carries: int, room: int) -> tuple:
    """:func:`linmstmm._walk_kernels.walk` of ``arrays``, with ``room`` or, where that
    is too little, four times as much, and so on."""
    from linmstmm._walk_kernels import Full, walk  # numba loads here

    try:
        return walk(*arrays, final_carries, room)
    except Full:
        return _walked(arrays, final_carries, 4 * room)


def _walk_input(deduction) -> tuple[tuple, list]:
    """(the kernel's arguments but the last, each column set's selection (12, k), None
    for a joint's jumps): the topology of ``deduction`` as flat arrays (see
    :mod:`linmstmm._walk_kernels`)."""
    topology = deduction.topology
    elements = topology.elements
    sets, selections, set_of = [], [], {}

    def selection_set(link) -> int:
        if link not in set_of:
            columns, selection = deduction.tip_selection(link)
            set_of[link] = len(sets)
            sets.append(columns)
            selections.append(selection)
        return set_of[link]

    root_set = selection_set(topology.root if topology.root[0] == "boundary" else ("cut", topology.root[1], 0))
    order = topology.order
    kinds, input_start, links, joints = [], [0], [], []  # links and joints flat, four and three a row
    for e in order:
        element = elements[e]
        kinds.append(_KIND_CODES[element.kind])
        for p in element.inputs:
            link = element.ports[p].link
            if link[0] == "element":
                links += (FROM_ELEMENT, link[1], 0, 0)
            elif link[0] == "cut" and not topology.cuts[link[1]].closing:
                _, c, side = link
                links += (FROM_CUT, 2 * c + side, selection_set(link), selection_set(("cut", c, 1 - side)))
            else:
                links += (FROM_TIP, 0, selection_set(link), 0)
        input_start.append(len(links) // 4)
        if e in deduction.jump_columns:
            released = element.record.released
            joints += (released.size, int((released < 3).sum()), len(sets))
            sets.append(deduction.jump_selection(e)[0])
            selections.append(None)
        else:
            joints += _NO_JOINT
    set_start = np.zeros(len(sets) + 1, dtype=np.int64)
    np.cumsum([columns.size for columns in sets], out=set_start[1:])
    arrays = (np.array(kinds, dtype=np.int64), np.array(order, dtype=np.int64),
              np.array(input_start, dtype=np.int64), np.array(links, dtype=np.int64).reshape(-1, 4),
              np.array(joints, dtype=np.int64).reshape(-1, 3), np.concatenate(sets).astype(np.int64, copy=False),
              set_start, root_set, topology.root[0] == "boundary", deduction.full_order, len(elements),
              len(topology.cuts))
    return arrays, selections


#: A joint's entry for an element that is none (:func:`_walk_input`).
_NO_JOINT = (-1, -1, -1)


def _constants(carries: np.ndarray, other_inputs: np.ndarray, joints: np.ndarray) -> Constants:
    """The walk's :class:`Constants` from its records: ``carries`` (element, kind, U0,
    U2), ``other_inputs`` (element, k, U_{j,Ik}, H_{j,Ik}), ``joints`` (element, F, E)."""
    constants = Constants()
    for e, kind, kinematic, inertial in carries.tolist():
        constants.carry(e, _KIND_NAMES[kind], kinematic, inertial)
    constants.other_input = [tuple(entry) for entry in other_inputs.tolist()]
    constants.joint = [tuple(entry) for entry in joints.tolist()]
    return constants
