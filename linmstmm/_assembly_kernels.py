"""Where each entry of Ū_all comes from in a compiled program's workspace, found by a
compiled kernel (:func:`assembly`): a loop over the blocks' entries that numpy did in
twenty small calls a block (0.1 ms of a launcher's first solve); and where it goes
for the determinant, once lone columns are expanded along (:func:`determinant_blocks`)."""
from __future__ import annotations

import numpy as np
from numba import njit

from linmstmm._compile_notice import announce_compiles

announce_compiles()  # one line on stderr if this run compiles (linmstmm._compile_notice)


@njit(cache=True)
def assembly(slot_offset, slot_rows, slot_width, slot_columns, slot_columns_start, blocks, kept_rows,
             kept_columns, order):
    """(sources (E,), targets (E,)) int64: entry ``sources[e]`` of a frequency's workspace
    is added to entry ``targets[e]`` of the transposed Ū_all (N, N) flattened.

    Parameters
    ----------
    slot_offset, slot_rows, slot_width, slot_columns, slot_columns_start : int64
        The program's slots (:class:`linmstmm.program_record.Program`).
    blocks : (b,) int64
        The slots of Ū_all's blocks in the order they stand: the root state, −Z_root
        (the two share the first twelve rows: entries met twice add up in that
        order), then the geometric and joint rows.
    kept_rows, kept_columns : int64
        Rows and columns of Ū_all that remain after release, ascending (N each).
    order : int
        Order of Ū_all before release.

    Returns
    -------
    sources, targets : (E,) int64
        Every entry on a row and a column kept, block by block, row-major in each.
    """
    row_of, column_of = _kept_at(kept_rows, order), _kept_at(kept_columns, order)
    kept = kept_columns.size
    total = 0
    for slot in blocks:
        total += slot_rows[slot] * slot_width[slot]
    sources, targets = np.empty(total, np.int64), np.empty(total, np.int64)
    n = start = 0
    for position in range(blocks.size):
        slot = blocks[position]
        rows, width, columns = slot_rows[slot], slot_width[slot], slot_columns_start[slot]
        for i in range(rows):
            row = row_of[start + i]
            if row < 0:
                continue
            for j in range(width):
                column = column_of[slot_columns[columns + j]]
                if column >= 0:
                    sources[n] = slot_offset[slot] + i * width + j
                    targets[n] = column * kept + row
                    n += 1
        if position > 0:  # the root state and −Z_root share the first twelve rows
            start += rows
    return sources[:n].copy(), targets[:n].copy()


@njit(cache=True)
def _kept_at(kept, order):
    """(order,) int64: where each of the full Ū_all's ``order`` rows (or columns) stands among
    the ``kept`` ones, -1 for one released."""
    position = np.full(order, -1, dtype=np.int64)
    for k in range(kept.size):
        position[kept[k]] = k
    return position


