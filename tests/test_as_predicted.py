"""Predictions that stand as the coarse model gives them (rtol from
:data:`linmstmm.rayleigh.AS_PREDICTED_FROM` up): certified by Wittrick–Williams counts
alone, without their modes; where some do not stand, only theirs are made. Checked
against the FE route on the same model, which shares nothing with the counts or the
transfer matrices but the file."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import linmstmm.solve
from linmstmm import load_model, natural_frequencies
from linmstmm.coarse_prediction import predict_frequencies
from linmstmm.fe import fe_frequencies
from linmstmm.rayleigh import AS_PREDICTED_FROM, PREDICTED_TO
from linmstmm.roots.settings import predictions_wanted
from linmstmm.standard_eigen import Bisection
from linmstmm.wittrick_williams import ModeCounter

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture
def made(monkeypatch):
    """{"vectors": eigenvector sets a bisection makes, "refined": the rows of each set of
    Rayleigh values made}, growing as a solve runs."""
    made, vectors, rayleigh = {"vectors": 0, "refined": []}, Bisection.vectors, ModeCounter.rayleigh_values

    def counted_vectors(self):
        made["vectors"] += self._vectors is None
        return vectors(self)

    def counted_rayleigh(self, modes, *args, **kwargs):
        made["refined"].append(len(modes))
        return rayleigh(self, modes, *args, **kwargs)

    monkeypatch.setattr(Bisection, "vectors", counted_vectors)
    monkeypatch.setattr(ModeCounter, "rayleigh_values", counted_rayleigh)
    predict_frequencies.cache_clear()
    yield made
    predict_frequencies.cache_clear()


@pytest.fixture(scope="module")
def launcher():
    return load_model(ROOT / "models" / "mlrs" / "mlrs.toml")


@pytest.fixture(scope="module")
def launcher_fe(launcher):
    """The FE route's 20 lowest (Hz) at rtol 1e-9, with its own error estimate."""
    fe = fe_frequencies(launcher, 20, rtol=1e-9)
    assert np.max(fe.error_estimate) <= 1e-9  # far inside every rtol asked here
    return fe.frequencies_hz


@pytest.mark.parametrize("rtol", [1e-5, 1e-4])
def test_the_launchers_ten_lowest_stand_as_predicted_without_modes(launcher, launcher_fe, made, rtol):
    """Coarse values within 2.0e-6 of the roots: every one stands, found only to
    PREDICTED_TO × rtol."""
    result = natural_frequencies(launcher, 10, engine="compiled", rtol=rtol)
    predicted = predict_frequencies(launcher, predictions_wanted(10))[:10] / (2 * np.pi)  # to rounding
    assert made == {"vectors": 0, "refined": []} and result.evaluations == 0
    assert np.all(np.abs(result.frequencies_hz / predicted - 1) <= PREDICTED_TO * rtol)
    assert np.max(np.abs(result.frequencies_hz / launcher_fe[:10] - 1)) <= rtol


@pytest.mark.parametrize("count, rtol", [(10, AS_PREDICTED_FROM), (20, 1e-4)])
def test_where_some_do_not_stand_only_they_are_refined(launcher, launcher_fe, made, count, rtol):
    """A few coarse values lie more than rtol off (the ten lowest up to 2.0e-6, the
    twenty lowest up to 5.3e-4): the modes are made once, and only those few refined."""
    result = natural_frequencies(launcher, count, engine="compiled", rtol=rtol)
    assert made["vectors"] == 1 and len(made["refined"]) == 1 and 0 < made["refined"][0] < count // 2
    assert np.max(np.abs(result.frequencies_hz / launcher_fe[:count] - 1)) <= rtol


@pytest.mark.parametrize("engine", ["compiled", "numpy"])
def test_a_beam_models_predictions_that_do_not_stand_are_refined_within_rtol(engine):
    """The tip-mass cantilever: bending waves that a coarse mesh resolves to about 1e-3
    only, on a finer mesh than the first; every root within rtol of the FE route's."""
    model = load_model(ROOT / "models" / "cantilever_tip_mass.toml")
    fe = fe_frequencies(model, 12, rtol=1e-9)
    result = natural_frequencies(model, 12, engine=engine, rtol=AS_PREDICTED_FROM)
    allowed = AS_PREDICTED_FROM + 3 * fe.error_estimate
    assert np.all(np.abs(result.frequencies_hz / fe.frequencies_hz - 1) <= allowed)


@pytest.mark.parametrize("rtol", [None, AS_PREDICTED_FROM / 10])
def test_a_tighter_request_predicts_with_the_modes(launcher, monkeypatch, rtol):
    asked = []
    predicted_modes = linmstmm.solve.predicted_modes
    monkeypatch.setattr(linmstmm.solve, "predicted_modes",
                        lambda model, count, later=False, accuracy=None:
                        asked.append(later) or predicted_modes(model, count, later, accuracy))
    natural_frequencies(launcher, 10, engine="compiled", rtol=rtol)
    assert asked == [False]


def test_a_root_found_within_rtol_of_a_value_that_stood_takes_its_place(monkeypatch):
    """Varied model 41's twenty lowest at rtol 1e-4: the root at 3457.9 rad/s is predicted
    at 3503.9, and the secant and the pencil from there land on the next root, whose
    coarse value (7e-6 off) stood. Divided out as it stood, that value left a zero
    beside its pole, which the deflated secant took for a known root: the segment
    search ran (48 evaluations). The root found there takes the value's place, and
    the deflated secant finds the missing one."""
    from varied_models import varied_model

    from linmstmm.roots import RootFinder

    searched, segment = [], RootFinder.segment
    monkeypatch.setattr(RootFinder, "segment", lambda self, lo, hi: searched.append((lo, hi)) or segment(self, lo, hi))
    result = natural_frequencies(varied_model(41)[0], 20, engine="compiled", rtol=1e-4)
    fe = fe_frequencies(varied_model(41)[0], 20, rtol=1e-10)
    assert searched == []
    assert np.all(np.abs(result.frequencies_hz / fe.frequencies_hz - 1) <= 1e-4 + 3 * fe.error_estimate)


def test_the_numpy_engine_finds_the_coarse_values_to_rounding_whatever_is_loaded(launcher):
    """Only a compiled counter asks for the coarse frequencies to a fraction of rtol (the
    compiled bracketing): the numpy engine's values are LAPACK's, to the bit, with the
    compiled kernels loaded in the process or not, so its answers do not depend on what
    ran before in it."""
    from linmstmm.determinant import load_kernels

    load_kernels()
    predict_frequencies.cache_clear()
    result = natural_frequencies(launcher, 10, engine="numpy", rtol=1e-4)
    predicted = predict_frequencies(launcher, predictions_wanted(10))[:10] / (2 * np.pi)  # to rounding
    assert np.array_equal(result.frequencies_hz, predicted)
