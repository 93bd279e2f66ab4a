"""The deduction of one model compiled into flat arrays: a straight-line program.

:class:`~linmstmm.deduction.Deduction` carries the boundary states from the
tips to the root in Python, element by element, orthonormalising on the way.
What it does depends on the topology alone, except how many pieces each beam
is cut into and whether an orthonormalisation is needed (both decided per
frequency). :func:`compile_program` walks that carry once, with every
orthonormalisation assumed to happen, and writes it down as a list of
operations on numbered blocks ("slots") of a workspace; the compiled kernels
(:mod:`linmstmm._kernels`) replay the list for any frequency without a Python
call per element, deciding the pieces and the skipped orthonormalisations
themselves. A skipped orthonormalisation still lays its blocks out on the
columns the plan expects (the columns it would have widened them to, with
zeros), so the plan holds either way.

The walk here (:class:`_Planner`, :func:`_walked`) is the readable reference;
:func:`compile_program` walks by the compiled kernel of
:mod:`linmstmm._walk_kernels`, which writes the same program bit for bit.
The program's form (its operation codes and arrays, the workspace's slots) is
:mod:`linmstmm.program_record`'s.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from itertools import chain

import numpy as np

from linmstmm.compiled_walk import compiled_walk
from linmstmm.deduction import Deduction
from linmstmm.elements.beam import _state_rotation
from linmstmm.godunov import FINAL_CARRIES, left_to_the_lu
from linmstmm.model_structure import KeptByKey
from linmstmm.program_constants import Constants
from linmstmm.program_record import (BEAM, CARRY, COMBINE, GEOMETRIC, JOINT, ORTHO, ROW_BLOCK, STATE_BLOCK, TIP,
                                     Program)


class _Planner:
    """Walks :meth:`Deduction._carry` symbolically and records its operations."""

    def __init__(self, deduction: Deduction):
        self.deduction = deduction
        self.slots: list[tuple[int, np.ndarray]] = []  # (rows, columns)
        self.column_masks: list[int] = []  # each slot's columns as bits (column c: 1 << c), for the unions
        self._columns_of: dict[int, np.ndarray] = {}  # mask -> its columns, one array per set of columns
        self.operations: list[tuple] = []
        self.terms: list[tuple] = []
        self.places: list[np.ndarray] = []
        self.matrices: list[np.ndarray] = []
        self.orthos: list[tuple] = []
        self.ortho_blocks: list[tuple] = []
        self.beams: list[int] = []  # element index of each BEAM record
        self.constants = Constants()  # where the model's numbers go among the matrices

    # -- storage ----------------------------------------------------------------------
    def slot(self, rows: int, columns: np.ndarray, mask: int | None = None) -> int:
        """A new slot of ``rows`` rows on ``columns`` (sorted int64; ``mask`` the same
        columns as bits, if the caller has it: slots share both, neither is ever changed)."""
        self.slots.append((rows, columns))
        self.column_masks.append(_mask(columns) if mask is None else mask)
        return len(self.slots) - 1

    def slot_like(self, rows: int, slot: int) -> int:
        """A new slot of ``rows`` rows on the columns of ``slot``."""
        return self.slot(rows, self.slots[slot][1], self.column_masks[slot])

    def union(self, slots) -> tuple[np.ndarray, int]:
        """(sorted int64 array, bits) of the columns of all of ``slots``."""
        mask = 0
        for s in slots:
            mask |= self.column_masks[s]
        return self.columns_of(mask), mask

    def columns_of(self, mask: int) -> np.ndarray:
        """The columns whose bits ``mask`` holds, sorted int64 (the same array for the same mask)."""
        if mask not in self._columns_of:
            bits = np.unpackbits(np.frombuffer(mask.to_bytes((mask.bit_length() + 7) // 8, "little"), np.uint8),
                                 bitorder="little")
            self._columns_of[mask] = np.flatnonzero(bits).astype(np.int64, copy=False)
        return self._columns_of[mask]

    def matrix(self, matrix) -> int:
        """Index of a new constant: one the topology alone fixes (a selection, a sign)."""
        self.matrices.append(matrix)
        return len(self.matrices) - 1

    def valued(self) -> int:
        """Index of a new constant made from the model's numbers, which the caller enters
        in ``self.constants`` (:class:`~linmstmm.program_constants.Constants`)."""
        return self.matrix(None)

    def all_matrices(self) -> np.ndarray:
        """(K, 12, 12) every constant: the topology's, padded, and the model's numbers'."""
        matrices = np.zeros((len(self.matrices), 12, 12))
        for index, matrix in enumerate(self.matrices):
            if matrix is not None:
                matrices[index, :matrix.shape[0], :matrix.shape[1]] = matrix
        self.constants.fill(self.deduction, matrices)
        return matrices

    def place(self, columns: np.ndarray, onto: np.ndarray) -> int:
        """Index of a new place: where each of ``columns`` is among ``onto`` (both sorted int64)."""
        self.places.append(onto.searchsorted(columns))  # the method: np.searchsorted's wrapper cost more
        return len(self.places) - 1

    def emit(self, *record) -> None:
        self.operations.append(tuple(record) + (0,) * (6 - len(record)))

    # -- blocks -----------------------------------------------------------------------
    def tip(self, link, negate: bool = False) -> int:
        """Slot of a boundary end's or cut side's state in its (kept) unknowns."""
        columns, selection = self.deduction.tip_selection(link)
        slot = self.slot(12, columns)
        self.emit(TIP, slot, self.matrix(-selection if negate else selection))
        return slot

    def columns(self, slot) -> np.ndarray:
        return self.slots[slot][1]

    def combined(self, sources: list[tuple[int, int]]) -> int:
        """New slot = Σ matrix @ source over the union of the sources' columns."""
        union, union_mask = self.union([s for s, _ in sources])
        dst = self.slot(12, union, union_mask)
        first = len(self.terms)
        for src, matrix in sources:
            self.terms.append((src, matrix, self.place(self.columns(src), union)))
        self.emit(COMBINE, dst, first, len(sources))
        return dst