@njit(cache=True)
def determinant_blocks(sources, targets, kept):
    """Ū_all's entries laid out for its determinant: columns with one entry that can be
    nonzero each stand alone, the rest form one block, and det Ū_all = sign · Π det(block).

    A column whose one entry that can be nonzero is at row r expands det Ū_all along
    itself: ± that entry times the determinant without row r and the column
    (Laplace), exactly, whatever the entry's size. Taking such columns one after
    another (a column counts the rows not yet taken) leaves the rest as one block
    for the LU. A root end's unknowns enter Ū_all only through the root's selection
    (:func:`linmstmm.program._held_at_zero`), one entry a column: on the launcher
    six columns, which leaves one LU of order 54 in place of one of 60.

    Parameters
    ----------
    sources, targets : (E,) int64
        The entries that can be nonzero: workspace entry ``sources[e]`` adds to entry
        ``targets[e]`` = column · N + row of Ū_all (N, N) (:func:`assembly`'s, less
        those known to be zero).
    kept : int
        N, the order of Ū_all.

    Returns
    -------
    block_sources, block_targets : (F,) int64
        The entries in the blocks: workspace entry ``block_sources[f]`` adds to entry
        ``block_targets[f]`` of the blocks laid end to end, each in Fortran order; the
        entries of a lone column's row in other columns are left out.
    block_offsets : (b + 1,) int64
        Where each block starts among them, and their total size last.
    block_orders : (b,) int64
        Each block's order: 1 for each lone column, in the order taken, then the rest's.
    sign : float
        ±1, the sign of the row permutation times that of the column permutation that
        bring the blocks to the diagonal (block upper triangular).
    """
    n = kept
    row_of, column_of = (targets % n, targets // n) if n else (targets, targets)
    by_row, row_starts = _grouped(row_of, column_of, n)
    by_column, column_starts = _grouped(column_of, row_of, n)
    taken, alone = np.zeros(n, np.bool_), np.zeros(n, np.bool_)  # rows, and columns, taken by a lone column
    lone_rows, lone_columns = np.empty(n, np.int64), np.empty(n, np.int64)
    queue = np.empty(n + targets.size, np.int64)  # columns to look at: each, then each beside a row taken
    queue[:n] = np.arange(n)
    queued, head, lone = n, 0, 0
    while head < queued:
        c = queue[head]
        head += 1
        row = -1  # the one row not taken among the column's entries; -2 where two are
        for k in range(column_starts[c], column_starts[c + 1]):
            if not taken[by_column[k]] and by_column[k] != row:
                row = by_column[k] if row == -1 else -2
        if alone[c] or row < 0:
            continue
        taken[row], alone[c] = True, True
        lone_rows[lone], lone_columns[lone] = row, c
        lone += 1
        for k in range(row_starts[row], row_starts[row + 1]):
            queue[queued] = by_row[k]  # it may stand alone now
            queued += 1
    return _laid_out(sources, row_of, column_of, lone_rows[:lone], lone_columns[:lone], taken, alone)


@njit(cache=True)
def _grouped(keys, values, n):
    """(``values`` ordered by ``keys`` (E,), where each of the n keys' run starts (n + 1,))."""
    starts = np.zeros(n + 1, np.int64)
    for key in keys:
        starts[key + 1] += 1
    starts = np.cumsum(starts)
    ordered, filled = np.empty(keys.size, np.int64), starts[:-1].copy()
    for e in range(keys.size):
        ordered[filled[keys[e]]] = values[e]
        filled[keys[e]] += 1
    return ordered, starts


@njit(cache=True)
def _laid_out(sources, row_of, column_of, lone_rows, lone_columns, taken, alone):
    """:func:`determinant_blocks`' layout of the lone columns (at ``lone_rows``) as blocks
    of order one, in the order taken, then of every other row and column as one block,
    each ascending (``taken``, ``alone`` (n,): the rows and columns of lone ones)."""
    n, lone = taken.size, lone_rows.size
    rest = n - lone
    blocks = lone + (1 if rest else 0)
    block_orders = np.ones(blocks, np.int64)
    if rest:
        block_orders[-1] = rest
    block_offsets = np.zeros(blocks + 1, np.int64)
    block_offsets[1:] = np.cumsum(block_orders * block_orders)
    block_of_row, block_of_column = np.full(n, blocks - 1, np.int64), np.full(n, blocks - 1, np.int64)
    local_row, local_column = np.zeros(n, np.int64), np.zeros(n, np.int64)
    rows_in_order, columns_in_order = np.empty(n, np.int64), np.empty(n, np.int64)
    for k in range(lone):
        block_of_row[lone_rows[k]], block_of_column[lone_columns[k]] = k, k
        rows_in_order[k], columns_in_order[k] = lone_rows[k], lone_columns[k]
    placed_rows = placed_columns = lone
    for i in range(n):
        if not taken[i]:
            local_row[i] = placed_rows - lone
            rows_in_order[placed_rows] = i
            placed_rows += 1
        if not alone[i]:
            local_column[i] = placed_columns - lone
            columns_in_order[placed_columns] = i
            placed_columns += 1
    inside = 0
    for e in range(row_of.size):
        if block_of_row[row_of[e]] == block_of_column[column_of[e]]:
            inside += 1
    block_sources, block_targets = np.empty(inside, np.int64), np.empty(inside, np.int64)
    f = 0
    for e in range(row_of.size):
        k = block_of_row[row_of[e]]
        if k == block_of_column[column_of[e]]:
            block_sources[f] = sources[e]
            block_targets[f] = block_offsets[k] + local_column[column_of[e]] * block_orders[k] + local_row[row_of[e]]
            f += 1
    sign = _permutation_sign(rows_in_order) * _permutation_sign(columns_in_order)
    return block_sources, block_targets, block_offsets, block_orders, sign

@njit(cache=True)
def _permutation_sign(order):
    """±1.0: the sign of the permutation ``order`` (n,) of 0 … n−1, from its cycles."""
    seen = np.zeros(order.size, np.bool_)
    sign = 1.0
    for start in range(order.size):
        length = 0
        k = start
        while not seen[k]:
            seen[k] = True
            k = order[k]
            length += 1
        if length and length % 2 == 0:
            sign = -sign
    return sign
