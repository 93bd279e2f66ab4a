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
axially or in torsion), each port follows its body's mass centre and each fixed
component is dropped, T's entries the ports' lever arms, put into a layout kept
per structure (:func:`~linmstmm.fe.port_following.kept_port_following`, with
which the node constraints make T). :func:`counter_parts` takes that layout for
a new model of such a structure, and its springs from the last model's where
their records are the same: the same arrays as the full build. On the
launcher's firing scenes: 0.08 ms a scene against 0.18 ms for the parts made anew.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from linmstmm.fe.assembly import ConstrainedParts, constrained_parts
from linmstmm.fe.layout import _layout, _Triplets, element_maps
from linmstmm.fe.node_constraints import _add_rigid_masses, _add_springs, kept_node_constraints
from linmstmm.fe.port_following import kept_port_following
from linmstmm.model import Model
from linmstmm.model_structure import MODELS_KEPT, KeptByStructure


@dataclass(frozen=True, eq=False)
class _KeptSprings:
    """The springs of the last model of a structure held at free points
    (:func:`~linmstmm.fe.node_constraints.held_at_free_points`)."""

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


#: The kept springs of each structure seen last (None: one not held at free points).
_springs = KeptByStructure(MODELS_KEPT)


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
        the model's elimination follows its ports), masters, n_full, spring strains
        and stiffnesses, rigid masses and beam maps: the same arrays as the full build's.
    """
    fresh = []

    def derived(model: Model) -> _KeptSprings | None:
        nodes = kept_node_constraints(model)
        fresh.append(constrained_parts(model, 1, nodes))
        return None if nodes.following is None else _KeptSprings()

    kept = _springs.get(model, derived)
    if fresh:
        return fresh[0]
    if kept is None:
        return constrained_parts(model, 1, kept_node_constraints(model))
    layout = _layout(model, 1)
    mass = _Triplets(repeats=True)
    _add_rigid_masses(model, layout, mass)
    following = kept_port_following(model, layout)
    return ConstrainedParts(layout, following.T(layout.positions), following.masters, following.shape[0],
                            *kept.springs(model, layout), mass, element_maps(layout.beam_table, layout.beam_axes))
