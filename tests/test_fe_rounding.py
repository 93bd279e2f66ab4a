"""The FE route's float64 eigenvalues on fine meshes against the same eigenproblems
solved in mpmath (tests/mpmath_stiffness.py), on a model that made its rounding
show: a floating loop of three beams and three bodies, one beam 7e10 times
stiffer in one bending plane than in the other, its second frequency a torsion
of the beam whose polar inertia is 3.5e10 times its torsion constant.

The rigid-body modes, deflated from every solve, are stored to the rounding of
their translations, which the stiff plane's chord rotations (w₂ − w₁)/h take in
1/h larger: Rayleigh quotients taken from the deflated vectors came out
7e-10 to 3e-9 high on meshes of 128 to 1024 elements per beam, and the
refinement reported the second frequency 1.66e-9 off with an estimate of 4.5e-11.
"""
from __future__ import annotations

import mpmath as mp
import numpy as np
import pytest
from mpmath_stiffness import ExactStiffness
from varied_models import varied_model

from linmstmm.fe import assemble, fe_frequencies, fe_modes

#: Relative rounding allowed in a mesh's float64 λ (measured: 1e-14 up to 1024
#: elements per beam; the deflated vectors' Rayleigh quotients were 2.3e-9 off).
MESH_ROUNDING = 1e-12


@pytest.fixture(scope="module")
def floating_loop():
    return varied_model(98)[0]


def test_a_fine_mesh_has_the_eigenvalues_of_that_mesh_in_mpmath(floating_loop):
    """λ₁..λ₃ on 512 elements per beam: the float64 subspace iteration against the
    roots of det(K − λM) of the same mesh, interior nodes condensed exactly."""
    lam = fe_modes(assemble(floating_loop, 512), 3)[0]
    mesh = ExactStiffness(floating_loop, elements=512)
    exact = np.array([float(mesh.root(value)) for value in lam])
    assert np.all(np.abs(lam / exact - 1) <= MESH_ROUNDING), lam / exact - 1


def test_refined_frequencies_are_within_their_estimates_of_the_exact_beams(floating_loop):
    """The refinement of the lowest ten (the meshes go to 512 elements per beam):
    f₁..f₃ against the roots of the exact dynamic stiffness (no mesh, no transfer
    matrix), within each one's own error estimate and the rounding the first test
    allows (the extrapolation takes it in at most 1.5 times, halved in f)."""
    result = fe_frequencies(floating_loop, count=10)
    exact = ExactStiffness(floating_loop)
    for f, estimate in zip(result.frequencies_hz[:3], result.error_estimate[:3]):
        reference = mp.sqrt(exact.root((2 * np.pi * f) ** 2)) / (2 * mp.pi)
        assert abs(float(f / reference) - 1) <= estimate + MESH_ROUNDING, (f, reference, estimate)
