"""A model whose structure a compiled program already serves (a parameter study's next
step) takes that program with its own numbers (linmstmm.program.compile_program): the
result must be, array for array, the program a fresh walk of its carry writes."""
from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from linmstmm import program
from linmstmm.compiled_model import forget_compiled_models
from linmstmm.deduction import Deduction
from linmstmm.model import ModelError, load_model
from linmstmm.nullspace import release_indeterminate
from linmstmm.parameters import get_value, parameter_keys, parse_key, with_values
from linmstmm.topology import build_topology
from random_models import KINDS, random_model
from test_joints import beam_on_joint, four_bar, pinned_bars, sliding_carts

MODELS = Path(__file__).resolve().parents[1] / "models"


def _models():
    yield from (load_model(MODELS / f) for f in ("mlrs/mlrs.toml", "launcher2/launcher2.toml"))
    yield from (random_model(kind, seed) for kind in KINDS for seed in range(3))
    yield from (four_bar(), pinned_bars(), sliding_carts(), beam_on_joint(["rx", "ry"]))


def _deduced(model):
    deduction = Deduction(build_topology(model))
    release_indeterminate(deduction)
    return deduction


def _edited(model, rng):
    """``model`` with a third of its numbers moved by up to 20 % (points off springs by up to 1 %
    of its size: a spring's ends must stay together; no frame or inertia tensor)."""
    on_springs = {f"points.{p}[" for spring in model.springs for p in spring.ends}
    keys = [k for k in parameter_keys(model) if k[:k.rfind("[") + 1] not in on_springs
            and ".axes[" not in k and ".inertia[" not in k]  # frames and tensors stay valid
    size = np.ptp(np.array(list(model.points.values())), axis=0).max()
    edits = {}
    for text in rng.choice(keys, size=max(1, len(keys) // 3), replace=False):
        key, value = parse_key(model, text), get_value(model, parse_key(model, text))
        edits[key] = value + 0.01 * size * rng.uniform(-1, 1) if key.section == "points" else value * rng.uniform(0.8, 1.2)
    return with_values(model, edits)


@pytest.mark.parametrize("model", list(_models()), ids=lambda m: m.name)
def test_a_program_with_new_numbers_is_the_program_a_fresh_walk_writes(model):
    rng = np.random.default_rng(7)
    forget_compiled_models()
    program.compile_program(_deduced(model))
    checked = 0
    for _ in range(6):
        try:
            edited = _edited(model, rng)
        except ModelError:  # an edit that breaks the model (an inertia off its triangle): none to compile
            continue
        deduction = _deduced(edited)
        reused = program._structure(deduction) in program._layouts
        assert reused == (program._structure(deduction) == program._structure(_deduced(model)))
        kept = program.compile_program(deduction)
        program._layouts.clear()
        fresh = program.compile_program(_deduced(edited))
        program.compile_program(_deduced(model))
        for field in dataclasses.fields(fresh):
            assert np.array_equal(getattr(kept, field.name), getattr(fresh, field.name)), field.name
        checked += reused
    assert checked  # the kept walk served at least one edited model


def test_a_different_structure_walks_its_own_carry():
    model = load_model(MODELS / "mlrs/mlrs.toml")
    forget_compiled_models()
    program.compile_program(_deduced(model))
    held = dataclasses.replace(model, boundary={})  # the same elements, nothing fixed
    assert program._structure(_deduced(held)) not in program._layouts


def test_forgetting_compiled_models_forgets_the_walks():
    program.compile_program(_deduced(load_model(MODELS / "cantilever_tip_mass.toml")))
    forget_compiled_models()
    assert not program._layouts
