"""Where a step of a parameter study starts its root search: from its neighbour's
roots, from those extrapolated along the neighbour's last move, or from its own
coarse predictions (:func:`warm_starts`), by what the steps before it measured
(:class:`~linmstmm.sweep.StepSolution`: the last move seen between neighbours, how
far the extrapolation missed, the predictions' error)."""
from __future__ import annotations

import math

import numpy as np

from linmstmm.model import Model
from linmstmm.threads import single_blas_thread


def warm_starts(start) -> np.ndarray | None:
    """The frequencies (Hz) a step starts from: those of its neighbour ``start``,
    those extrapolated along the neighbour's own last move, or None (a cold start,
    from the coarse predictions of its own model).

    Each start is judged by how far it was off where it was last measured: the
    neighbour's roots by the last change seen between neighbours
    (:attr:`~linmstmm.sweep.StepSolution.moved`), the extrapolation (:func:`trend`) by
    how far the same extrapolation missed the neighbour's own roots
    (:attr:`~linmstmm.sweep.StepSolution.trend_miss`). The start with the smaller miss
    is taken (the extrapolation only where the last move is smaller than the closest
    relative gap between the neighbour's roots: two modes that veer may change ranks
    within one move, and the extrapolation then misses by as much as they move, 4e-3
    on the salvo's tenth scene) unless that miss is above the square root of the predictions' error
    (:attr:`~linmstmm.sweep.StepSolution.prediction_error`): a start that has at least
    half the correct digits of a prediction costs the secant (order 1.6) about one
    step more per root, less than the prediction it saves (a coarse FE model
    assembled and solved: 1.4 ms for a launcher scene); one that has fewer costs more,
    and lands on a neighbouring root where it is farther off than their gap. The
    launcher's salvo moves 1-1.4 % a scene (its predictions are 1e-6 off), too far for
    the neighbour's roots (its scenes 2-18 took 742 evaluations from them, 312 from
    their predictions), while the extrapolation misses by 3e-4 to 1e-3 away from the
    scenes where two modes veer: about half its scenes start from it, 3.4-4.1 ms a
    scene against 4.1-4.7 ms from their predictions. With every other tube loaded its
    scenes move 40 ppm, less than the extrapolation misses.
    Where no miss is known yet (the first steps, or a model without predictions) the
    neighbour's roots are taken."""
    if start is None:
        return None
    allowed = math.sqrt(start.prediction_error)
    extrapolated = trend(start)
    if (extrapolated is not None and start.trend_miss < start.moved and not start.trend_miss > allowed
            and start.moved < _closest(start.frequencies_hz)):
        return extrapolated  # (False where a miss is nan)
    return None if start.moved > allowed else start.frequencies_hz


def trend(start) -> np.ndarray | None:
    """The frequencies (Hz) of the step after ``start`` extrapolated linearly, rank by
    rank, from those of ``start`` and of the step it started from
    (:attr:`~linmstmm.sweep.StepSolution.previous_hz`); None where that is not known,
    the two differ in how many they hold, or an extrapolated frequency is not positive."""
    found, previous = start.frequencies_hz, start.previous_hz
    if previous is None or previous.size != found.size or not found.size:
        return None
    extrapolated = 2 * found - previous
    return np.sort(extrapolated) if np.all(extrapolated > 0) else None


def _closest(frequencies: np.ndarray) -> float:
    """Smallest relative gap between neighbouring distinct ``frequencies`` (ascending); inf without two."""
    distinct = np.unique(frequencies)
    return float(np.min(np.diff(distinct) / distinct[1:])) if distinct.size > 1 else math.inf


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
