"""What a parameter study's next model takes from a model of the same structure
(linmstmm.model_structure) must be, array for array, what a fresh build of it gives:
the rigid-body motions, the Wittrick–Williams counter's matrices and the unknowns a
solve releases, on edited launchers, random models and jointed ones."""
from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from linmstmm import counter_parts, model_structure, rigid_motion
from linmstmm.compiled_model import forget_compiled_models
from linmstmm.fe.assembly import constrained_parts
from linmstmm.fe.layout import _layout
from linmstmm.fe.node_constraints import kept_node_constraints, node_constraints
from linmstmm.fe.port_following import kept_port_following, port_following
from linmstmm.wittrick_williams import ModeCounter
from linmstmm.model import ModelError, load_model
from test_program_reuse import _edited, _models

MODELS = Path(__file__).resolve().parents[1] / "models"


def _edits(model, count: int = 6, seed: int = 7):
    """Up to ``count`` edited copies of ``model`` (its numbers moved, its structure kept)."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        try:
            yield _edited(model, rng)
        except ModelError:  # an edit that breaks the model: nothing to compare
            continue


def _kept_and_fresh(model, edited, build):
    """(``build(edited)`` after ``model`` left its structure's parts behind, the same built
    with nothing kept), and whether the first took kept parts. ``model`` is built twice:
    the second build takes the kept parts too, and leaves behind what they keep of it."""
    forget_compiled_models()
    build(model)
    build(model)
    reused = model_structure.structure_of(edited) == model_structure.structure_of(model)
    kept = build(edited)
    forget_compiled_models()
    return kept, build(edited), reused


@pytest.mark.parametrize("model", list(_models()), ids=lambda m: m.name)
def test_rigid_body_motions_of_a_kept_structure_are_those_found_afresh(model):
    reused = 0
    for edited in _edits(model):
        kept, fresh, same = _kept_and_fresh(model, edited, rigid_motion._motions)
        assert np.array_equal(kept, fresh)
        reused += same
    assert reused  # the kept structure served at least one edited model


def _counter_arrays(model) -> list:
    """Every array a Wittrick–Williams counter of ``model`` counts with."""
    counter = ModeCounter(model, "numpy")
    return [np.array(counter.n_dof), counter._static, counter._mass, counter._maps, counter._columns,
            *dataclasses.astuple(counter._beams)]


@pytest.mark.parametrize("model", list(_models()), ids=lambda m: m.name)
def test_a_counter_on_a_kept_elimination_is_the_counter_built_afresh(model):
    """The counter of an edited model, built on the elimination its structure's first
    model left behind (linmstmm.counter_parts), against the full build."""
    reused = 0
    for edited in _edits(model):
        kept, fresh, same = _kept_and_fresh(model, edited, _counter_arrays)
        assert len(kept) == len(fresh)
        for ours, theirs in zip(kept, fresh):
            assert ours.shape == theirs.shape and np.array_equal(ours, theirs)
        reused += same and counter_parts._springs.get(edited, lambda m: None) is not None
    if model.name.startswith("MLRS"):
        assert reused  # the launcher's structure is of the kind kept, and served


def test_the_kept_elimination_is_the_first_models_and_makes_the_full_builds_arrays():
    """The layout kept for a structure is the one the first model's node constraints made
    their T with, and equals the layout made anew for every next model of the structure;
    that model takes its T from it, the arrays (types included) of its full build, with
    the same masters."""
    model = load_model(MODELS / "mlrs/mlrs.toml")
    forget_compiled_models()
    ModeCounter(model)
    kept = counter_parts._springs.get(model, lambda m: None)
    following = kept_node_constraints(model).following
    assert kept is not None and kept_port_following(model, _layout(model, 1)) is following
    edited = [edit for edit in _edits(model)
              if model_structure.structure_of(edit) == model_structure.structure_of(model)]
    assert edited
    for edit in edited:
        ours = counter_parts.counter_parts(edit)
        assert counter_parts._springs.get(edit, lambda m: None) is kept
        assert node_constraints(edit).following is following
        fresh = port_following(edit, _layout(edit, 1))          # the layout made anew: the kept one
        for name in ("arm_ends", "arm_starts", "arm_signs", "rows", "cols", "source", "masters"):
            a, b = getattr(following, name), getattr(fresh, name)
            assert a.dtype == b.dtype and np.array_equal(a, b)
        assert following.shape == fresh.shape
        theirs = constrained_parts(edit, 1, node_constraints(edit))
        assert np.array_equal(ours.masters, theirs.masters) and ours.T.shape == theirs.T.shape
        for name in ("indptr", "indices", "data"):
            a, b = getattr(ours.T, name), getattr(theirs.T, name)
            assert a.dtype == b.dtype and np.array_equal(a, b)
    forget_compiled_models()


def test_only_an_elimination_fixed_by_the_structure_is_kept():
    """A port on a boundary point, a point two bodies share or an inf spring direction
    puts numbers into the constraints: such a structure keeps no elimination."""
    model = load_model(MODELS / "mlrs/mlrs.toml")
    forget_compiled_models()
    ModeCounter(model)
    assert counter_parts._springs.get(model, lambda m: None) is not None
    body = model.rigids[0]
    for changed in (dataclasses.replace(model, boundary={**model.boundary, body.ports[0]: np.ones(6, bool)}),
                    dataclasses.replace(model, springs=tuple(dataclasses.replace(s, k=np.where(
                        np.arange(6) == 0, np.inf, s.k)) for s in model.springs))):
        ModeCounter(changed)
        assert counter_parts._springs.get(changed, lambda m: 0) is None


def test_a_structure_differs_where_a_release_or_a_boundary_does():
    model = load_model(MODELS / "mlrs/mlrs.toml")
    held = dataclasses.replace(model, boundary={})
    assert model_structure.structure_of(held) != model_structure.structure_of(model)
    assert rigid_motion.rigid_body_mode_count(held) == 6 != rigid_motion.rigid_body_mode_count(model)


def test_forgetting_compiled_models_forgets_the_structures():
    model = load_model(MODELS / "cantilever_tip_mass.toml")
    rigid_motion.rigid_body_mode_count(model)
    forget_compiled_models()
    assert not rigid_motion._free_parts._kept and model_structure.structure_of.cache_info().currsize == 0
