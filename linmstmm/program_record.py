"""What a compiled program is: its operation codes and arrays (:class:`Program`),
written by :func:`linmstmm.program.compile_program` and replayed by the kernels
(:mod:`linmstmm._kernels`).

Slots: every block a carry forms (a port state, a geometric row, a cut side
waiting to enter, the root's known side) is stored row-major, ``rows ×
len(columns)``, at its own offset of the workspace. An operation that widens
a block's columns writes a new slot; one that keeps them writes in place.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# Operation codes (first entry of each record in Program.operations). The kernels
# compile them, and the block kinds, into their caches: after a change, touch
# linmstmm/_kernels.py and linmstmm/_walk_kernels.py (see the latter).
#: TIP dst constant: the slot holds a constant (12, k) selection, reference 1.
TIP = 0
#: CARRY dst src U0 U2: dst = (U0 + ω² U2) src (U2 = −1: none; only U2[6:, :6] acts).
CARRY = 1
#: BEAM slot beam first ortho: the slot carried along the beam; ``first`` = 1: the first
#: piece only (the piece count decided from the group's largest |ω|); 0: the
#: other pieces, each followed by orthonormalisation ``ortho`` (in place).
BEAM = 2
#: COMBINE dst terms: dst = Σ M_i src_i placed on dst's columns (M_i = −1: identity).
COMBINE = 3
#: GEOMETRIC dst first other H: dst = −first[:6] + H other, each placed on dst's columns.
GEOMETRIC = 4
#: ORTHO index: orthonormalisation record ``index`` (Program.orthos).
ORTHO = 5
#: JOINT dst src F: dst (its r rows) = F[:r] src, the forces along a joint's released
#: directions (:func:`linmstmm.elements.spring.joint_force`), on src's columns.
JOINT = 6

#: Block kinds in an orthonormalisation: a formed row (no growth reference), or a state.
ROW_BLOCK, STATE_BLOCK = 0, 1


@dataclass(frozen=True)
class Program:
    """A compiled deduction: everything the kernels need, as plain arrays.

    Attributes
    ----------
    slot_offset, slot_rows, slot_width : (S,) int64, where slot s sits in the
        workspace, its rows and its number of columns.
    slot_columns, slot_columns_start : the columns (unknowns) of slot s are
        ``slot_columns[slot_columns_start[s]:slot_columns_start[s + 1]]``.
    workspace : int, entries per frequency.
    operations : (P, 6) int64 records ``(code, a, b, c, d, e)``, see the codes above.
    terms : (T, 3) int64 ``(src, matrix, place)`` of COMBINE records ``a..a+b``;
        ``place`` indexes ``places``.
    places, places_start : column positions of a source slot in a destination slot.
    matrices : (K, 12, 12) float64 constants (selections padded, U0, U2, U_{j,Ik}, H).
    orthos : (O, 5) int64 ``(first block, number of blocks, state block, columns, layout only)``;
        ``layout only`` = 1: the blocks are laid out on the columns, never orthonormalised.
    ortho_blocks : (B, 6) int64 ``(src, dst, rows, kind, place, forces)``: ``place``
        indexes ``places`` (src's columns in dst), −1 where dst is src; ``forces``:
        a joint's row block has that many force rows first, moment rows after (their
        kinds in the row scales), −1 for any other block (three rows per kind).
    beams : (nb, 10) float64 ``(E, G, rho, A, Iy, Iz, J, Ip, length, flags)``,
        flags = axial + 2 torsion; beam_rotation : (nb, 12, 12) its state rotation.
    root, root_row : slots of the carried root state and of −Z_root.
    geometric_rows : (g,) slots of the geometric and joint rows, in Ū_all's row order.
    order, kept_rows, kept_columns : order of Ū_all before release, and the rows and
        columns that remain after it.
    row_kinds : (order,) int64 what each row of Ū_all before release is (0 a
        displacement, 1 a rotation, 2 a moment, 3 a force), as
        :meth:`~linmstmm.deduction.Deduction.kinds` has it.
    assembly_sources, assembly_targets : (E,) int64, entry ``assembly_sources[e]`` of a
        frequency's workspace is added to entry ``assembly_targets[e]`` of the
        transposed Ū_all (N, N) flattened (:func:`linmstmm._assembly_kernels.assembly`).
    block_sources, block_targets, block_offsets, block_orders, block_sign : the entries
        of the diagonal blocks of Ū_all's block-triangular form, where each block starts
        and its order, and the sign of the permutations: det Ū_all = block_sign ·
        Π det(block) (:func:`linmstmm._assembly_kernels.determinant_blocks`).
    """

    slot_offset: np.ndarray
    slot_rows: np.ndarray
    slot_width: np.ndarray
    slot_columns: np.ndarray
    slot_columns_start: np.ndarray
    workspace: int
    operations: np.ndarray
    terms: np.ndarray
    places: np.ndarray
    places_start: np.ndarray
    matrices: np.ndarray
    orthos: np.ndarray
    ortho_blocks: np.ndarray
    beams: np.ndarray
    beam_rotation: np.ndarray
    root: int
    root_row: int
    geometric_rows: np.ndarray
    order: int
    kept_rows: np.ndarray
    kept_columns: np.ndarray
    row_kinds: np.ndarray
    assembly_sources: np.ndarray
    assembly_targets: np.ndarray
    block_sources: np.ndarray
    block_targets: np.ndarray
    block_offsets: np.ndarray
    block_orders: np.ndarray
    block_sign: float
