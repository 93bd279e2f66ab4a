"""Godunov orthonormalisation of the states carried by the deduction: the
port state ``Z_port = matrix @ z̄[columns]`` (:class:`PortState`) and the
orthonormaliser that keeps growing beam solutions from swamping the decaying
ones in the stable evaluation of :class:`linmstmm.deduction.Deduction`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from linmstmm.numeric import power_of_two_scale, size_estimate


#: An orthonormalisation after which at most this many element carries, and no
#: beam, remain is left to the final LU: a change of unknowns (every block that
#: holds its columns is in it) commutes with the carries that follow (they
#: multiply rows), and the LU factorises the same matrix: the numpy carry leaves the
#: same ones (:func:`left_to_the_lu`), the compiled program marks them layout only
#: (:mod:`linmstmm.program`). On the launcher these were the four largest (60 rows, 54 columns) and cost more than half of an
#: evaluation at 1000 rad/s and above (224 → 88 µs); log|det| against mpmath at
#: 12 frequencies from 10 to 3e4 rad/s kept its accuracy on both launcher models
#: (largest error 2e-11 below 1e4 rad/s and 4e-8 above, as before, against 5e-11
#: and 6e-8 of the numpy carry). Not for a model without boundary, whose
#: closing equation T_loop − I must be orthonormalised with the state carried
#: round the loop (every block holds the closing cut's unknowns there), lest the I
#: be lost under T_loop's growth (a ring at 1.3e5 rad/s lost 3e-9 in log|det|).
FINAL_CARRIES = 4


def left_to_the_lu(topology) -> frozenset:
    """The elements (indices) whose orthonormalisation, made once an element is carried,
    the stable carry leaves to the final LU (:data:`FINAL_CARRIES`): the last ones of
    ``topology.order``, up to FINAL_CARRIES + 1 of them, back to the last beam (included:
    its pieces are orthonormalised on the way, the one after them is not); none for a
    model without boundary. The compiled program (:func:`linmstmm.program._walked`) and
    the numpy carry (:meth:`linmstmm.deduction.Deduction._carry`) both take these."""
    if topology.root[0] != "boundary":
        return frozenset()
    left: set[int] = set()
    for e in reversed(topology.order):
        left.add(e)
        if topology.elements[e].kind == "beam" or len(left) > FINAL_CARRIES:
            break
    return frozenset(left)


@dataclass
class PortState:
    """``Z_port = matrix @ z̄[columns]``; matrix (n, 12, len(columns)).

    reference : (n,) max |matrix| when its columns were last orthonormalised,
    to tell how much it has grown: 1 at a tip (its selection is orthonormal),
    the largest of the inputs' at a merge (their columns are disjoint, except a
    cut's two sides); None: unknown, orthonormalise at the next chance.
    """

    columns: np.ndarray
    matrix: np.ndarray
    reference: np.ndarray | None = None


class _Orthonormaliser:
    """Godunov orthonormalisation of the unknowns carried by one port state.

    The columns S of a state are replaced by an orthonormal basis of
    everything formed on them: the state itself and every other block that
    holds one of its columns (the rows already formed, the other open
    states, a cut side still waiting to enter), widened to the union of
    their columns until no block outside shares one. QR with a positive
    real diagonal (so the basis is smooth in ω): z̄_S = R⁻¹ w_S; every block
    is rewritten in the new unknowns, det R is accumulated, and growing beam
    solutions can no longer swamp the decaying ones. A loop's cut columns
    are carried along both arcs of the loop and are orthonormalised like any
    other (the launcher's tube between its supports grew by 1e16 at
    8000 rad/s while they were left alone, and det lost 7 digits). Only
    float and complex stacks are handled.
    """

    #: Orthonormalise once a state has grown (or shrunk) by this factor since the last time.
    GROWTH = 1e2
    #: Entries beyond this (or below its inverse) after a QR are scaled back by a
    #: power of two (a chain of 300 cells above its cutoff grows ×400 per cell).
    FAR = 1e100

    def __init__(self, omega):
        self.log_scale = np.zeros(omega.size)
        #: (cut, side) -> PortState of a cut side whose other side entered first
        self.waiting: dict[tuple, PortState] = {}

    def enter_cut_side(self, link, tip) -> PortState:
        """The state of cut side ``link`` = ("cut", c, side) as it enters the carry:
        its tip state (``tip(link)``), and the other side then waits, a block of
        every orthonormalisation on the cut's columns; or, if it was the one
        waiting, its tip state as those left it."""
        _, c, side = link
        if (c, side) in self.waiting:
            return self.waiting.pop((c, side))
        self.waiting[c, 1 - side] = tip(("cut", c, 1 - side))
        return tip(link)

    @staticmethod
    def _unit_scale(stacked, kinds) -> np.ndarray:
        """(n, rows) scale of each row of ``stacked`` (n, rows, k): one per kind of
        row (``kinds``: 0 displacement, 1 rotation, 2 moment, 3 force), the inverse
        root-mean-square size of all rows of that kind.

        Every row of one kind gets the same scale, the rows already formed on the
        columns as well as the state, so the QR sees the known side and the carried
        side of an equation in one metric (scaling each row by its own size made a
        ring's closing equation T_loop − I lose up to 5 digits at 1300 rad/s), and
        no kind is weighted down until the QR cannot see it (a state's moments and
        forces must keep its columns independent where its displacements alone
        would not).
        """
        peak = size_estimate(stacked).max(axis=(1, 2))
        peak = np.where(peak > 0, peak, 1.0)[:, None, None]
        squares = (np.abs(stacked / peak) ** 2).sum(axis=2)  # (n, rows), relative to the peak: no overflow
        size = np.sqrt(squares @ (kinds[:, None] == np.arange(4)))  # (n, 4): each kind's rows together
        size = np.where(size > 0, size, size.max(axis=1, keepdims=True))
        return 1 / (size[:, kinds] * peak[:, :, 0])

    def _sharing(self, state: PortState, rows, open_states):
        """(columns, blocks): the union of ``state``'s columns and those of every block
        that holds one of them, closed (no block outside holds one); blocks are
        (kind, key, columns, matrix) with kind "row" (key: the row), "state" (key in
        ``open_states``) or "waiting" (key in :attr:`waiting`)."""
        others = ([("row", row, row[1], row[2]) for row in rows]
                  + [("state", key, other.columns, other.matrix) for key, other in open_states.items()]
                  + [("waiting", key, tip.columns, tip.matrix) for key, tip in self.waiting.items()])
        held = [set(block[2].tolist()) for block in others]
        columns, chosen = set(state.columns.tolist()), set()
        while True:
            more = {i for i, cs in enumerate(held) if i not in chosen and cs & columns}
            if not more:
                return np.array(sorted(columns), dtype=int), [others[i] for i in sorted(chosen)]
            chosen |= more
            for i in more:
                columns |= held[i]

    def apply(self, state: PortState, rows, open_states, keep_columns: bool = False) -> PortState:
        """The state on orthonormalised columns, every block sharing them rewritten
        (``rows`` and ``open_states`` in place); unchanged if it has not grown, or if
        there are fewer rows than columns to orthonormalise.

        open_states : the other states not yet consumed downstream.
        keep_columns : only where no block widens the columns (a periodic run's
        powers need the state's own columns).
        """
        if state.reference is not None:
            growth = size_estimate(state.matrix).max(axis=(1, 2)) / state.reference
            if growth.max() < self.GROWTH and growth.min() > 1 / self.GROWTH:
                return state
        columns, blocks = self._sharing(state, rows, open_states)
        if keep_columns and columns.size != state.columns.size:
            return state
        parts = [_embed(block_columns, matrix, columns) for _, _, block_columns, matrix in blocks]
        parts.append(_embed(state.columns, state.matrix, columns))
        stacked = np.concatenate(parts, axis=1)
        if stacked.shape[1] < stacked.shape[2]:
            return state
        kinds = [_row_kinds(block) for block in blocks] + [np.arange(state.matrix.shape[1]) // 3]
        row_scale = self._unit_scale(stacked, np.concatenate(kinds))
        q, r = np.linalg.qr(stacked * row_scale[:, :, None])
        diagonal = np.diagonal(r, axis1=1, axis2=2)
        if not np.all(np.abs(diagonal) > 0):  # dependent columns (exactly at a root): keep as is
            return state
        q = q * (diagonal / np.abs(diagonal))[:, None, :] / row_scale[:, :, None]
        self.log_scale += np.log(np.abs(diagonal)).sum(axis=1)
        # The new columns keep each kind's size, growth included; past FAR a
        # common power of two goes into the log-scale instead (no overflow).
        peak = size_estimate(q).max(axis=(1, 2))
        far = (peak > self.FAR) | (peak < 1 / self.FAR)
        if far.any():
            common = np.where(far, power_of_two_scale(peak), 1.0)
            q = q * common[:, None, None]
            self.log_scale -= np.log(common) * q.shape[2]
        offset = 0
        for kind, key, _, matrix in blocks:
            part = q[:, offset:offset + matrix.shape[1]]
            offset += matrix.shape[1]
            if kind == "row":
                key[1], key[2] = columns, part
            elif kind == "state":
                open_states[key] = PortState(columns, part, size_estimate(part).max(axis=(1, 2)))
            else:
                self.waiting[key] = PortState(columns, part, size_estimate(part).max(axis=(1, 2)))
        q = q[:, offset:]
        return PortState(columns, q, size_estimate(q).max(axis=(1, 2)))


def _row_kinds(block) -> np.ndarray:
    """Kind of each row of an orthonormaliser block (:meth:`_Orthonormaliser._unit_scale`):
    0 displacement, 1 rotation, 2 moment, 3 force. A joint row says its own; a
    point load's row (it pins the load's unknown to 1, :class:`_Loads`) is weighed
    with the forces its unknown brings in: weighed as a displacement, the QR lost
    up to 5 digits of a cantilever's receptance (closed form, βL from 1 to 50). A
    state, a cut side and the other rows are displacement, rotation, moment,
    force, three rows each, as far as they go."""
    kind, key, _, matrix = block
    if kind == "row" and len(key) > 3:
        return key[3]
    if kind == "row" and isinstance(key[0], tuple):
        return np.full(matrix.shape[1], 3)
    return np.arange(matrix.shape[1]) // 3


def _embed(columns, block, onto):
    """``block`` (n, r, len(columns)) placed on the columns ``onto`` (a superset)."""
    out = np.zeros(block.shape[:2] + (len(onto),), dtype=block.dtype)
    out[:, :, np.searchsorted(onto, columns)] = block
    return out
