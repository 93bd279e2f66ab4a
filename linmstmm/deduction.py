"""U_all and the square Ū_all(ω) by the automatic deduction theorem.

The unknowns ``z̄`` are the non-zero entries of the boundary state vectors:
six per boundary end (the free displacements and the forces of the fixed
components), twelve per loop cut (the state on side 0; side 1 is
``C Z_0`` with ``C = diag(I, −I)``, or ``C = I`` for the closing cut of a
boundary-less model, whose side 0 is the root).

The state at every port is carried as a matrix ``Z_port = S_port z̄``, built
from the tips towards the root: an element with inputs I_1..I_L and output O
gives ``S_O = U_j S_I1 + Σ_k U_{j,Ik} S_Ik``. Each ``S`` is the sum of the
products of transfer matrices along the paths from the tips to that port, so
the rows collected below are exactly the theorem's rows of U_all with the
boundary conditions already applied:

* main transfer equation (12 rows): ``S_root − Z_root = 0``;
* geometric equation of input k ≥ 2 of a body (6 rows each):
  ``−H_j S_I1 + H_{j,Ik} S_Ik = 0``.

Only the columns of the tips upstream of a port are stored with it, so the
cost of one evaluation is linear in the number of elements. Everything is
vectorised over a stack of frequencies.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from linmstmm.elements.beam import beam_transfer
from linmstmm.elements.frames import FORCE_INDEX
from linmstmm.elements.rigid import (force_extraction, position_extraction,
                                     position_incidence, rigid_transfer)
from linmstmm.elements.spring import spring_transfer
from linmstmm.topology import Topology

_CUT_SIGN = np.diag(np.r_[np.ones(6), -np.ones(6)])


@dataclass
class PortState:
    """``Z_port = matrix @ z̄[columns]``; matrix (n, 12, len(columns))."""

    columns: np.ndarray
    matrix: np.ndarray


def boundary_selection(fixed) -> np.ndarray:
    """(12, 6) map from a boundary end's six unknowns to its state vector.

    Component c is a free displacement (row c) unless fixed, then its force
    (row FORCE_INDEX[c]) is the unknown.
    """
    selection = np.zeros((12, 6))
    for c in range(6):
        selection[FORCE_INDEX[c] if fixed[c] else c, c] = 1.0
    return selection


class Deduction:
    """The deduced overall transfer equation of one topology.

    Attributes: ``order`` (= ``ubar_order``, the order N of Ū_all) and
    ``columns``: a label per unknown, e.g. ``"tyre1.Qz"``.
    """

    def __init__(self, topology: Topology):
        self.topology = topology
        self._boundary_columns = {}
        self._cut_columns = {}
        labels = []
        names = ["X", "Y", "Z", "Θx", "Θy", "Θz", "Mx", "My", "Mz", "Qx", "Qy", "Qz"]
        for b, boundary in enumerate(topology.boundaries):
            self._boundary_columns[b] = np.arange(len(labels), len(labels) + 6)
            labels += [f"{boundary.label}.{names[FORCE_INDEX[c] if boundary.fixed[c] else c]}"
                       for c in range(6)]
        for c, cut in enumerate(topology.cuts):
            self._cut_columns[c] = np.arange(len(labels), len(labels) + 12)
            labels += [f"cut {cut.point}.{name}" for name in names]
        self.columns = labels
        self.order = len(labels)
        n_geometric = sum(max(len(el.inputs) - 1, 0) for el in topology.elements)
        if 12 + 6 * n_geometric != self.order:
            raise AssertionError(f"U_all is not square: {12 + 6 * n_geometric} rows, "
                                 f"{self.order} unknowns")

    # -- element transfer matrices ------------------------------------------------
    def transfer(self, e: int, omega) -> np.ndarray:
        """(n, 12, 12) U_j of element e from its first input to its output."""
        element = self.topology.elements[e]
        record = element.record
        inp = element.ports[element.inputs[0]]
        out = element.ports[element.output]
        if element.kind == "junction":
            return np.broadcast_to(np.eye(12), (np.size(omega), 12, 12))
        if element.kind == "rigid":
            return rigid_transfer(record.mass, record.com, record.inertia,
                                  inp.position, out.position, omega)
        if element.kind == "spring":
            return spring_transfer(record.k, record.axes, omega)
        return beam_transfer(record, omega, reverse=element.inputs[0] == 1)

    # -- boundary states ------------------------------------------------------------
    def _tip_state(self, link, n) -> PortState:
        if link[0] == "boundary":
            b = link[1]
            selection = boundary_selection(self.topology.boundaries[b].fixed)
            return PortState(self._boundary_columns[b], np.broadcast_to(selection, (n, 12, 6)))
        _, c, side = link
        closing = self.topology.cuts[c].closing
        tie = np.eye(12) if (side == 0 or closing) else _CUT_SIGN
        return PortState(self._cut_columns[c], np.broadcast_to(tie, (n, 12, 12)))

    # -- the theorem ----------------------------------------------------------------
    def port_states(self, omega):
        """States of every element's output port, and the geometric rows.

        Returns (outputs, rows): outputs[e] is the PortState at element e's
        output; rows is a list of (label, columns, (n, 6, k) matrix).
        """
        omega = np.atleast_1d(np.asarray(omega, dtype=float))
        n = omega.size
        elements = self.topology.elements
        outputs: dict[int, PortState] = {}
        rows = []
        for e in self.topology.order:
            element = elements[e]
            inputs = []
            for p in element.inputs:
                link = element.ports[p].link
                inputs.append(outputs[link[1]] if link[0] == "element" else self._tip_state(link, n))
            out_position = element.ports[element.output].position
            terms = [(self.transfer(e, omega), inputs[0])]
            first_position = element.ports[element.inputs[0]].position
            for p, state in zip(element.inputs[1:], inputs[1:]):
                position = element.ports[p].position
                terms.append((force_extraction(position, out_position), state))
                rows.append((f"{element.name} input {element.ports[p].point}",
                             *_combine([(-position_extraction(), inputs[0]),
                                        (position_incidence(first_position, position), state)])))
            outputs[e] = PortState(*_combine(terms))
        return outputs, rows

    def root_state(self, outputs) -> PortState:
        """The computed state at the root (output of the last element)."""
        return outputs[self.topology.order[-1]]

    def matrix(self, omega) -> np.ndarray:
        """Ū_all(ω): stack (n, N, N), rows = main equation then geometric equations."""
        omega = np.atleast_1d(np.asarray(omega, dtype=float))
        outputs, rows = self.port_states(omega)
        root = self.root_state(outputs)
        ubar = np.zeros((omega.size, self.order, self.order))
        ubar[:, :12, root.columns] += root.matrix
        kind, index = self.topology.root
        root_columns = self._boundary_columns[index] if kind == "boundary" else self._cut_columns[index]
        root_given = self._tip_state(self.topology.root if kind == "boundary" else ("cut", index, 0),
                                     omega.size)
        ubar[:, :12, root_columns] -= root_given.matrix
        for r, (_, columns, block) in enumerate(rows):
            ubar[:, 12 + 6 * r:18 + 6 * r, columns] += block
        return ubar

    def log_det(self, omega):
        """(sign, log|det Ū_all|) over the frequency stack, each shape (n,)."""
        return np.linalg.slogdet(self.matrix(omega))


def _combine(terms):
    """Sum of ``A @ S`` over (A, PortState) terms, on the union of their columns.

    A is (12, 12), (6, 12) or a stack (n, ., 12). Returns (columns, (n, rows, k)).
    """
    columns = np.unique(np.concatenate([state.columns for _, state in terms]))
    first = terms[0][0]
    n = max(np.shape(state.matrix)[0] for _, state in terms)
    total = np.zeros((n, np.shape(first)[-2], columns.size))
    for A, state in terms:
        total[:, :, np.searchsorted(columns, state.columns)] += A @ state.matrix
    return columns, total
