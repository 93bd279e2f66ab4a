"""The FE route gives the launcher's frequencies in any units.

The launcher in µm, pg and µs and in µm, µg and s against the same launcher in
SI (frequencies scaled by the unit of time) and against the transfer matrix
method on the SI model, at one mesh and refined. The static solve of the FE
route works on its equilibrium equations balanced column by column
(:func:`linmstmm.fe.flexibility._balanced_equilibrium`); unbalanced, the µm-pg-µs
launcher came out up to 8 % off on one mesh and unsettled when refined.
"""
from __future__ import annotations

import numpy as np
import pytest
from builders import BUNDLED_MODELS
from varied_models import in_units

import linmstmm as lm
from linmstmm.fe import fe_frequencies

LAUNCHER = next(p for p in BUNDLED_MODELS if p.name == "mlrs.toml")
UNITS = [pytest.param(1e6, 1e15, 1e6, id="µm-pg-µs"), pytest.param(1e6, 1e9, 1.0, id="µm-µg-s")]


@pytest.mark.parametrize("length, mass, time", UNITS)
def test_one_mesh_gives_the_si_frequencies(length, mass, time):
    model = lm.load_model(LAUNCHER)
    theirs = fe_frequencies(model, count=6, elements_per_beam=8, estimate_error=False).frequencies_hz
    ours = fe_frequencies(in_units(model, length, mass, time), count=6, elements_per_beam=8,
                          estimate_error=False).frequencies_hz
    np.testing.assert_allclose(ours * time, theirs, rtol=1e-9)


@pytest.mark.parametrize("length, mass, time", UNITS)
def test_refined_frequencies_are_those_of_the_transfer_matrix_method(length, mass, time):
    model = lm.load_model(LAUNCHER)
    exact = lm.natural_frequencies(model, count=4).frequencies_hz
    result = fe_frequencies(in_units(model, length, mass, time), count=4)
    assert len(result.frequencies_hz) == 4
    assert np.all(result.error_estimate <= 1e-9)
    np.testing.assert_allclose(result.frequencies_hz * time, exact, rtol=1e-9)
