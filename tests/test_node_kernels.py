"""The compiled node builder (linmstmm._node_kernels, used once numba is loaded) makes,
integer for integer and bit for bit, the node constraints the numpy reference makes:

* the layout of the elimination of a model held at free points (where T's entries sit and where their
  numbers come from) and T itself (linmstmm.fe.port_following);
* the springs' strain and constraint rows and stiffnesses, and the bodies' mass
  entries (linmstmm.fe.node_constraints._add_springs, _add_rigid_masses);
* the beams' elements' DOFs and maps to their local DOFs, one to three elements
  per beam (linmstmm.fe.layout.element_maps);

on the bundled models, models with joints, released directions, rigid spring
directions and beams rigid axially, and 60 random models.
"""
from __future__ import annotations

import dataclasses
from pathlib import Path
from unittest import mock

import numpy as np
import pytest
from random_models import KINDS, random_model
from test_fe_assembly import mixed_model
from test_joints import beam_on_joint, four_bar, pinned_bars, sliding_carts
from test_program_layout import BUNDLED

import linmstmm.determinant as determinant
from linmstmm.fe import port_following
from linmstmm.fe.layout import _element_maps_in_numpy, _layout, element_maps
from linmstmm.fe.node_constraints import held_at_free_points, node_constraints
from linmstmm.model import load_model

MODELS = Path(__file__).resolve().parents[1] / "models"
RANDOM_SEEDS = 12  # of each kind: 60 random models


def _models():
    yield from (load_model(MODELS / path) for path in BUNDLED)
    yield from (four_bar(), pinned_bars(), sliding_carts(), beam_on_joint(["rx", "ry"]), beam_on_joint(["x", "rz"]))
    yield from (mixed_model(), mixed_model(held=False))
    yield from (random_model(kind, seed) for kind in KINDS for seed in range(RANDOM_SEEDS))


def _in_numpy(make, *args):
    """``make(*args)`` with the kernels taken for not loaded: the numpy reference."""
    with mock.patch.object(determinant, "kernels_loaded", lambda: False):
        return make(*args)


def _arrays(value) -> list:
    """Every array in ``value`` (a dataclass, triplets, tuple or list, nested), in order."""
    if isinstance(value, np.ndarray):
        return [value]
    if dataclasses.is_dataclass(value):
        return [a for field in dataclasses.fields(value) for a in _arrays(getattr(value, field.name))]
    if hasattr(value, "joined"):  # triplets: their entries and rows
        return [*value.joined(), np.array([value.n_rows, len(value.rows)])]
    if isinstance(value, (tuple, list)):
        return [a for part in value for a in _arrays(part)]
    if hasattr(value, "indptr"):
        return [value.indptr, value.indices, value.data, np.array(value.shape)]
    return []


def _same(compiled, reference) -> bool:
    first, second = _arrays(compiled), _arrays(reference)
    return len(first) == len(second) and all(a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()
                                             for a, b in zip(first, second))


@pytest.fixture(scope="module", autouse=True)
def kernels():
    determinant.load_kernels()


@pytest.mark.parametrize("model", list(_models()), ids=lambda m: m.name)
def test_the_compiled_node_constraints_are_the_numpy_ones(model):
    assert determinant.kernels_loaded()
    assert _same(node_constraints(model), _in_numpy(node_constraints, model))


@pytest.mark.parametrize("model", [model for model in _models() if held_at_free_points(model)], ids=lambda m: m.name)
def test_the_compiled_port_following_is_the_numpy_one(model):
    layout = _layout(model, 1)
    compiled, reference = port_following.port_following(model, layout), _in_numpy(port_following.port_following,
                                                                                   model, layout)
    assert _same(compiled, reference)
    assert _same(compiled.T(layout.positions), compiled._T_in_numpy(layout.positions))


@pytest.mark.parametrize("model", list(_models()), ids=lambda m: m.name)
def test_the_compiled_element_maps_are_the_numpy_ones(model):
    for elements_per_beam in (1, 2, 3):
        layout = _layout(model, elements_per_beam)
        assert _same(element_maps(layout.beam_table, layout.beam_axes),
                     _element_maps_in_numpy(layout.beam_table, layout.beam_axes))
