"""The launcher written in other units has the SI launcher's frequencies.

Ū_all is balanced from the model's own units (:mod:`linmstmm.own_units`)
before its null space is read, so a model in µm, pg and µs (forces in nN) or in
µm, µg and s is not taken for a mechanism; the reference is the same model in
SI, its frequencies scaled by the unit of time.
"""
from __future__ import annotations

import numpy as np
import pytest
from builders import BUNDLED_MODELS
from varied_models import in_units

import linmstmm as lm
from linmstmm.deduction import Deduction
from linmstmm.nullspace import PROBES, characteristic_frequencies, equilibration, own_units_start
from linmstmm.topology import build_topology

LAUNCHER = next(p for p in BUNDLED_MODELS if p.name == "mlrs.toml")


def test_launcher_in_micrometres_picograms_and_microseconds():
    """The same launcher in µm, pg and µs (forces in nN, stresses in kPa): its
    frequencies per µs are the SI ones times 1e-6 (it was refused as a
    mechanism, Ū_all's null space moving with frequency)."""
    model = lm.load_model(LAUNCHER)
    si = lm.natural_frequencies(model, count=4).frequencies_hz
    scaled = lm.natural_frequencies(in_units(model, 1e6, 1e15, 1e6), count=4).frequencies_hz
    np.testing.assert_allclose(scaled * 1e6, si, rtol=1e-9)


def test_launcher_in_micrometres_micrograms_and_seconds():
    model = lm.load_model(LAUNCHER)
    si = lm.natural_frequencies(model, count=4).frequencies_hz
    scaled = lm.natural_frequencies(in_units(model, 1e6, 1e9), count=4).frequencies_hz
    np.testing.assert_allclose(scaled, si, rtol=1e-9)


@pytest.mark.parametrize("length, mass, time", [(1e6, 1e15, 1e6), (1e6, 1e9, 1.0), (1e-3, 1e3, 1.0), (37.0, 1e5, 0.01)])
def test_balanced_matrix_does_not_depend_on_the_units(length, mass, time):
    """Ū_all at the probes, balanced from the model's own units, is the SI one's
    balanced matrix (each unknown and equation scaled by its unit), so its
    singular values, on which the null space is decided, are the same."""
    def balanced_singular_values(model):
        deduction = Deduction(build_topology(model))
        probes = np.asarray(PROBES) * min(characteristic_frequencies(deduction.topology))
        samples = deduction.matrix(probes)
        rows, cols = equilibration(samples[0], start=own_units_start(deduction))
        sigma = np.linalg.svd(rows[:, None] * samples * cols, compute_uv=False)
        return sigma / sigma[:, :1]

    model = lm.load_model(LAUNCHER)
    np.testing.assert_allclose(balanced_singular_values(in_units(model, length, mass, time)),
                               balanced_singular_values(model), rtol=1e-9, atol=1e-14)


def test_launcher_modes_in_micrometres_picograms_and_microseconds():
    """Mode shapes: the null space at each root is read in the model's own units too
    (its shapes were noted as not accurate in float64, Rayleigh quotients 22 % off,
    mass orthogonality 9e-2). Each modal stiffness over modal mass is ω² of the
    SI launcher, scaled, and the shapes are mass-orthogonal."""
    model = lm.load_model(LAUNCHER)
    si = 2 * np.pi * lm.natural_frequencies(model, count=4).frequencies_hz
    modes = lm.mode_shapes(in_units(model, 1e6, 1e15, 1e6), count=4)
    assert not modes.note
    np.testing.assert_allclose(np.asarray(modes.modal_stiffness) / np.asarray(modes.modal_mass) * 1e12,
                               si ** 2, rtol=1e-8)
    assert modes.mass_orthogonality_error <= 1e-9
