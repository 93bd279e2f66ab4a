"""The root search decides by the model's own frequency scale, not by its units.

The search's floor, first chunks and ceiling are multiples of the lowest
:func:`~linmstmm.nullspace.characteristic_frequencies` of the model
(:class:`~linmstmm.roots.RootFinder` ``scale``). A model written in mm-kg-s,
km-kg-s or mm-t-s is the same model: the same frequencies and the same
decisions, so the same number of evaluations of det Ū_all. A copy with its
clock slowed by 1e5 (every stiffness ÷ 1e10: a huge soft structure whose first
frequency is 1e-4 Hz) is searched alike, its frequencies 1e5 times lower; an
absolute floor of 1e-3 rad/s refused it. References: the SI model's own solve
(scaling is exact physics) and the FE route.
"""
from __future__ import annotations

import numpy as np
import pytest
from random_models import random_model
from varied_models import UNITS, in_units

from linmstmm.fe import fe_frequencies
from linmstmm.model import load_model
from linmstmm.solve import frequency_finder, natural_frequencies

#: The same frequencies in other units: rounding of the converted data only.
SAME = 1e-10
#: The same decisions: evaluations of det Ū_all may differ by a secant or Newton step
#: here and there (the converted data round differently), not by a path. The
#: cantilever's double roots took 1745 evaluations in m and 804 in mm until the
#: predicted search's intervals stopped putting an edge between a double root's
#: two predictions (which side rounding put each on decided the path).
SAME_PATH = 0.05
#: ... and by this many evaluations however few there are: one secant step of a
#: pair of roots (the cantilever's ten lowest take 24 to 26 since its double roots
#: go to the pencil and the counts, where the secant had crept to them).
SAME_PATH_STEP = 2


def same_path(a: int, b: int) -> bool:
    return abs(a - b) <= max(SAME_PATH * max(a, b), SAME_PATH_STEP)


@pytest.fixture(scope="module", params=["cantilever", "loops 3"])
def si_model(request):
    return load_model("models/cantilever_tip_mass.toml") if request.param == "cantilever" else random_model("loops", 3)


@pytest.mark.parametrize("units", [u for u in UNITS if u[0] != "m-kg-s"], ids=lambda u: u[0])
def test_other_units_give_the_same_search(si_model, units):
    _, length, mass = units
    reference = natural_frequencies(si_model, count=8)
    scaled = natural_frequencies(in_units(si_model, length, mass), count=8)
    np.testing.assert_allclose(scaled.frequencies_hz, reference.frequencies_hz, rtol=SAME)
    assert same_path(scaled.evaluations, reference.evaluations), (scaled.evaluations, reference.evaluations)
    floors = [frequency_finder(m)[1].floor for m in (si_model, in_units(si_model, length, mass))]
    assert floors[1] == pytest.approx(floors[0], rel=SAME)


def test_a_slow_model_is_searched_like_its_fast_copy(si_model):
    """Time × 1e5: first frequency 1e-4 Hz or below, the search the same, and FE agrees."""
    reference = natural_frequencies(si_model, count=8)
    slow_model = in_units(si_model, 1.0, 1.0, time=1e5)
    slow = natural_frequencies(slow_model, count=8)
    assert slow.frequencies_hz[0] < 1e-4
    np.testing.assert_allclose(slow.frequencies_hz * 1e5, reference.frequencies_hz, rtol=SAME)
    assert same_path(slow.evaluations, reference.evaluations), (slow.evaluations, reference.evaluations)
    fe = fe_frequencies(slow_model, count=8)
    np.testing.assert_allclose(slow.frequencies_hz, fe.frequencies_hz,
                               rtol=max(1e-9, 3 * float(fe.error_estimate.max())))
