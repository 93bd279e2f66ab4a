"""The walk of the carry in compiled code: :func:`walk` records, for flat arrays of a
topology, the program :func:`linmstmm.program._walked` and
:func:`linmstmm.program._assembled` record in Python, to the same integers.

The Python walk stays the readable reference (a test holds both to the same
program on the bundled and random models); this one exists for its cost: on the
launcher the Python walk and the arrays it is turned into took about 0.6 ms of
a model's first solve, more than the solve's evaluations after it.

Sets of columns are bits, :data:`BITS` columns to a word of an int64 array (column
c: bit ``c % BITS`` of word ``c // BITS``), so that unions, overlaps and
equalities are a few word operations and a set's columns come out ascending.
The walk records into arrays of a given room (:func:`walk`'s ``room``); one that
would overflow raises :class:`Full`, and the caller walks again with more.

Inputs (:mod:`linmstmm.compiled_walk` makes them, and names the codes): per
element, in the order of the carry, its kind, index, inputs and joint; per input
a link ``(code, value, set, other set)``: ``FROM_ELEMENT`` (the open state of
element ``value``), ``FROM_CUT`` (side ``value`` = 2 cut + side of a cut that
does not close the carry, entered with the state of its other side: ``set`` its
own selection, ``other set`` the other side's) or ``FROM_TIP`` (a boundary end
or a closing cut's side, ``set`` its selection); the column sets of the
selections and of the joints' jumps.
"""
from __future__ import annotations

from collections import namedtuple

import numpy as np
from numba import njit

from linmstmm.compiled_walk import BEAM_ELEMENT, FROM_CUT, FROM_ELEMENT, RIGID
from linmstmm.program_record import BEAM, CARRY, COMBINE, GEOMETRIC, JOINT, ORTHO, ROW_BLOCK, STATE_BLOCK, TIP

#: Columns to a word of a column set (below 63: no sign bit in an int64).
BITS = 62
#: Place entries the record has room for, per record of the other tables (:func:`walk`'s ``room``).
PLACES_A_RECORD = 16
#: Block groups of the walk, in the order an orthonormalisation looks at them: Ū_all's
#: rows, the open states of elements, the cut sides waiting to enter.
_ROWS, _OPEN, _WAITING = 0, 1, 2


class Full(Exception):
    """The walk's record outgrew the room it was given."""


