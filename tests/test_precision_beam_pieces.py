"""Beam pieces orthonormalised after each one: float64 certifies launcher 2's roots above 1e4 rad/s.

A beam piece parts its growing and decaying solutions by e^{2βL} while the carried
state's size grows by e^{βL} at most; when the growth test let two pieces of βL ≈ 4
pass between orthonormalisations, det Ū_all of launcher 2 near its root at
21,465 rad/s (the tube between its rings, βL 24 in six pieces) came out of float64
with an error that moved the root by up to 1e-8 relative, so its 120 lowest
frequencies fell back to mpmath. mpmath at 30 digits is the referee here.
"""
from __future__ import annotations

import numpy as np
import pytest
from det_next_to_root import det_errors_next_to

from linmstmm import load_model, natural_frequencies
from linmstmm.determinant import NumpyDeterminant
from linmstmm.precision import refine_roots
from linmstmm.solve import frequency_finder

#: rad/s, launcher 2's root near 21,465 rad/s as float64 found it before the fix
#: (the mpmath refinement starts from here).
NEAR = 21465.437071982018


@pytest.fixture(scope="module")
def launcher2():
    model = load_model("models/launcher2/launcher2.toml")
    deduction, finder, _ = frequency_finder(model, engine="compiled")
    root = refine_roots(deduction, model, [NEAR], 30)[0]
    return model, deduction, finder.determinant, root


def test_the_root_above_1e4_rad_s_is_certified_in_float64_to_the_default_rtol(launcher2):
    model, _, _, root = launcher2
    result = natural_frequencies(model, 120, engine="compiled")
    assert result.precision == "float64"
    omegas = result.frequencies_hz * 2 * np.pi
    nearest = omegas[np.argmin(np.abs(omegas - float(root)))]
    assert abs(nearest / float(root) - 1) <= 1e-9


@pytest.mark.parametrize("engine", ["numpy", "compiled"])
def test_det_next_to_the_root_is_accurate_by_either_engine(launcher2, engine):
    """det Ū_all 1e-7 either side of the root, against mpmath: within 1e-3 relative (the
    root to 1e-10); before the fix 4e-2 and 1.4e-1 (numpy), 1e-2 and 8e-2 (compiled)."""
    model, deduction, compiled, root = launcher2
    determinant = compiled if engine == "compiled" else NumpyDeterminant(deduction)
    assert np.all(det_errors_next_to(model, deduction, determinant, float(root), 1e-7) <= 1e-3)
