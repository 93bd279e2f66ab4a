"""What a parameter study's next model takes from a model of the same structure
(linmstmm.model_structure) must be, array for array, what a fresh build of it gives:
the rigid-body motions, the Wittrick–Williams counter's matrices and the unknowns a
solve releases, on edited launchers, random models and jointed ones."""
from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from linmstmm import model_structure, rigid_motion
from linmstmm.compiled_model import forget_compiled_models
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
    with nothing kept), and whether the first took kept parts."""
    forget_compiled_models()
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