@njit(cache=True)
def walk(kinds, elements, input_start, links, joints, set_columns, set_start, root_set, root_is_boundary,
         order, element_count, cut_count, final_carries, room):
    """The program of one carry, as :func:`linmstmm.program._walked` and
    :func:`~linmstmm.program._assembled` lay it out.

    Parameters
    ----------
    kinds, elements : (n,) int64
        Kind and element index of each element, in the order of the carry.
    input_start : (n + 1,) int64
        Element i's inputs are ``links[input_start[i]:input_start[i + 1]]``.
    links : (m, 4) int64
        ``(code, value, set, other set)`` of each input (see the module).
    joints : (n, 3) int64
        ``(released directions, force directions among them, set of its jumps)`` of a
        joint, ``(-1, -1, -1)`` for any other element.
    set_columns, set_start : int64
        Column set s is ``set_columns[set_start[s]:set_start[s + 1]]``, ascending.
    root_set : int
        Set of the root's known side (entered negated).
    root_is_boundary : bool
        The root is a boundary end (not a closing cut).
    order : int
        Unknowns of Ū_all before release (every column is below it).
    element_count, cut_count : int
        Elements and cuts of the topology.
    final_carries : int
        :data:`linmstmm.program.FINAL_CARRIES`.
    room : int
        Slots and records of each table the record has room for; place entries, PLACES_A_RECORD times as many.

    Returns
    -------
    tuple
        ``(slot_rows, slot_width, slot_columns, operations, terms, places,
        places_start, orthos, ortho_blocks, root, root_row, geometric_rows,
        row_kinds, matrix_sets, beams, carries, other_inputs, joint_constants)``:
        the Program's arrays of those names; ``matrix_sets`` (K,) per constant the set
        whose selection it is plus one (negated for the root's), 0 for one made
        from the model's numbers; ``beams`` the element of each BEAM record;
        ``carries`` (element, kind, U0, U2), ``other_inputs`` (element, k, U_{j,Ik},
        H_{j,Ik}) and ``joint_constants`` (element, F, E): where each of the
        model's constants goes (:class:`linmstmm.program_constants.Constants`).

    Raises
    ------
    Full
        Where the record needs more than ``room``.
    """
    w = max((order + BITS - 1) // BITS, 1)
    set_words = np.zeros((set_start.size - 1, w), dtype=np.int64)
    for s in range(set_start.size - 1):
        for c in set_columns[set_start[s]:set_start[s + 1]]:
            set_words[s, c // BITS] |= np.int64(1) << (c % BITS)
    r = _record(w, room)
    open_block = np.full(element_count, -1, dtype=np.int64)
    waiting = np.full(2 * cut_count, -1, dtype=np.int64)
    _block(r, _ROWS, _tip(r, set_words[root_set], -(root_set + 1)), 12, -1, ROW_BLOCK)
    inputs = np.empty(links.shape[0], dtype=np.int64)
    term_slots, term_matrices = np.empty(links.shape[0] + 1, np.int64), np.empty(links.shape[0] + 1, np.int64)
    for i in range(kinds.size):
        e, kind = elements[i], kinds[i]
        count = input_start[i + 1] - input_start[i]
        for j in range(count):
            link = links[input_start[i] + j]
            if link[0] == FROM_ELEMENT:
                inputs[j] = _taken(r, open_block[link[1]])
            elif link[0] == FROM_CUT:
                side = link[1]
                if waiting[side] >= 0:
                    inputs[j] = _taken(r, waiting[side])
                    waiting[side] = -1
                else:
                    waiting[side ^ 1] = _block(r, _WAITING, _tip(r, set_words[link[3]], link[3] + 1), 12, -1,
                                               STATE_BLOCK)
                    inputs[j] = _tip(r, set_words[link[2]], link[2] + 1)
            else:
                inputs[j] = _tip(r, set_words[link[2]], link[2] + 1)
        terms = 1  # COMBINE's terms: source slot, matrix (-1: the identity)
        if kind == BEAM_ELEMENT:
            index = _put(r, _BEAMS, e)
            _put(r, _OPERATIONS, BEAM, inputs[0], index, 1, 0, 0)
            state = _orthonormalise(r, inputs[0], True)
            records = r.counts[_RECORDS, _ORTHOS]
            if _orthonormalise(r, state, False) != state:
                raise AssertionError("a beam's orthonormalisation widened its columns twice")
            _put(r, _OPERATIONS, BEAM, state, index, 0, records if r.counts[_RECORDS, _ORTHOS] > records else -1, 0)
            term_slots[0], term_matrices[0] = state, -1
        else:
            carried = _slot(r, 12, r.masks[inputs[0]])
            kinematic = _valued(r)
            inertial = _valued(r) if kind == RIGID else -1
            _put(r, _CARRIES, e, kind, kinematic, inertial)
            _put(r, _OPERATIONS, CARRY, carried, inputs[0], kinematic, inertial, 0)
            term_slots[0], term_matrices[0] = carried, -1
            if joints[i, 0] >= 0:
                term_slots[1], term_matrices[1] = _joint(r, e, joints[i], inputs[0], set_words), -1
                terms = 2
        for k in range(count - 1):
            other = inputs[k + 1]
            forces, incidence = _valued(r), _valued(r)
            _put(r, _OTHER_INPUTS, e, k, forces, incidence)
            term_slots[terms], term_matrices[terms] = other, forces
            terms += 1
            union = r.masks[inputs[0]] | r.masks[other]
            row = _slot(r, 6, union)
            _put(r, _OPERATIONS, GEOMETRIC, row, inputs[0], other, incidence, r.counts[_RECORDS, _PLACES])
            _place(r, r.masks[inputs[0]], union)
            _place(r, r.masks[other], union)
            _block(r, _ROWS, row, 6, -1, ROW_BLOCK)
        state = term_slots[0] if terms == 1 else _combined(r, term_slots[:terms], term_matrices[:terms])
        open_block[e] = _block(r, _OPEN, _orthonormalise(r, state, True), 12, -1, STATE_BLOCK)
    root = r.store[_at(r, _BLOCKS, open_block[elements[-1]])]
    if root_is_boundary:
        _leave_final_orthos_to_the_lu(r, final_carries)
    return _arrays(r, root)


#: The record's tables (:data:`_Record`), each a run of the store of records of a width:
#: slots' rows; operations, COMBINE's terms, place entries, where each place starts
#: (after a first 0), orthonormalisations and their blocks as the Program has them;
#: each constant's set (:func:`walk`'s ``matrix_sets``), BEAM records' elements, and
#: where the model's constants go (carries, other inputs, joints); the blocks an
#: orthonormalisation may gather (:data:`_BLOCK_FIELDS`).
(_SLOT_ROWS, _OPERATIONS, _TERMS, _PLACE_ENTRIES, _PLACES, _ORTHOS, _ORTHO_BLOCKS, _MATRICES, _BEAMS, _CARRIES,
 _OTHER_INPUTS, _JOINT_CONSTANTS, _BLOCKS) = range(13)
_WIDTHS = (1, 6, 3, 1, 1, 5, 6, 1, 1, 4, 4, 3, 6)
#: A block's fields: its slot (rewritten when an orthonormalisation widens it), rows,
#: force rows, kind, group (_ROWS, _OPEN, _WAITING) and 1 while it is open (a state or cut
#: side not yet taken as an input).
_SLOT, _ROWS_FIELD, _FORCES, _KIND, _GROUP, _OPEN_FIELD = range(6)
#: Rows of the record's counts: records of each table so far, where its run of the store
#: starts (one more entry: where the last ends), its width.
_RECORDS, _START, _WIDTH = range(3)
#: What the walk records: the tables' ``store`` (int64), ``masks`` (room, w) int64
#: each slot's column words, ``counts`` (3, tables + 1) int64 (see above). Three arrays,
#: not one a table: numba hands a tuple to every call whole.
_Record = namedtuple("_Record", ("store", "masks", "counts"))


@njit(cache=True)
def _record(w, room):
    counts = np.zeros((3, len(_WIDTHS) + 1), dtype=np.int64)
    for t in range(len(_WIDTHS)):
        counts[_WIDTH, t] = _WIDTHS[t]
        records = room * (PLACES_A_RECORD if t == _PLACE_ENTRIES else 1) + (1 if t == _PLACES else 0)
        counts[_START, t + 1] = counts[_START, t] + records * _WIDTHS[t]
    store = np.empty(counts[_START, -1], dtype=np.int64)
    store[counts[_START, _PLACES]] = 0  # where the first place starts, before the table's records
    counts[_START, _PLACES] += 1
    return _Record(store, np.empty((room, w), np.int64), counts)


@njit(cache=True)
def _at(r, table, index):
    """Where record ``index`` of ``table`` starts in the store."""
    return r.counts[_START, table] + index * r.counts[_WIDTH, table]


@njit(cache=True)
def _put(r, table, *record):
    """Append ``record`` to ``table``; returns the record's index."""
    index = r.counts[_RECORDS, table]
    at = _at(r, table, index)
    if at + len(record) > r.counts[_START, table + 1]:
        raise Full("the walk needs more room")
    for value in record:
        r.store[at] = value
        at += 1
    r.counts[_RECORDS, table] = index + 1
    return index


@njit(cache=True)
def _block(r, group, slot, rows, forces, kind):
    """Index of a new open block."""
    return _put(r, _BLOCKS, slot, rows, forces, kind, group, 1)


@njit(cache=True)
def _taken(r, block):
    """The slot of open ``block``, which is taken (no longer open)."""
    at = _at(r, _BLOCKS, block)
    r.store[at + _OPEN_FIELD] = 0
    return r.store[at + _SLOT]


@njit(cache=True)
def _slot(r, rows, words):
    """Index of a new slot of ``rows`` rows on the columns ``words``."""
    s = _put(r, _SLOT_ROWS, rows)
    if s >= r.masks.shape[0]:
        raise Full("the walk needs more room")
    r.masks[s] = words
    return s


@njit(cache=True)
def _valued(r):
    """Index of a new constant made from the model's numbers."""
    return _put(r, _MATRICES, 0)


@njit(cache=True)
def _tip(r, words, matrix_set):
    """Slot of a selection's state: a TIP of the constant ``matrix_set`` (walk's ``matrix_sets``)."""
    slot = _slot(r, 12, words)
    _put(r, _OPERATIONS, TIP, slot, _put(r, _MATRICES, matrix_set), 0, 0, 0)
    return slot


@njit(cache=True)
def _place(r, columns, onto):
    """Index of a new place: where each of the columns ``columns`` stands among ``onto`` (a superset)."""
    position = 0
    for k in range(onto.size):
        for b in range(BITS):
            bit = np.int64(1) << b
            if onto[k] & bit:
                if columns[k] & bit:
                    _put(r, _PLACE_ENTRIES, position)
                position += 1
    return _put(r, _PLACES, r.counts[_RECORDS, _PLACE_ENTRIES])  # where the next place starts


@njit(cache=True)
def _count(words):
    """Columns among ``words``."""
    count = 0
    for word in words:
        while word:
            word &= word - 1
            count += 1
    return count


@njit(cache=True)
def _combined(r, slots, matrices):
    """New slot = Σ matrix @ source over the union of the sources' columns (COMBINE)."""
    union = r.masks[slots[0]].copy()
    for slot in slots:
        union |= r.masks[slot]
    dst = _slot(r, 12, union)
    first = r.counts[_RECORDS, _TERMS]
    for k in range(slots.size):
        _put(r, _TERMS, slots[k], matrices[k], _place(r, r.masks[slots[k]], union))
    _put(r, _OPERATIONS, COMBINE, dst, first, slots.size, 0, 0)
    return dst


@njit(cache=True)
def _joint(r, e, joint, state, set_words):
    """A joint's row (JOINT) on its input ``state``; returns the slot of its jumps' state."""
    row = _slot(r, joint[0], r.masks[state])
    force, jump = _valued(r), _valued(r)
    _put(r, _JOINT_CONSTANTS, e, force, jump)
    _put(r, _OPERATIONS, JOINT, row, state, force, 0, 0)
    _block(r, _ROWS, row, joint[0], joint[1], ROW_BLOCK)
    jumps = _slot(r, 12, set_words[joint[2]])
    _put(r, _OPERATIONS, TIP, jumps, jump, 0, 0, 0)
    return jumps


@njit(cache=True)
def _orthonormalise(r, state, emit):
    """Mirror of the Python walk's: the blocks sharing columns with ``state`` (and with
    those, in turn) gathered, laid out on their union and orthonormalised; returns the
    state's new slot (``state`` where too few rows to orthonormalise). ``emit``: False to
    record it without an ORTHO operation."""
    columns = r.masks[state].copy()
    n, store, masks = r.counts[_RECORDS, _BLOCKS], r.store, r.masks
    blocks = store[r.counts[_START, _BLOCKS]:r.counts[_START, _BLOCKS] + 6 * n].reshape(n, 6)
    chosen = np.zeros(n, dtype=np.bool_)
    grown = True
    while grown:
        grown = False
        for group in range(3):
            for i in range(n):
                if blocks[i, _GROUP] != group or not blocks[i, _OPEN_FIELD] or chosen[i]:
                    continue
                slot = blocks[i, _SLOT]
                if _shared(masks, slot, columns):
                    chosen[i] = grown = True
                    for k in range(columns.size):
                        columns[k] |= masks[slot, k]
    rows = 12
    for i in range(n):
        if chosen[i]:
            rows += blocks[i, _ROWS_FIELD]
    width = _count(columns)
    if rows < width:  # fewer rows than columns: never orthonormalised
        return state
    first = r.counts[_RECORDS, _ORTHO_BLOCKS]
    taken = 0
    for group in range(3):
        for i in range(n):
            if chosen[i] and blocks[i, _GROUP] == group:
                blocks[i, _SLOT] = _laid(r, blocks[i, _SLOT], columns, blocks[i, _ROWS_FIELD], blocks[i, _KIND],
                                         blocks[i, _FORCES])
                taken += 1
    dst = _laid(r, state, columns, 12, STATE_BLOCK, -1)
    ortho = _put(r, _ORTHOS, first, taken + 1, taken, width, 0)
    if emit:
        _put(r, _OPERATIONS, ORTHO, ortho, 0, 0, 0, 0)
    return dst


@njit(cache=True)
def _shared(masks, slot, columns):
    """True where ``slot``'s columns (rows of ``masks``) and ``columns`` share one."""
    for k in range(columns.size):
        if masks[slot, k] & columns[k]:
            return True
    return False


@njit(cache=True)
def _same(masks, slot, columns):
    """True where ``slot``'s columns (rows of ``masks``) are ``columns``."""
    for k in range(columns.size):
        if masks[slot, k] != columns[k]:
            return False
    return True


@njit(cache=True)
def _laid(r, src, columns, rows, kind, forces):
    """Slot of block ``src`` laid out on ``columns`` (``src`` itself where those are its
    own), recorded as an orthonormalisation's block."""
    if _same(r.masks, src, columns):
        dst, place = src, -1
    else:
        dst = _slot(r, rows, columns)
        place = _place(r, r.masks[src], columns)
    _put(r, _ORTHO_BLOCKS, src, dst, rows, kind, place, forces)
    return dst


@njit(cache=True)
def _leave_final_orthos_to_the_lu(r, final_carries):
    """Mark the orthonormalisations after which at most ``final_carries`` carries and no
    beam remain as layout only (:data:`linmstmm.program.FINAL_CARRIES`)."""
    carries = 0
    operations = _table(r, _OPERATIONS)
    orthos = _table(r, _ORTHOS)
    for p in range(operations.shape[0] - 1, -1, -1):
        code, index = operations[p, 0], operations[p, 1]
        if code == BEAM:
            return
        if code == CARRY:
            carries += 1
            if carries > final_carries:
                return
        if code == ORTHO:
            orthos[index, 4] = 1


@njit(cache=True)
def _table(r, table):
    """(records, width) view of ``table``'s records so far."""
    start, records, width = r.counts[_START, table], r.counts[_RECORDS, table], r.counts[_WIDTH, table]
    return r.store[start:start + records * width].reshape(records, width)


@njit(cache=True)
def _arrays(r, root):
    """:func:`walk`'s answer from its record ``r`` and the root's slot."""
    slots = r.counts[_RECORDS, _SLOT_ROWS]
    slot_width = np.empty(slots, dtype=np.int64)
    for s in range(slots):
        slot_width[s] = _count(r.masks[s])
    slot_columns = np.empty(slot_width.sum(), dtype=np.int64)
    at = 0
    for s in range(slots):
        for k in range(r.masks.shape[1]):
            word = r.masks[s, k]
            for b in range(BITS):
                if word & (np.int64(1) << b):
                    slot_columns[at] = k * BITS + b
                    at += 1
    blocks = _table(r, _BLOCKS)
    rows = 0
    for i in range(blocks.shape[0]):
        if blocks[i, _GROUP] == _ROWS:
            rows += blocks[i, _ROWS_FIELD]
    row_slots, row_kinds = np.empty(blocks.shape[0], np.int64), np.empty(rows, np.int64)
    count = at = 0
    for i in range(blocks.shape[0]):
        if blocks[i, _GROUP] == _ROWS:
            row_slots[count] = blocks[i, _SLOT]
            count += 1
            for k in range(blocks[i, _ROWS_FIELD]):  # a joint's force rows, then moments; else three rows per kind
                forces = blocks[i, _FORCES]
                row_kinds[at] = k // 3 if forces < 0 else 3 if k < forces else 2
                at += 1
    return (_column(r, _SLOT_ROWS), slot_width, slot_columns, _table(r, _OPERATIONS).copy(),
            _table(r, _TERMS).copy(), _column(r, _PLACE_ENTRIES), _column(r, _PLACES, 1), _table(r, _ORTHOS).copy(),
            _table(r, _ORTHO_BLOCKS).copy(), root, row_slots[0], row_slots[1:count].copy(), row_kinds,
            _column(r, _MATRICES), _column(r, _BEAMS), _table(r, _CARRIES).copy(), _table(r, _OTHER_INPUTS).copy(),
            _table(r, _JOINT_CONSTANTS).copy())


@njit(cache=True)
def _column(r, table, first=0):
    """(first + records,) copy of the one-integer ``table`` (with ``first`` entries before its records)."""
    start = r.counts[_START, table] - first
    return r.store[start:start + first + r.counts[_RECORDS, table]].copy()
