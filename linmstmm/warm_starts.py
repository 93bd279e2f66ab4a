"""Where a step of a parameter study starts its root search: from its neighbour's
roots or from its own coarse predictions (:func:`warm_starts`), by what the steps
before it measured (:class:`~linmstmm.sweep.StepSolution`: the last move seen between
neighbours, the predictions' error)."""
from __future__ import annotations

import math

import numpy as np

from linmstmm.model import Model
from linmstmm.threads import single_blas_thread


def warm_starts(start) -> np.ndarray | None:
    """The frequencies (Hz) a step starts from: those of its neighbour ``start``, or
    None (a cold start, from the coarse predictions of its own model).

    The neighbour's are taken unless the last change seen between neighbours
    (:attr:`~linmstmm.sweep.StepSolution.moved`) is above the square root of the
    predictions' error (:attr:`~linmstmm.sweep.StepSolution.prediction_error`): a
    start that has at least half the correct digits of a prediction costs the secant
    (order 1.6) about one step more per root, less than the prediction it saves (a coarse FE model assembled and
    solved: 1.4 ms for a launcher scene); one that has fewer costs more, and lands
    on a neighbouring root where it is farther off than their gap. The launcher's
    salvo moves 1-1.4 % a scene (its predictions are 1e-6 off): its scenes 2-18 took
    742 evaluations warm from the previous scene, 312 from their predictions; with
    every other tube loaded its scenes move 40 ppm and stay warm. Where neither is
    known yet (the first steps, or a model without predictions) the neighbour's are
    taken."""
    if start is None:
        return None
    return None if start.moved > math.sqrt(start.prediction_error) else start.frequencies_hz


def largest_difference(values: np.ndarray, found: np.ndarray) -> float:
    """Largest relative difference of ``values`` from the frequencies ``found`` (both
    ascending, one unit), rank by rank over the ranks both have; nan without one."""
    ranks = min(values.size, found.size)
    return float(np.max(np.abs(values[:ranks] / found[:ranks] - 1))) if ranks else math.nan


@single_blas_thread  # as the search's own predictions, where they are not kept: the eigenproblem is small
def prediction_error(model: Model, count: int, found: np.ndarray) -> float:
    """Largest relative error of the coarse predictions of ``model`` at its lowest
    frequencies ``found`` (Hz), as many as the root search asks for ``count``
    (:meth:`~linmstmm.roots.RootFinder.find`: the predictions that search made are
    kept, :func:`~linmstmm.coarse_prediction.predict_frequencies`, and nothing is
    solved again); nan without predictions."""
    from linmstmm.coarse_prediction import predict_frequencies
    from linmstmm.roots.settings import predictions_wanted

    predicted = predict_frequencies(model, predictions_wanted(count))
    return largest_difference(predicted / (2 * np.pi), found)
