"""The coarse predictions kept for the last model and count asked
(:func:`linmstmm.coarse_prediction.predict_frequencies`): asked again, they are the
ones a fresh eigensolve gives, bit for bit, without solving; and a warm-started
sweep's first step measures the predictions' error at its roots from the
predictions its own search made (:func:`linmstmm.warm_starts.prediction_error`),
with no eigenproblem solved after the search."""
from __future__ import annotations

import numpy as np
import pytest

import linmstmm.coarse_prediction as coarse
from linmstmm.model import load_model
from linmstmm.roots.settings import predictions_wanted
from linmstmm.sweep import solve_step
from linmstmm.warm_starts import largest_difference


@pytest.fixture
def eigensolves(monkeypatch):
    """A list that grows by one at every eigensolve of a coarse pencil, all kept ones dropped."""
    solved, solve = [], coarse._lowest_eigenvalues
    monkeypatch.setattr(coarse, "_lowest_eigenvalues", lambda *args: solved.append(args[1]) or solve(*args))
    coarse.coarse_pencil.cache_clear()
    yield solved
    coarse.coarse_pencil.cache_clear()


def test_kept_predictions_are_a_fresh_eigensolves(eigensolves):
    model = load_model("models/launcher2/launcher2.toml")
    first = coarse.predict_frequencies(model, 24)
    solves = len(eigensolves)
    assert solves >= 1
    again = coarse.predict_frequencies(model, 24)
    assert len(eigensolves) == solves and again is not first and np.array_equal(again, first)
    again[:] = 0.0                                          # the caller's own copy
    coarse.coarse_pencil.cache_clear()
    fresh = coarse.predict_frequencies(model, 24)
    assert len(eigensolves) == 2 * solves and np.array_equal(fresh, first)
    assert np.array_equal(coarse.predict_frequencies(model, 24), first)
    coarse.predict_frequencies(model, 12)                   # another count is solved
    assert len(eigensolves) > 2 * solves


def test_first_step_of_a_chain_solves_no_eigenproblem_after_its_search(eigensolves):
    model, count = load_model("models/mlrs/mlrs.toml"), 6
    step = solve_step(model, count, engine="compiled", with_shapes=False, chained=True)
    assert eigensolves == [predictions_wanted(count) + coarse.coarse_pencil(model, 2).rigid_body_modes]
    coarse.coarse_pencil.cache_clear()
    predicted = coarse.predict_frequencies(model, predictions_wanted(count)) / (2 * np.pi)
    assert step.prediction_error == largest_difference(predicted, step.frequencies_hz)
    assert 0 < step.prediction_error < 1e-2
