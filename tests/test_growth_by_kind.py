"""The orthonormaliser's growth test by kind of row (:func:`linmstmm.godunov.grown`).

Launcher 2's elevating cylinder has soft springs: they turn moments into rotations
that grow by 1e2 and more while the state's largest entry (a force, in newtons)
does not move. Once every long beam piece was orthonormalised after
(linmstmm.deduction), the test by the largest entry alone let the rotations'
columns swamp each other there, and det Ū_all put the root near 7,634 rad/s
2.5e-10 to 5.3e-10 off (1e-13 before that rule). mpmath at 30 digits is the referee
here.
"""
from __future__ import annotations

import mpmath
import numpy as np
import pytest
from det_next_to_root import det_errors_next_to
from varied_models import in_units

import linmstmm.godunov as godunov
from linmstmm import load_model
from linmstmm.deduction import Deduction
from linmstmm.determinant import NumpyDeterminant
from linmstmm.nullspace import release_indeterminate
from linmstmm.solve import frequency_finder
from linmstmm.topology import build_topology

LAUNCHER2 = "models/launcher2/launcher2.toml"
#: rad/s, launcher 2's root near 7,634 rad/s to 30 digits (mpmath: linmstmm.precision.refine_roots at 25).
ROOT = mpmath.mpf("7634.53201781845107644554254198")


@pytest.fixture(scope="module")
def launcher2():
    model = load_model(LAUNCHER2)
    deduction, finder, _ = frequency_finder(model, engine="compiled")
    return model, deduction, finder.determinant


@pytest.mark.parametrize("engine", ["numpy", "compiled"])
def test_the_root_near_7634_rad_s_is_accurate_to_1e_11(launcher2, engine):
    """det Ū_all 1e-6 either side of the root within 1e-5 relative of mpmath's, so that the
    float64 root is within 1e-11 of it: 8e-9 to 5e-7 by either carry; with long beam
    pieces orthonormalised after and the test by the largest entry alone 9e-5 to 2.7e-4
    (the root up to 2.7e-10), without that rule 1.7e-7 to 4.3e-7."""
    model, deduction, compiled = launcher2
    determinant = compiled if engine == "compiled" else NumpyDeterminant(deduction)
    assert np.all(det_errors_next_to(model, deduction, determinant, float(ROOT), 1e-6) <= 1e-5)


def _decisions(model, omega, monkeypatch) -> list[bool]:
    """Whether each growth test of the numpy carry of ``model`` at ``omega`` (rad/s) was due."""
    due = []

    def recorded(sizes, reference, factor):
        result = grown(sizes, reference, factor)
        due.append(bool(result.any()))
        return result

    grown = godunov.grown
    monkeypatch.setattr(godunov, "grown", recorded)
    deduction = Deduction(build_topology(model))
    release_indeterminate(deduction)
    deduction.log_det(np.array([omega]))
    monkeypatch.setattr(godunov, "grown", grown)
    return due


@pytest.mark.parametrize("omega", [2000.0, 20000.0])
@pytest.mark.parametrize("units", [(1e3, 1.0, 1.0), (1e6, 1e15, 1e6)])
def test_the_same_launcher_in_other_units_takes_the_same_decisions(omega, units, monkeypatch):
    """Launcher 2 in mm (or µm, pg and µs) orthonormalises where it does in SI: each kind's
    growth is a ratio of sizes of one kind. (The test by the largest entry, which the tips
    and merges keep, compares kinds in the model's units; on launcher 2 at 2000 rad/s it
    took 8 decisions in SI and 9 in mm, before the test by kind took them over.)"""
    model = load_model(LAUNCHER2)
    si = _decisions(model, omega, monkeypatch)
    other = _decisions(in_units(model, *units), omega / units[2], monkeypatch)
    assert sum(si) > 0
    assert other == si
