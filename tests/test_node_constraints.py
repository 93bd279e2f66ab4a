"""The nodes' constraint elimination, made once and extended to every mesh.

* the T and masters a mesh takes from its nodes' elimination (an identity block
  for the interior beam nodes) are the arrays that eliminating that mesh's
  constraints from the start gives, bit for bit, on the launchers, random
  models and models whose beams declare directions rigid (which are always
  eliminated mesh by mesh);
* where every constraint is a fixed component of a point no body owns, the
  nodes' T is the port map without those columns, the arrays the general
  elimination gives (on the launchers and the random models of that kind; the
  others are eliminated the general way);
* the Wittrick–Williams counter and the coarse predicting mesh of one model
  object eliminate its nodes' constraints once, and forgetting the compiled
  models forgets that elimination too.
"""
from __future__ import annotations

from dataclasses import replace
from unittest import mock

import numpy as np
import pytest
from random_models import random_model
from test_fe_assembly import mixed_model

from linmstmm.coarse_prediction import coarse_pencil
from linmstmm.compiled_model import forget_compiled_models
from linmstmm.fe.assembly import _add_beam_constraints
from linmstmm.fe.layout import _beam_axes, _layout, _Triplets, element_maps
from linmstmm.fe import node_constraints as node_module
from linmstmm.fe.node_constraints import held_at_free_points, kept_node_constraints, node_constraints
from linmstmm.model import load_model
from linmstmm.wittrick_williams import mode_counter

MODELS = {
    "launcher": lambda: load_model("models/mlrs/mlrs.toml"),
    "launcher 2": lambda: load_model("models/launcher2/launcher2.toml"),
    "mixed (a beam rigid axially)": mixed_model,
    "mixed floating": lambda: mixed_model(held=False),
    **{f"{kind} {seed}": (lambda kind=kind, seed=seed: random_model(kind, seed))
       for kind in ("tree", "floating_tree", "loops", "floating_loops", "ring") for seed in range(4)},
}


def general_node_constraints(model):
    """:func:`node_constraints` of ``model`` the general way: the port map formed and
    every constraint row eliminated in turn."""
    with mock.patch.object(node_module, "held_at_free_points", lambda model: False):
        return node_constraints(model)


def eliminations(model, n):
    """(T, masters) of ``model`` meshed with ``n`` elements per beam: by the nodes'
    shared elimination, and eliminated from the start."""
    layout = _layout(model, n)
    beam_rows = _Triplets()
    _add_beam_constraints(model.beams, element_maps(layout.beam_table, _beam_axes(model.beams)), n, beam_rows)
    return (node_constraints(model).eliminated(beam_rows, 6 * layout.n_nodes),
            replace(general_node_constraints(model), elimination=None).eliminated(beam_rows, 6 * layout.n_nodes))


@pytest.mark.parametrize("name", MODELS)
def test_meshes_extend_the_nodes_elimination_exactly(name):
    model = MODELS[name]()
    for n in (1, 2, 3, 5):
        (T, masters), (reference, reference_masters) = eliminations(model, n)
        assert T.shape == reference.shape and np.array_equal(masters, reference_masters)
        for ours, theirs in ((T.indptr, reference.indptr), (T.indices, reference.indices), (T.data, reference.data)):
            assert ours.dtype == theirs.dtype and np.array_equal(ours, theirs)


def test_fixed_components_alone_are_dropped_as_the_general_elimination_drops_them():
    kinds = set()
    for make in MODELS.values():
        model = make()
        kinds.add(held_at_free_points(model))
        if not held_at_free_points(model):
            continue
        (T, masters), (reference, reference_masters) = (nodes.elimination for nodes in (
            node_constraints(model), general_node_constraints(model)))
        assert T.shape == reference.shape and np.array_equal(masters, reference_masters)
        for ours, theirs in ((T.indptr, reference.indptr), (T.indices, reference.indices), (T.data, reference.data)):
            assert ours.dtype == theirs.dtype and np.array_equal(ours, theirs)
    assert kinds == {True, False} and held_at_free_points(MODELS["launcher"]())


def test_models_with_rigid_beam_directions_are_eliminated_per_mesh():
    assert node_constraints(mixed_model()).elimination is None
    assert node_constraints(load_model("models/mlrs/mlrs.toml")).elimination is not None


def test_counter_and_coarse_mesh_share_one_elimination():
    forget_compiled_models()
    model = load_model("models/mlrs/mlrs.toml")
    mode_counter(model, "numpy")
    coarse_pencil(model, 2)
    info = kept_node_constraints.cache_info()
    assert (info.misses, info.hits, info.currsize) == (1, 1, 1)
    forget_compiled_models()
    assert kept_node_constraints.cache_info().currsize == 0
