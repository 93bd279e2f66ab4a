"""Where each entry of Ū_all comes from in a compiled program's workspace, found by a
compiled kernel (:func:`assembly`): a loop over the blocks' entries that numpy did in
twenty small calls a block (0.1 ms of a launcher's first solve)."""
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
