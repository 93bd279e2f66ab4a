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

Kept whole: numba invalidates a cached kernel when the file that defines it
changes, not when a kernel it calls in another file does; split, an edit to
the record's accessors would leave the walk running the old code from the cache.
The cached walk also keeps the integers it reads from other modules, which numba
compiles in as constants: the element kinds and link codes of
:mod:`linmstmm.compiled_walk` and the operation codes and block kinds of
:mod:`linmstmm.program_record`. After a change to any of them, touch this file (or
delete its cache), or the cached walk records the old codes.
"""
from __future__ import annotations

from collections import namedtuple

import numpy as np
from numba import njit

from linmstmm._compile_notice import announce_compiles
from linmstmm.compiled_walk import BEAM_ELEMENT, FROM_CUT, FROM_ELEMENT, RIGID
from linmstmm import program_record

announce_compiles()  # one line on stderr if this run compiles (linmstmm._compile_notice)

#: Columns to a word of a column set (below 63: no sign bit in an int64).
BITS = 62
#: Place entries the record has room for, per record of the other tables (:func:`walk`'s ``room``).
PLACES_A_RECORD = 16
#: Block groups of the walk, in the order an orthonormalisation looks at them: Ū_all's
#: rows, the open states of elements, the cut sides waiting to enter. (Every index a
#: kernel here hands another is an np.int64, not an int: numba compiles a callee anew
#: for each int constant it is given, which made this module's first compile twice as long.)
_ROWS, _OPEN, _WAITING = (np.int64(g) for g in range(3))
#: The program's operation codes and block kinds (:mod:`linmstmm.program_record`), and the
#: integers the walk hands its kernels as they stand in a record.
BEAM, CARRY, COMBINE, GEOMETRIC, JOINT, ORTHO, TIP, ROW_BLOCK, STATE_BLOCK = (
    np.int64(getattr(program_record, name))
    for name in ("BEAM", "CARRY", "COMBINE", "GEOMETRIC", "JOINT", "ORTHO", "TIP", "ROW_BLOCK", "STATE_BLOCK"))
_NONE, _ZERO, _ONE, _GEOMETRIC_ROWS, _STATE_ROWS = (np.int64(v) for v in (-1, 0, 1, 6, 12))
#: Whether an orthonormalisation is recorded with an ORTHO operation (:func:`_orthonormalise`).
_EMIT, _QUIET = np.bool_(True), np.bool_(False)


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
        :data:`linmstmm.godunov.FINAL_CARRIES`.
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
    _block(r, _ROWS, _tip(r, set_words[root_set], -(root_set + 1)), _STATE_ROWS, _NONE, ROW_BLOCK)
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
                    waiting[side ^ 1] = _block(r, _WAITING, _tip(r, set_words[link[3]], link[3] + 1), _STATE_ROWS, _NONE,
                                               STATE_BLOCK)
                    inputs[j] = _tip(r, set_words[link[2]], link[2] + 1)
            else:
                inputs[j] = _tip(r, set_words[link[2]], link[2] + 1)
        terms = 1  # COMBINE's terms: source slot, matrix (-1: the identity)
        if kind == BEAM_ELEMENT:
            index = _push(r, _BEAMS, e)
            _put(r, _OPERATIONS, BEAM, inputs[0], index, _ONE, _ZERO, _ZERO)
            state = _orthonormalise(r, inputs[0], _EMIT)
            records = r.counts[_RECORDS, _ORTHOS]
            if _orthonormalise(r, state, _QUIET) != state:
                raise AssertionError("a beam's orthonormalisation widened its columns twice")
            _put(r, _OPERATIONS, BEAM, state, index, _ZERO, records if r.counts[_RECORDS, _ORTHOS] > records else -1, _ZERO)
            term_slots[0], term_matrices[0] = state, -1
        else:
            carried = _slot(r, _STATE_ROWS, r.masks[inputs[0]])
            kinematic = _valued(r)
            inertial = _valued(r) if kind == RIGID else -1
            _put(r, _CARRIES, e, kind, kinematic, inertial, _ZERO, _ZERO)
            _put(r, _OPERATIONS, CARRY, carried, inputs[0], kinematic, inertial, _ZERO)
            term_slots[0], term_matrices[0] = carried, -1
            if joints[i, 0] >= 0:
                term_slots[1], term_matrices[1] = _joint(r, e, joints[i], inputs[0], set_words), -1
                terms = 2
        for k in range(count - 1):
            other = inputs[k + 1]
            forces, incidence = _valued(r), _valued(r)
            _put(r, _OTHER_INPUTS, e, k, forces, incidence, _ZERO, _ZERO)
            term_slots[terms], term_matrices[terms] = other, forces
            terms += 1
            union = _union(r.masks, inputs[0], other)
            row = _slot(r, _GEOMETRIC_ROWS, union)
            _put(r, _OPERATIONS, GEOMETRIC, row, inputs[0], other, incidence, r.counts[_RECORDS, _PLACES])
            _place(r, r.masks[inputs[0]], union)
            _place(r, r.masks[other], union)
            _block(r, _ROWS, row, _GEOMETRIC_ROWS, _NONE, ROW_BLOCK)
        state = term_slots[0] if terms == 1 else _combined(r, term_slots[:terms], term_matrices[:terms])
        open_block[e] = _block(r, _OPEN, _orthonormalise(r, state, _EMIT), _STATE_ROWS, _NONE, STATE_BLOCK)
    root = r.store[_at(r, _BLOCKS, open_block[elements[-1]])]
    if root_is_boundary:
        _leave_final_orthos_to_the_lu(r, final_carries)
    return _arrays(r, root)


#: The record's tables (:data:`_Record`), each a run of the store of records of a width:
#: slots' rows; operations, COMBINE's terms, place entries, where each place starts
#: (after a first 0), orthonormalisations and their blocks as the Program has them;
#: each constant's set (:func:`walk`'s ``matrix_sets``), BEAM records' elements, and
#: where the model's constants go (carries, other inputs, joints); the blocks an
#: orthonormalisation may gather (their fields below).
(_SLOT_ROWS, _OPERATIONS, _TERMS, _PLACE_ENTRIES, _PLACES, _ORTHOS, _ORTHO_BLOCKS, _MATRICES, _BEAMS, _CARRIES,
 _OTHER_INPUTS, _JOINT_CONSTANTS, _BLOCKS) = (np.int64(t) for t in range(13))
_WIDTHS = (1, 6, 3, 1, 1, 5, 6, 1, 1, 4, 4, 3, 6)
#: A block's fields: its slot (rewritten when an orthonormalisation widens it), rows,
#: force rows, kind, group (_ROWS, _OPEN, _WAITING) and 1 while it is open (a state or cut
#: side not yet taken as an input).
_SLOT, _ROWS_FIELD, _FORCES, _KIND, _GROUP, _OPEN_FIELD = (np.int64(f) for f in range(6))
#: Rows of the record's counts: records of each table so far, where its run of the store
#: starts (one more entry: where the last ends), its width.
_RECORDS, _START, _WIDTH = (np.int64(c) for c in range(3))
#: What the walk records: the tables' ``store`` (int64), ``masks`` (room, w) int64
#: each slot's column words, ``counts`` (3, tables + 1) int64 (see above). Three arrays,
#: not one a table: numba hands a tuple to every call whole.
_Record = namedtuple("_Record", ("store", "masks", "counts"))


@njit
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


@njit(inline="always")  # the record's accessors are inlined where they are called (a call cost more than they do)
def _at(r, table, index):
    """Where record ``index`` of ``table`` starts in the store."""
    return r.counts[_START, table] + index * r.counts[_WIDTH, table]


@njit(inline="always")
def _put(r, table, a, b, c, d, e, f):
    """Append the record ``(a, b, c, d, e, f)``, cut to ``table``'s width, to ``table``;
    returns the record's index."""
    index, width = r.counts[_RECORDS, table], r.counts[_WIDTH, table]
    at = r.counts[_START, table] + index * width
    if at + width > r.counts[_START, table + 1]:
        raise Full("the walk needs more room")
    store = r.store
    store[at] = a
    if width > 1:
        store[at + 1] = b
    if width > 2:
        store[at + 2] = c
    if width > 3:
        store[at + 3] = d
    if width > 4:
        store[at + 4] = e
    if width > 5:
        store[at + 5] = f
    r.counts[_RECORDS, table] = index + 1
    return index


