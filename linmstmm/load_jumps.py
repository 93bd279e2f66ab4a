"""Point loads and probes of a forced carry (:meth:`linmstmm.deduction.Deduction.forced`):
each load a jump of the carried state on a fresh unknown, each probe the
displacement rows of the state at its port.
"""
from __future__ import annotations

import numpy as np

from linmstmm.godunov import PortState


class _Loads:
    """The point loads and probes of one forced carry (:meth:`linmstmm.deduction.Deduction.forced`
    of ``deduction``).

    Jump j enters as a fresh unknown, label ``full_order + j``, with a row of
    its own that pins it to 1 (appended when it enters, moved after every
    other row at the end): the orthonormalisation then transforms it like
    any unknown. A probe is the displacement rows of the state at its port,
    kept among the open states (key ``("probe", name)``) so that every
    orthonormalisation rewrites it too.
    """

    def __init__(self, deduction, jumps, probes, n: int):
        self.deduction, self.jumps, self.probes, self.n = deduction, jumps, probes, n
        self.labels = {port: deduction.full_order + j for j, port in enumerate(jumps)}
        self.states: dict[str, PortState] = {}

    @property
    def active(self) -> bool:
        return bool(self.jumps or self.probes)

    def jumped(self, port, state: PortState, rows) -> PortState:
        """``state`` plus the jump at ``port`` (if any) on its fresh unknown, whose row joins ``rows``."""
        if port not in self.jumps:
            return state
        label = self.labels[port]
        jump = np.broadcast_to(self.jumps[port], (self.n, 12))[:, :, None]
        rows.append([("load", label), np.array([label]), np.ones((self.n, 1, 1), dtype=jump.dtype)])
        columns = np.r_[state.columns, label]
        order = np.argsort(columns, kind="stable")
        matrix = np.concatenate([state.matrix.astype(np.result_type(state.matrix, jump)), jump], axis=2)
        return PortState(columns[order], matrix[:, :, order])

    def watch_tips(self, open_states) -> None:
        """Start the probes at tips (a boundary end's or cut side's input) from their tip states."""
        for name, (e, p) in self.probes.items():
            if p != self.deduction.topology.elements[e].output:
                tip = self.deduction.tip_state(self.deduction.topology.elements[e].ports[p].link, self.n)
                open_states["probe", name] = PortState(tip.columns, tip.matrix[:, :6])

    def watch(self, port, state: PortState, open_states) -> None:
        """Start the probes at ``port`` (an element's output) from its ``state``."""
        for name, where in self.probes.items():
            if where == port:
                open_states["probe", name] = PortState(state.columns, state.matrix[:, :6])

    def finish(self, rows, open_states) -> None:
        """Move the loads' rows last (in place) and collect the probes into ``states``."""
        rows[:] = ([row for row in rows if not isinstance(row[0], tuple)]
                   + [row for row in rows if isinstance(row[0], tuple)])
        self.states = {name: open_states.pop(("probe", name)) for name in self.probes}