def compile_program(deduction: Deduction) -> Program:
    """The straight-line program of ``deduction`` (after any release of unknowns).

    The walk of the carry depends on the topology and the released unknowns
    alone (:func:`_structure`), the constants it records on the model's numbers
    too. A parameter study's models differ in their numbers only, so the last
    LAYOUTS_KEPT walks are kept by structure, and a model with the structure of
    one of them takes that program with its own numbers in it
    (:func:`_revalued`): on the launcher 0.15 ms against 0.3 ms for the compiled walk.

    Parameters
    ----------
    deduction : Deduction
        The deduced system, any indeterminate unknowns released.

    Returns
    -------
    Program
    """
    structure = _structure(deduction)
    walked = structure not in _layouts
    layout = _layouts.value(structure, lambda: _planned(deduction))
    return layout.program if walked else _revalued(layout, deduction)


@dataclass(frozen=True)
class _Layout:
    """A walk of the carry: its program, and how the model's numbers enter it.

    constants : where each constant made from the model's numbers goes among the
    program's matrices; beams : (nb,) element index of each BEAM record.
    """

    program: Program
    constants: Constants
    beams: tuple


#: Walks kept by structure (:func:`compile_program`), least recently used dropped first.
LAYOUTS_KEPT = 8
_layouts = KeptByKey(LAYOUTS_KEPT)


def _structure(deduction: Deduction) -> tuple:
    """Everything the walk of :func:`_planned` reads that no number of the model changes:
    each element's kind, ports' links, inputs and output (a joint's released
    directions), the order, root, cuts and boundary conditions, and the unknowns
    and rows released."""
    topology = deduction.topology
    elements = tuple((el.kind, el.output, tuple(el.inputs), tuple([port.link for port in el.ports]),
                      deduction.jump_columns[e].tobytes() + el.record.released.tobytes()
                      if e in deduction.jump_columns else None)
                     for e, el in enumerate(topology.elements))
    return (elements, tuple(topology.order), topology.root, tuple((c.ends, c.closing) for c in topology.cuts),
            tuple(b.fixed.tobytes() for b in topology.boundaries), deduction.full_order,
            deduction.released_columns.tobytes(), deduction.released_rows.tobytes())


def _revalued(layout: _Layout, deduction: Deduction) -> Program:
    """``layout``'s program with the numbers of ``deduction`` (of the same structure)."""
    matrices = layout.program.matrices.copy()
    layout.constants.fill(deduction, matrices)
    return replace(layout.program, matrices=matrices, beams=_beam_parameters(deduction, layout.beams),
                   beam_rotation=_beam_rotations(deduction, layout.beams))


def _beam_parameters(deduction: Deduction, beams) -> np.ndarray:
    """(nb, 10) ``(E, G, rho, A, Iy, Iz, J, Ip, length, flags)`` of the beam elements ``beams``."""
    records = [deduction.topology.elements[e].record for e in beams]
    return np.array([(b.E, b.G, b.rho, b.A, b.Iy, b.Iz, b.J, b.Ip, b.length,
                      float(b.axial) + 2.0 * float(b.torsion)) for b in records], dtype=float).reshape(-1, 10)