@njit(inline="always")
def _push(r, table, value):
    """Append ``value`` to the one-integer ``table``; returns its index."""
    return _put(r, table, value, _ZERO, _ZERO, _ZERO, _ZERO, _ZERO)


@njit
def _block(r, group, slot, rows, forces, kind):
    """Index of a new open block."""
    return _put(r, _BLOCKS, slot, rows, forces, kind, group, _ONE)


@njit
def _taken(r, block):
    """The slot of open ``block``, which is taken (no longer open)."""
    at = _at(r, _BLOCKS, block)
    r.store[at + _OPEN_FIELD] = 0
    return r.store[at + _SLOT]


@njit
def _slot(r, rows, words):
    """Index of a new slot of ``rows`` rows on the columns ``words``."""
    s = _push(r, _SLOT_ROWS, rows)  # raises Full past the room, which is masks' rows too
    for k in range(words.size):
        r.masks[s, k] = words[k]
    return s


@njit
def _valued(r):
    """Index of a new constant made from the model's numbers."""
    return _push(r, _MATRICES, _ZERO)


@njit
def _tip(r, words, matrix_set):
    """Slot of a selection's state: a TIP of the constant ``matrix_set`` (walk's ``matrix_sets``)."""
    slot = _slot(r, _STATE_ROWS, words)
    _put(r, _OPERATIONS, TIP, slot, _push(r, _MATRICES, matrix_set), _ZERO, _ZERO, _ZERO)
    return slot


