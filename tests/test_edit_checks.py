"""An edited model (linmstmm.parameters.with_values) is checked only where a change of
numbers can break it (linmstmm.model.with_numbers): it must accept and refuse exactly
what the constructor's full check accepts and refuses, with the same message."""
from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from linmstmm.model import Model, ModelError, load_model
from linmstmm.parameters import _edited_numbers, parameter_keys, parse_key, with_values
from random_models import KINDS, random_model

MODELS = Path(__file__).resolve().parents[1] / "models"
FILES = ["mlrs/mlrs.toml", "launcher2/launcher2.toml", "cantilever_tip_mass.toml",
         "spring_mass_chain.toml", "dashpot_chain.toml"]


def _fully_checked(model: Model, edits) -> Model:
    """The edited model built by the constructor, which checks every record."""
    points, changed, damping = _edited_numbers(model, edits)
    return dataclasses.replace(model, points=points, damping=damping, **{
        attribute: tuple(changed.get(r.name, r) for r in getattr(model, attribute))
        for attribute in ("rigids", "beams", "springs")})


def _outcome(build):
    """("ok", the model's numbers) or ("refused", the message, element, key)."""
    try:
        model = build()
    except ModelError as error:
        return ("refused", str(error), error.element, error.key)
    return ("ok", [(k, _value(model, k)) for k in parameter_keys(model)]
            + [(r.name, getattr(r, "length", None)) for r in model.beams])


def _value(model, key):
    from linmstmm.parameters import get_value

    return get_value(model, parse_key(model, key))


def _drawn_value(rng, value: float) -> float:
    """A new value for a number now ``value``: mostly plausible, often one that breaks something."""
    choice = rng.integers(10)
    return [value * rng.uniform(0.5, 2.0), 0.0, -abs(value) - 1.0, np.nan, np.inf, value + 1e6,
            value + rng.normal(), value * (1 + 1e-12), 1e-30,
            value + 1e12][choice]  # a point this far makes every other beam shorter than the length tolerance


def _models():
    yield from (load_model(MODELS / f) for f in FILES)
    yield from (random_model(kind, seed) for kind in KINDS for seed in range(4))


@pytest.mark.parametrize("model", list(_models()), ids=lambda m: m.name)
def test_an_edit_is_accepted_and_refused_as_the_full_check_would(model):
    rng = np.random.default_rng(abs(hash(model.name)) % 2**32)
    keys = parameter_keys(model)
    refused = accepted = 0
    for _ in range(60):
        chosen = rng.choice(keys, size=min(len(keys), rng.integers(1, 4)), replace=False)
        edits = {}
        for text in chosen:
            key = parse_key(model, text)
            edits[key] = _drawn_value(rng, _value(model, text))
        fast, full = _outcome(lambda: with_values(model, edits)), _outcome(lambda: _fully_checked(model, edits))
        assert fast == full or (fast[0] == full[0] == "ok" and _same_numbers(fast[1], full[1])), (chosen, fast, full)
        refused += fast[0] == "refused"
        accepted += fast[0] == "ok"
    assert refused and accepted  # both sides of the check were exercised


def _same_numbers(a, b) -> bool:
    """Equal lists of (name, value), nan equal to nan."""
    return len(a) == len(b) and all(x[0] == y[0] and (x[1] == y[1] or (np.isnan(x[1]) and np.isnan(y[1])))
                                    for x, y in zip(a, b))


def test_an_edited_model_cannot_be_changed_in_place():
    model = load_model(MODELS / "mlrs/mlrs.toml")
    edited = with_values(model, {parse_key(model, "points.muzzle[2]"): 3.5,
                                 parse_key(model, "rigid.cradle.com[0]"): 0.6})
    with pytest.raises(TypeError):
        edited.points["muzzle"] = np.zeros(3)
    for array in (edited.points["muzzle"], edited.element("cradle").com, edited.element("tube_fore").axes):
        assert not array.flags.writeable
    assert isinstance(edited.rigids, tuple) and dataclasses.replace(edited).points["muzzle"][2] == 3.5