def _beam_rotations(deduction: Deduction, beams) -> np.ndarray:
    """(nb, 12, 12) state rotation of each of the beam elements ``beams``, input to output."""
    elements = [deduction.topology.elements[e] for e in beams]
    return np.array([_state_rotation(tuple(np.ravel(el.record.axes)), el.inputs[0] == 1)
                     for el in elements]).reshape(-1, 12, 12)


def _planned(deduction: Deduction) -> _Layout:
    """The walk of ``deduction``'s carry, recorded by the compiled kernel
    (:func:`~linmstmm.compiled_walk.compiled_walk`): the program of
    :func:`_planned_in_python`, integer for integer and bit for bit, in about half its time
    (the launcher's 0.30 against 0.52 ms, the numbers' constants included)."""
    fields, constants, beams = compiled_walk(deduction, FINAL_CARRIES)
    return _Layout(_program(deduction, beams, **fields), constants, beams)


def _planned_in_python(deduction: Deduction) -> _Layout:
    """The walk of ``deduction``'s carry, recorded in Python: the readable reference of :func:`_planned`."""
    plan = _Planner(deduction)
    rows, root = _walked(plan)
    return _Layout(_assembled(plan, rows, root), plan.constants, tuple(plan.beams))


def _walked(plan: _Planner) -> tuple[list, int]:
    """Walk the carry of ``plan``'s deduction, recording it in ``plan``; returns the row
    blocks of Ū_all ([slot, rows, forces, kind] each, the root's known side first) and the
    slot of the root's carried state."""
    deduction = plan.deduction
    topology = deduction.topology
    elements = topology.elements
    root_given = topology.root if topology.root[0] == "boundary" else ("cut", topology.root[1], 0)
    left = left_to_the_lu(topology)  # their orthonormalisations: layout only, the final LU does the rest
    # Blocks, each [slot, rows, forces, kind] (see Program.ortho_blocks), its slot rewritten when
    # an orthonormalisation widens it: the rows of Ū_all, the root's known side first; the
    # open states by element; the cut sides waiting to enter by (cut, side).
    rows: list[list] = [[plan.tip(root_given, negate=True), 12, -1, ROW_BLOCK]]
    open_states: dict[int, list] = {}
    waiting: dict[tuple, list] = {}

    def orthonormalise(state: int, emit: bool = True) -> int:
        """Mirror of :meth:`_Orthonormaliser.apply`; returns the state's new slot.

        emit : False to record it without an ORTHO operation (a beam's pieces
        after the first run it themselves)."""
        masks = plan.column_masks
        others = rows + list(open_states.values()) + list(waiting.values())
        columns = masks[state]
        chosen = [False] * len(others)
        grown = True
        while grown:  # every block that shares a column with those gathered so far
            grown = False
            for i, block in enumerate(others):
                if not chosen[i] and masks[block[0]] & columns:
                    chosen[i] = grown = True
                    columns |= masks[block[0]]
        blocks = [block for block, taken in zip(others, chosen) if taken] + [_state_block(state)]
        if sum(block[1] for block in blocks) < columns.bit_count():  # fewer rows than columns: never orthonormalised
            return state
        union = plan.columns_of(columns)
        first = len(plan.ortho_blocks)
        for block in blocks:
            src, count, forces, kind = block
            if masks[src] == columns:  # its columns are the union's: in place
                dst, place = src, -1
            else:
                dst, place = plan.slot(count, union, columns), plan.place(plan.columns(src), union)
            plan.ortho_blocks.append((src, dst, count, kind, place, forces))
            block[0] = dst
        plan.orthos.append((first, len(blocks), len(blocks) - 1, union.size, 0))
        if emit:
            plan.emit(ORTHO, len(plan.orthos) - 1)
        return dst

    def enter_cut_side(link) -> int:
        _, c, side = link
        if (c, side) in waiting:
            return waiting.pop((c, side))[0]
        waiting[c, 1 - side] = _state_block(plan.tip(("cut", c, 1 - side)))
        return plan.tip(link)

    for e in topology.order:
        element = elements[e]
        inputs = []
        for p in element.inputs:
            link = element.ports[p].link
            if link[0] == "element":
                inputs.append(open_states.pop(link[1])[0])
            elif link[0] == "cut" and not topology.cuts[link[1]].closing:
                inputs.append(enter_cut_side(link))
            else:
                inputs.append(plan.tip(link))
        if element.kind == "beam":
            plan.beams.append(e)
            index = len(plan.beams) - 1
            plan.emit(BEAM, inputs[0], index, 1)
            state = orthonormalise(inputs[0])
            records = len(plan.orthos)
            if orthonormalise(state, emit=False) != state:
                raise AssertionError("a beam's orthonormalisation widened its columns twice")
            plan.emit(BEAM, state, index, 0, records if len(plan.orthos) > records else -1)
            terms = [(state, -1)]
        else:
            carried = plan.slot_like(12, inputs[0])
            kinematic = plan.valued()
            inertial = plan.valued() if element.kind == "rigid" else -1  # U2 = 0: none
            plan.constants.carry(e, element.kind, kinematic, inertial)
            plan.emit(CARRY, carried, inputs[0], kinematic, inertial)
            terms = [(carried, -1)]
            if e in deduction.jump_columns:
                terms.append((_joint(plan, deduction, e, inputs[0], rows), -1))
        for k, other in enumerate(inputs[1:]):
            forces, incidence = plan.valued(), plan.valued()
            plan.constants.other_input.append((e, k, forces, incidence))
            terms.append((other, forces))
            first = inputs[0]
            union, union_mask = plan.union([first, other])
            row = plan.slot(6, union, union_mask)
            plan.emit(GEOMETRIC, row, first, other, incidence, len(plan.places))
            plan.place(plan.columns(first), union)
            plan.place(plan.columns(other), union)
            rows.append([row, 6, -1, ROW_BLOCK])
        state = terms[0][0] if len(terms) == 1 else plan.combined(terms)
        recorded = len(plan.orthos)
        open_states[e] = _state_block(orthonormalise(state))
        if e in left and len(plan.orthos) > recorded:
            plan.orthos[-1] = plan.orthos[-1][:4] + (1,)
    return rows, open_states[topology.order[-1]][0]