@njit
def _place(r, columns, onto):
    """Index of a new place: where each of the columns ``columns`` stands among ``onto`` (a superset)."""
    entries = r.counts[_RECORDS, _PLACE_ENTRIES]
    at = r.counts[_START, _PLACE_ENTRIES] + entries
    if at + _count(columns) > r.counts[_START, _PLACE_ENTRIES + 1]:
        raise Full("the walk needs more room")
    before = 0  # onto's columns in the words before
    for k in range(onto.size):
        word = columns[k]
        while word:  # the columns, lowest first: each stands after the columns of onto below it
            bit = word & -word
            r.store[at] = before + _bits(onto[k] & (bit - 1))
            at += 1
            word ^= bit
        before += _bits(onto[k])
    r.counts[_RECORDS, _PLACE_ENTRIES] = at - r.counts[_START, _PLACE_ENTRIES]
    return _push(r, _PLACES, r.counts[_RECORDS, _PLACE_ENTRIES])  # where the next place starts


@njit
def _count(words):
    """Columns among ``words``."""
    count = 0
    for word in words:
        count += _bits(word)
    return count


@njit(inline="always")
def _bits(word):
    """Bits set in ``word`` (non-negative int64), by halves, nibbles and bytes."""
    word = word - ((word >> 1) & 0x5555555555555555)
    word = (word & 0x3333333333333333) + ((word >> 2) & 0x3333333333333333)
    word = (word + (word >> 4)) & 0x0F0F0F0F0F0F0F0F
    return ((word * 0x0101010101010101) >> 56) & 255


@njit
def _combined(r, slots, matrices):
    """New slot = Σ matrix @ source over the union of the sources' columns (COMBINE)."""
    union = r.masks[slots[0]].copy()
    for slot in slots[1:]:
        _or_into(union, r.masks, slot)
    dst = _slot(r, _STATE_ROWS, union)
    first = r.counts[_RECORDS, _TERMS]
    for k in range(slots.size):
        _put(r, _TERMS, slots[k], matrices[k], _place(r, r.masks[slots[k]], union), _ZERO, _ZERO, _ZERO)
    _put(r, _OPERATIONS, COMBINE, dst, first, slots.size, _ZERO, _ZERO)
    return dst


@njit
def _joint(r, e, joint, state, set_words):
    """A joint's row (JOINT) on its input ``state``; returns the slot of its jumps' state."""
    row = _slot(r, joint[0], r.masks[state])
    force, jump = _valued(r), _valued(r)
    _put(r, _JOINT_CONSTANTS, e, force, jump, _ZERO, _ZERO, _ZERO)
    _put(r, _OPERATIONS, JOINT, row, state, force, _ZERO, _ZERO)
    _block(r, _ROWS, row, joint[0], joint[1], ROW_BLOCK)
    jumps = _slot(r, _STATE_ROWS, set_words[joint[2]])
    _put(r, _OPERATIONS, TIP, jumps, jump, _ZERO, _ZERO, _ZERO)
    return jumps


