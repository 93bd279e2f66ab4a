"""The Wittrick–Williams counter's constrained parts, their elimination kept by the
model's structure.

The counter (:class:`~linmstmm.wittrick_williams.ModeCounter`) factorises D(ω) on
the reduced DOFs of the FE route with one element per beam
(:func:`linmstmm.fe.assembly.constrained_parts`): the model's springs, rigid
masses and the elimination ``q = T q_r`` of its constraints. Eliminating them
(:mod:`linmstmm.fe.node_constraints`) is most of the counter's build, and for a
common kind of structure its outcome is fixed by the structure alone: where
every constraint is a fixed boundary component of a point that no rigid body
owns (no ``inf`` spring direction, no point owned by two bodies, no beam rigid
axially or in torsion), each constraint row stays one unit entry after the
ports are moved onto their bodies, so the elimination drops those DOFs and
keeps every other: T is the port map T0 (each port following its body's mass
centre by u_p = u_c + θ × (p − c)) without the fixed columns, its numbers the
ports' lever arms. :func:`counter_parts` keeps, per such structure, where each
entry of T comes from, and puts a new model's lever arms into it. The first
model of a structure is built the full way; the layout is derived from that
build when a second model of the structure asks (a model solved once never
needs it), and must give the first model's T entry for entry, or none is kept.
On the launcher: 0.12 ms a scene against 0.27 ms for the parts made anew (whose
elimination :mod:`linmstmm.fe.node_constraints` also writes directly for this kind
of structure, from the ports alone), the counter's matrices the same bit for bit.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from linmstmm.fe.assembly import ConstrainedParts, constrained_parts
from linmstmm.fe.layout import _layout, _Triplets, element_maps
from linmstmm.fe.node_constraints import (
    _add_rigid_masses,
    _add_springs,
    _port_kinematics,
    held_at_free_points,
    kept_node_constraints,
)
from linmstmm.fe.sparse import Compressed, _sorted_rows
from linmstmm.model import Model
from linmstmm.model_structure import MODELS_KEPT, KeptByStructure


@dataclass(frozen=True, eq=False)
class _Elimination:
    """Where each entry of T comes from, for every model of one structure.

    ports, centres : (p,) node of each rigid body's port and of its mass centre, bodies
    and ports in model order. T's possible entries are first the u DOFs kept as they
    are (value 1), then each port's six DOFs against its body's six centre DOFs (the
    lever-arm block); order : (u + 36 p,) them by ascending position, position and
    cols : (u + 36 p,) row × n_dof + column and column of each, in that order.
    unit : u. masters : (n_dof,) full DOFs kept. shape : (n_full, n_dof).
    """

    ports: np.ndarray
    centres: np.ndarray
    order: np.ndarray
    position: np.ndarray
    cols: np.ndarray
    unit: int
    masters: np.ndarray
    shape: tuple
    _springs: list = field(default_factory=lambda: [None])  # [(records, (strains, stiffness))] made last

    def springs(self, model: Model, layout) -> tuple:
        """(strain triplets, stiffnesses) of ``model``'s springs on ``layout``, as
        :func:`~linmstmm.fe.node_constraints.node_constraints` makes them; those of the
        last model whose spring records were the same objects (a study's steps that edit
        no spring share them) are taken as they are."""
        records, kept = model.springs, self._springs[0]  # read once: another thread may replace it
        if kept is None or len(records) != len(kept[0]) or any(a is not b for a, b in zip(records, kept[0])):
            strains, stiffness = _Triplets(), []
            _add_springs(model, layout, strains, stiffness, _Triplets())  # no inf direction: no constraint row
            kept = records, (strains, stiffness)
            self._springs[0] = kept
        return kept[1]

    def T(self, positions: np.ndarray) -> Compressed:
        """(n_full, n_dof) CSR elimination of a model whose nodes sit at ``positions``
        ((n_nodes, 3) m): the entries scipy's product T0 T1 stores (exact zeros left out),
        columns ascending in each row."""
        values = np.concatenate([np.ones(self.unit),
                                 _port_kinematics(positions[self.ports], positions[self.centres]).ravel()])[self.order]
        stored = values != 0
        return _sorted_rows(self.position[stored], self.cols[stored], values[stored], self.shape)


class _FirstBuild:
    """The kept elimination of a structure of the kind kept, derived from the full build
    of its first model when a second model of it asks (:func:`_kept_elimination`): a
    model solved once has no use for it (0.1 ms of the launcher's first counter)."""

    def __init__(self, model: Model, parts: ConstrainedParts):
        self._first = (model, parts)
        self._elimination = None

    def elimination(self) -> _Elimination | None:
        """The :class:`_Elimination`, derived on the first call; None where the layout
        does not give the first model's T entry for entry."""
        if self._first is not None:
            self._elimination, self._first = _kept_elimination(*self._first), None
        return self._elimination


#: The kept elimination of each structure seen last (None: one of another kind).
_eliminations = KeptByStructure(MODELS_KEPT)


def counter_parts(model: Model) -> ConstrainedParts:
    """The :class:`~linmstmm.fe.assembly.ConstrainedParts` of ``model`` with one element
    per beam: those :func:`~linmstmm.fe.assembly.constrained_parts` gives, built on
    the kept elimination of its structure where there is one.

    Parameters
    ----------
    model : Model
        The model.

    Returns
    -------
    ConstrainedParts
        Layout, T (scipy CSR, or :class:`~linmstmm.fe.sparse.Compressed` CSR where
        built on the kept elimination), masters, n_full, spring strains and
        stiffnesses, rigid masses and beam maps: the same numbers as the full
        build's, T's entries in ascending columns within each row where kept.
    """
    fresh = []

    def derived(model: Model) -> _FirstBuild | None:
        fresh.append(constrained_parts(model, 1, kept_node_constraints(model)))
        return _FirstBuild(model, fresh[0]) if held_at_free_points(model) else None

    kept = _eliminations.get(model, derived)
    elimination = None if fresh or kept is None else kept.elimination()
    if elimination is None:
        return fresh[0] if fresh else constrained_parts(model, 1, kept_node_constraints(model))
    layout = _layout(model, 1)
    mass = _Triplets(repeats=True)
    _add_rigid_masses(model, layout, mass)
    return ConstrainedParts(layout, elimination.T(layout.positions), elimination.masters, elimination.shape[0],
                            *elimination.springs(model, layout), mass,
                            element_maps(layout.beam_table, layout.beam_axes))


def _kept_elimination(model: Model, parts: ConstrainedParts) -> _Elimination | None:
    """The :class:`_Elimination` of ``model``'s structure (of the kind kept,
    :func:`~linmstmm.fe.node_constraints.held_at_free_points`), checked against its
    full build ``parts``; None where the layout does not give ``parts.T`` entry for entry."""
    bodies = [(body.name, port) for body in model.rigids for port in body.ports]
    index, (n_full, n_dof) = parts.layout.index, parts.T.shape
    ports = np.array([index.points[port] for _, port in bodies], int)
    centres = np.array([index.rigids[name] for name, _ in bodies], int)
    column = np.full(n_full, -1)
    column[parts.masters] = np.arange(n_dof)
    slaved = np.zeros(n_full, bool)
    slaved[(6 * ports[:, None] + np.arange(6)).ravel()] = True
    unit = np.flatnonzero(~slaved & (column >= 0))
    port_dofs = np.repeat(6 * ports[:, None] + np.arange(6), 6, axis=1)                    # (p, 36): row r six times
    centre_dofs = np.tile(6 * centres[:, None] + np.arange(6), 6)                         # (p, 36): columns c
    if np.any(column[centre_dofs] < 0):  # a mass centre's DOF eliminated: not the kind kept
        return None
    rows = np.concatenate([unit, port_dofs.ravel()])
    cols = np.concatenate([column[unit], column[centre_dofs].ravel()])
    position = rows * n_dof + cols
    order = np.argsort(position)
    if np.any(np.diff(position[order]) == 0):  # two entries in one place: not the kind kept
        return None
    elimination = _Elimination(ports, centres, order, position[order], cols[order], unit.size, parts.masters,
                               (n_full, n_dof))
    kept, full = elimination.T(parts.layout.positions), parts.T
    lines = np.repeat(np.arange(n_full), np.diff(full.indptr))
    order = np.argsort(lines * n_dof + full.indices)          # the full build's entries, columns ascending
    same = (np.array_equal(kept.indptr, full.indptr) and np.array_equal(kept.indices, full.indices[order])
            and np.array_equal(kept.data, full.data[order]))
    return elimination if same else None