def _assembled(plan: _Planner, rows: list, root: int) -> Program:
    """The program ``plan`` recorded, as arrays (``rows`` and ``root`` as :func:`_walked` gives them)."""
    slot_columns = [c for _, c in plan.slots]
    return _program(
        plan.deduction, plan.beams,
        slot_rows=np.array([r for r, _ in plan.slots], dtype=np.int64),
        slot_width=np.array([c.size for c in slot_columns], dtype=np.int64),
        slot_columns=np.concatenate(slot_columns, dtype=np.int64),
        operations=_table(plan.operations, 6),
        terms=_table(plan.terms, 3),
        places=np.concatenate(plan.places).astype(np.int64) if plan.places else np.zeros(0, np.int64),
        places_start=_starts(np.array([p.size for p in plan.places], dtype=np.int64)),
        matrices=plan.all_matrices(),
        orthos=_table(plan.orthos, 5),
        ortho_blocks=_table(plan.ortho_blocks, 6),
        root=root,
        root_row=rows[0][0],
        geometric_rows=np.array([r[0] for r in rows[1:]], dtype=np.int64),
        row_kinds=np.concatenate([_row_kinds(count, forces) for _, count, forces, _ in rows]),
    )


def _program(deduction: Deduction, beams, slot_rows: np.ndarray, slot_width: np.ndarray, **arrays) -> Program:
    """The Program of a walk of ``deduction``: its slots (``slot_rows``, ``slot_width``)
    laid out in the workspace, the numbers of its ``beams`` (element indices), the
    released rows and columns, and the walk's other ``arrays`` (Program's fields)."""
    offsets = _starts(slot_rows * slot_width)
    order = deduction.full_order
    layout = dict(slot_offset=offsets[:-1], slot_rows=slot_rows, slot_width=slot_width,
                  slot_columns_start=_starts(slot_width), order=order,
                  kept_rows=_kept(order, deduction.released_rows),
                  kept_columns=_kept(order, deduction.released_columns), **arrays)
    return Program(workspace=int(offsets[-1]), beams=_beam_parameters(deduction, beams),
                   beam_rotation=_beam_rotations(deduction, beams), **_assembly(layout), **layout)


def _assembly(layout: dict) -> dict:
    """Where each entry of Ū_all comes from in a program of the fields ``layout``: its
    ``assembly_sources`` and ``assembly_targets`` (:func:`linmstmm._assembly_kernels.assembly`),
    and where those that can be nonzero go among the diagonal blocks of Ū_all's
    block-triangular form, which alone enter its determinant
    (:func:`~linmstmm._assembly_kernels.determinant_blocks`). Found once per walk: a
    program with new numbers keeps them (:func:`_revalued`)."""
    from linmstmm._assembly_kernels import assembly, determinant_blocks  # numba loads here, not at import

    blocks = np.concatenate(([layout["root"], layout["root_row"]], layout["geometric_rows"])).astype(np.int64)
    slots = [layout[name] for name in ("slot_offset", "slot_rows", "slot_width", "slot_columns", "slot_columns_start")]
    sources, targets = assembly(*slots, blocks, layout["kept_rows"], layout["kept_columns"], layout["order"])
    can_be_nonzero = ~_held_at_zero(layout, sources)
    block_sources, block_targets, offsets, orders, sign = determinant_blocks(
        sources[can_be_nonzero], targets[can_be_nonzero], layout["kept_columns"].size)
    return {"assembly_sources": sources, "assembly_targets": targets, "block_sources": block_sources,
            "block_targets": block_targets, "block_offsets": offsets, "block_orders": orders,
            "block_sign": float(sign)}