@njit
def _orthonormalise(r, state, emit):
    """Mirror of the Python walk's: the blocks sharing columns with ``state`` (and with
    those, in turn) gathered, laid out on their union and orthonormalised; returns the
    state's new slot (``state`` where too few rows to orthonormalise). ``emit``: False to
    record it without an ORTHO operation."""
    columns = r.masks[state].copy()
    n, masks = r.counts[_RECORDS, _BLOCKS], r.masks
    blocks = r.store[r.counts[_START, _BLOCKS]:r.counts[_START, _BLOCKS] + 6 * n].reshape(n, 6)
    open_blocks = np.empty(n, dtype=np.int64)  # the open blocks, group by group
    count = 0
    for group in range(3):
        for i in range(n):
            if blocks[i, _GROUP] == group and blocks[i, _OPEN_FIELD]:
                open_blocks[count] = i
                count += 1
    chosen = np.zeros(count, dtype=np.bool_)
    grown = True
    while grown:
        grown = False
        for j in range(count):
            slot = blocks[open_blocks[j], _SLOT]
            if not chosen[j] and _shared(masks, slot, columns):
                chosen[j] = grown = True
                _or_into(columns, masks, slot)
    rows = 12
    for j in range(count):
        if chosen[j]:
            rows += blocks[open_blocks[j], _ROWS_FIELD]
    width = _count(columns)
    if rows < width:  # fewer rows than columns: never orthonormalised
        return state
    first = r.counts[_RECORDS, _ORTHO_BLOCKS]
    taken = 0
    for j in range(count):
        if chosen[j]:
            i = open_blocks[j]
            blocks[i, _SLOT] = _laid(r, blocks[i, _SLOT], columns, blocks[i, _ROWS_FIELD], blocks[i, _KIND],
                                     blocks[i, _FORCES])
            taken += 1
    dst = _laid(r, state, columns, _STATE_ROWS, STATE_BLOCK, _NONE)
    ortho = _put(r, _ORTHOS, first, taken + 1, taken, width, _ZERO, _ZERO)
    if emit:
        _put(r, _OPERATIONS, ORTHO, ortho, _ZERO, _ZERO, _ZERO, _ZERO)
    return dst


@njit
def _union(masks, a, b):
    """(w,) int64 words of the columns of slots ``a`` and ``b`` (rows of ``masks``)."""
    union = masks[a].copy()
    _or_into(union, masks, b)
    return union


@njit(inline="always")
def _or_into(words, masks, slot):
    """``words`` (w,) int64 |= the columns of ``slot`` (a row of ``masks``), in place."""
    for k in range(words.size):
        words[k] |= masks[slot, k]


@njit
def _shared(masks, slot, columns):
    """True where ``slot``'s columns (rows of ``masks``) and ``columns`` share one."""
    for k in range(columns.size):
        if masks[slot, k] & columns[k]:
            return True
    return False


@njit
def _same(masks, slot, columns):
    """True where ``slot``'s columns (rows of ``masks``) are ``columns``."""
    for k in range(columns.size):
        if masks[slot, k] != columns[k]:
            return False
    return True


@njit
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


@njit
def _leave_final_orthos_to_the_lu(r, final_carries):
    """Mark the orthonormalisations after which at most ``final_carries`` carries and no
    beam remain as layout only (:data:`linmstmm.godunov.FINAL_CARRIES`)."""
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


@njit
def _table(r, table):
    """(records, width) view of ``table``'s records so far."""
    start, records, width = r.counts[_START, table], r.counts[_RECORDS, table], r.counts[_WIDTH, table]
    return r.store[start:start + records * width].reshape(records, width)


@njit
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
            while word:  # its columns, lowest first
                bit = word & -word
                slot_columns[at] = k * BITS + _bits(bit - 1)
                at += 1
                word ^= bit
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
            _table(r, _TERMS).copy(), _column(r, _PLACE_ENTRIES), _place_starts(r), _table(r, _ORTHOS).copy(),
            _table(r, _ORTHO_BLOCKS).copy(), root, row_slots[0], row_slots[1:count].copy(), row_kinds,
            _column(r, _MATRICES), _column(r, _BEAMS), _table(r, _CARRIES).copy(), _table(r, _OTHER_INPUTS).copy(),
            _table(r, _JOINT_CONSTANTS).copy())


@njit
def _place_starts(r):
    """(places + 1,) copy of where each place starts among the place entries, and the total."""
    start = r.counts[_START, _PLACES] - 1  # the first place's start, 0, stands before the table
    return r.store[start:start + 1 + r.counts[_RECORDS, _PLACES]].copy()


@njit
def _column(r, table):
    """(records,) copy of the one-integer ``table``."""
    start = r.counts[_START, table]
    return r.store[start:start + r.counts[_RECORDS, table]].copy()
