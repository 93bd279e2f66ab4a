"""The FE route gives the same frequencies whatever units a model is written in.

Two floating loops of stiff and soft planes (Iy/Iz up to 1e11 and more): one in
km-kg-s with a massless dangling point, one in mm-t-s. Each against its SI copy
(:func:`varied_models.varied_model` with ``units="m-kg-s"``): the same rigid-body
count, as many elastic frequencies, and the same values. Frequencies in hertz do
not change with the units of length and mass, so nothing is converted.
"""
from __future__ import annotations

import numpy as np
import pytest
from varied_models import varied_model

from linmstmm.fe import fe_frequencies

#: Two solves of one mesh that differ only in units agree to rounding; before the
#: rigid motions were weighted, they differed by 1.5e-5 (km) and 6.9e-8 (mm-t-s).
AGREEMENT = 1e-9
MODELS = [pytest.param(218, "km-kg-s", id="floating loops in km-kg-s"),
          pytest.param(248, "mm-t-s", id="floating loops in mm-t-s")]


@pytest.mark.parametrize("seed, units", MODELS)
def test_one_mesh_gives_the_si_frequencies(seed, units):
    model, variety = varied_model(seed, units=units)
    si, _ = varied_model(seed, units="m-kg-s")
    assert variety.units == units
    theirs, ours = (fe_frequencies(m, count=10, elements_per_beam=64, estimate_error=False) for m in (si, model))
    assert ours.rigid_body_modes == theirs.rigid_body_modes
    assert len(ours.frequencies_hz) == len(theirs.frequencies_hz) == 10
    np.testing.assert_allclose(ours.frequencies_hz, theirs.frequencies_hz, rtol=AGREEMENT, atol=0)


def test_refinement_in_km_reports_every_frequency_of_the_si_copy():
    """Refined to the mesh cap, the km copy lost two of its ten frequencies
    (estimates of 10 % and more) where the SI copy kept them all."""
    model, _ = varied_model(218, units="km-kg-s")
    si, _ = varied_model(218, units="m-kg-s")
    theirs, ours = fe_frequencies(si, count=10), fe_frequencies(model, count=10)
    assert len(ours.frequencies_hz) == len(theirs.frequencies_hz) == 10
    bound = np.maximum(ours.error_estimate, theirs.error_estimate)
    assert np.all(np.abs(ours.frequencies_hz / theirs.frequencies_hz - 1) <= 3 * bound)