def _held_at_zero(layout: dict, sources: np.ndarray) -> np.ndarray:
    """(E,) bool: which of the workspace entries ``sources`` (E,) are zero at every ω:
    those of the root's known side (−Z_root, its slot ``root_row``) that its selection
    holds at zero, where that slot keeps the selection its TIP operation writes (no
    other operation writes it, no orthonormalisation takes it in). A root end's
    unknowns enter Ū_all there alone, each with one entry in its column."""
    slot, operations, ortho_blocks = layout["root_row"], layout["operations"], layout["ortho_blocks"]
    writers = operations[(operations[:, 0] != ORTHO) & (operations[:, 1] == slot)]
    if len(writers) != 1 or writers[0, 0] != TIP or np.any(ortho_blocks[:, :2] == slot):
        return np.zeros(sources.size, dtype=bool)
    width, start = layout["slot_width"][slot], layout["slot_offset"][slot]
    inside = (sources >= start) & (sources < start + 12 * width)
    rows, columns = np.divmod(sources[inside] - start, width)
    held = np.zeros(sources.size, dtype=bool)
    held[inside] = layout["matrices"][writers[0, 2]][rows, columns] == 0.0
    return held


def _starts(counts: np.ndarray) -> np.ndarray:
    """(n + 1,) int64: where each of n consecutive runs of ``counts`` (n,) entries starts, and the total last."""
    starts = np.zeros(counts.size + 1, dtype=np.int64)
    np.cumsum(counts, out=starts[1:])
    return starts


def _mask(columns: np.ndarray) -> int:
    """``columns`` (int) as bits: column c is ``1 << c``."""
    mask = 0
    for c in columns.tolist():
        mask |= 1 << c
    return mask


def _state_block(slot: int) -> list:
    """A state's block, as the walk holds it: [slot, rows, forces, kind] (:func:`_walked`)."""
    return [slot, 12, -1, STATE_BLOCK]


def _table(records: list[tuple], width: int) -> np.ndarray:
    """(len(records), width) int64 of ``records``, each ``width`` integers."""
    return np.fromiter(chain.from_iterable(records), dtype=np.int64, count=width * len(records)).reshape(-1, width)


def _kept(order: int, released: np.ndarray) -> np.ndarray:
    """(order - released,) int64: 0..order-1, less the indices ``released``, ascending."""
    if not released.size:  # nothing released (most models)
        return np.arange(order, dtype=np.int64)
    kept = np.ones(order, dtype=bool)
    kept[released] = False
    return np.flatnonzero(kept).astype(np.int64, copy=False)


def _row_kinds(count: int, forces: int) -> np.ndarray:
    """Kinds of a row block of ``count`` rows (0 displacement, 1 rotation, 2 moment, 3
    force): a joint's ``forces`` force rows, then moment rows; any other block (the
    root's state, a geometric equation) three rows per kind (as
    :func:`linmstmm.godunov._row_kinds` weighs them)."""
    if forces >= 0:
        return np.repeat(np.array([3, 2], dtype=np.int64), [forces, count - forces])
    return _THREE_PER_KIND[:count]


#: Kinds of the rows of a block of up to 12 rows, three rows per kind (:func:`_row_kinds`).
_THREE_PER_KIND = np.arange(12, dtype=np.int64) // 3


def _joint(plan: _Planner, deduction: Deduction, e: int, state: int, rows: list) -> int:
    """Record joint e's row (no force along its released directions, on its input
    ``state``) as :meth:`Deduction._carry` does, and return the slot of its jumps' state
    (a constant, ``E Δ``) to add to its output."""
    record = deduction.topology.elements[e].record
    row = plan.slot_like(record.released.size, state)
    force, jump = plan.valued(), plan.valued()
    plan.constants.joint.append((e, force, jump))
    plan.emit(JOINT, row, state, force)
    rows.append([row, record.released.size, int(np.sum(record.released < 3)), ROW_BLOCK])
    slot = plan.slot(12, deduction.jump_selection(e)[0])
    plan.emit(TIP, slot, jump)
    return slot
