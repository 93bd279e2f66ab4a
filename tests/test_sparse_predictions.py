"""Predictions of models too large for the dense coarse eigensolve: a cantilever cut into
300 beams (3,606 unknowns on the two-element mesh, above MAX_UNKNOWNS) is predicted by
block shift-invert Lanczos about 0 (its stiffness is positive definite), so its search
polishes predictions instead of scanning; so, about half its lowest elastic eigenvalue,
is a rod free at both ends. So too are a round section's double roots, whose predictions
coincide, and close pairs of distinct roots. The references are the Euler–Bernoulli beam's frequency
equations, independent of both FE and transfer matrices."""
from __future__ import annotations

import dataclasses

import mpmath as mp
import numpy as np
import pytest
from builders import cantilever_of_beams

from linmstmm import coarse_prediction
from linmstmm.builders import make_beam
from linmstmm.coarse_prediction import predicted_modes
from linmstmm.model import Model
from linmstmm.solve import natural_frequencies

BEAMS = 300
LENGTH = 2.0


def cantilever_reference_hz(beam, count: int) -> np.ndarray:
    """The ``count`` lowest natural frequencies (Hz) of a clamped-free uniform beam of
    ``beam``'s section and material and length LENGTH: bending in both planes
    (cos λ cosh λ + 1 = 0), torsion and axial ((2k − 1) π / 2 of a fixed-free rod)."""
    rho_a = beam.rho * beam.A
    roots = [mp.findroot(lambda x: mp.cos(x) + mp.sech(x), (2 * k - 1) * mp.pi / 2)  # cos λ cosh λ + 1 = 0
             for k in range(1, count + 1)]
    bending = [float(lam**2 * mp.sqrt(EI / (rho_a * LENGTH**4)) / (2 * mp.pi))
               for EI in (beam.E * beam.Iy, beam.E * beam.Iz) for lam in roots]
    rods = [(2 * k - 1) / (4 * LENGTH) * speed for k in range(1, count + 1)
            for speed in (np.sqrt(beam.G * beam.J / (beam.rho * beam.Ip)), np.sqrt(beam.E / beam.rho))]
    return np.sort(np.array(bending + rods))[:count]


def test_a_long_cantilever_is_predicted_beyond_the_dense_limit():
    """The two-element mesh is beyond MAX_UNKNOWNS, yet its lowest eight are predicted,
    within the coarse mesh's error (1e-3) of the closed forms, with their modes."""
    model = cantilever_of_beams(BEAMS, LENGTH)
    assert 6 * (len(model.points) + len(model.beams)) > coarse_prediction.MAX_UNKNOWNS
    predicted = predicted_modes(model, 8)
    reference = 2 * np.pi * cantilever_reference_hz(model.beams[0], 8)
    assert predicted.values.size == 8
    np.testing.assert_allclose(predicted.values, reference, rtol=1e-3)
    assert predicted.nodal.shape == (8, 6 * len(model.points))


def test_a_long_cantilever_is_solved_from_its_predictions():
    """Its eight lowest to 1e-12 of the closed forms, at fewer than 10 evaluations of
    det Ū_all a root (the scan without predictions took 30 and more)."""
    model = cantilever_of_beams(BEAMS, LENGTH)
    got = natural_frequencies(model, 8)
    np.testing.assert_allclose(got.frequencies_hz, cantilever_reference_hz(model.beams[0], 8), rtol=1e-12)
    assert got.evaluations < 10 * 8


def test_a_close_pair_of_distinct_roots_is_searched_from_its_predictions():
    """The 40 lowest hold a bending pair of the two planes 5e-5 apart: distinct roots,
    polished from their predictions (a guard against multiple roots that also took
    this pair for one sent the search back to the scan: 1,798 evaluations)."""
    model = cantilever_of_beams(BEAMS, LENGTH)
    got = natural_frequencies(model, 40)
    np.testing.assert_allclose(got.frequencies_hz, cantilever_reference_hz(model.beams[0], 40), rtol=1e-12)
    assert got.evaluations < 10 * 40


def free_rod(beams: int) -> Model:
    """A steel rod of ``beams`` equal beams along x (Iz = 3e-7, Iy = 2e-7 m⁴), free at both
    ends: six rigid-body modes."""
    points = {f"p{i}": np.array([LENGTH * i / beams, 0.0, 0.0]) for i in range(beams + 1)}
    return Model("free rod", points, beams=tuple(make_beam(f"b{i}", f"p{i}", f"p{i + 1}", points, Iz=3e-7)
                                                for i in range(beams)))


def free_rod_reference_hz(beam, count: int) -> np.ndarray:
    """The ``count`` lowest elastic natural frequencies (Hz) of a free-free uniform beam of
    ``beam``'s section and material and length LENGTH: bending in both planes
    (cos λ cosh λ − 1 = 0), torsion and axial (k π of a free-free rod)."""
    rho_a = beam.rho * beam.A
    roots = [mp.findroot(lambda x: mp.cos(x) - mp.sech(x), (2 * k + 1) * mp.pi / 2)  # cos λ cosh λ − 1 = 0
             for k in range(1, count + 1)]
    bending = [float(lam**2 * mp.sqrt(EI / (rho_a * LENGTH**4)) / (2 * mp.pi))
               for EI in (beam.E * beam.Iy, beam.E * beam.Iz) for lam in roots]
    rods = [k / (2 * LENGTH) * speed for k in range(1, count + 1)
            for speed in (np.sqrt(beam.G * beam.J / (beam.rho * beam.Ip)), np.sqrt(beam.E / beam.rho))]
    return np.sort(np.array(bending + rods))[:count]


def test_a_long_free_rod_is_predicted_about_half_its_lowest_elastic_frequency():
    """Free at both ends, K is singular: a probe about a small shift finds the lowest
    elastic eigenvalue beyond the six rigid-body modes, and the predictions turn about half
    of it; its eight lowest are then polished from them, on the closed forms, at fewer than
    10 evaluations a root (the scan took 396 for the ten lowest)."""
    model = free_rod(BEAMS)
    reference = free_rod_reference_hz(model.beams[0], 8)
    np.testing.assert_allclose(predicted_modes(model, 8).values, 2 * np.pi * reference, rtol=1e-3)
    got = natural_frequencies(model, 8)
    assert got.rigid_body_modes == 6
    np.testing.assert_allclose(got.frequencies_hz, reference, rtol=1e-12)
    assert got.evaluations < 10 * 8


def round_cantilever(beams: int, gap: float = 0.0) -> Model:
    """:func:`cantilever_of_beams` with Iz = Iy (1 + gap)²: each bending root double for
    ``gap`` 0, else a pair ``gap`` apart (relative)."""
    model = cantilever_of_beams(beams, LENGTH)
    return dataclasses.replace(model, beams=tuple(dataclasses.replace(beam, Iz=beam.Iy * (1 + gap) ** 2)
                                                  for beam in model.beams))


def test_double_roots_of_a_long_round_cantilever_are_polished_from_their_predictions():
    """A round section (Iy = Iz): each bending root double. Without a Wittrick–Williams
    counter (a cantilever of 100 beams is too large for one) each pair of coinciding
    predictions is polished as one root, and a count over a small circle about it finds
    its second member: every bending root comes twice, on the closed form, in 174
    evaluations for the ten lowest (the scan took 635; the segment search about each
    pair, 789)."""
    model = round_cantilever(100)
    got = natural_frequencies(model, 10)
    reference = cantilever_reference_hz(model.beams[0], 10)  # both planes alike: each bending root twice
    np.testing.assert_allclose(got.frequencies_hz, reference, rtol=1e-12)
    assert got.evaluations < 300


@pytest.mark.parametrize("gap", [1e-7, 1e-6, 2e-6])
def test_close_pairs_of_a_long_cantilever_are_polished_from_their_predictions(gap):
    """Bending planes 1e-7 to 2e-6 apart: pairs of distinct roots whose predictions lie
    within the reach of a multiple root's. The pencil's offsets at the first member lead
    Newton to the second, so both come out apart, on the closed forms, in 84 evaluations
    for the ten lowest; by the segment search about each pair (the counts over a small
    circle read a pair 1e-6 apart as a double root) they took 300 to 44,000."""
    model = round_cantilever(100, gap)
    got = natural_frequencies(model, 10)
    reference = cantilever_reference_hz(model.beams[0], 10)
    assert np.all(np.diff(reference) > 0.5 * gap * reference[1:])  # every root distinct
    np.testing.assert_allclose(got.frequencies_hz, reference, rtol=1e-12)
    assert got.evaluations < 200


def test_a_double_root_above_the_count_does_not_send_the_search_to_the_scan():
    """The first torsion frequency tuned onto the fourth bending one (y plane): a double
    root above the six lowest, whose predictions coincide. The six lowest are polished from
    their predictions (255 evaluations by the scan when coinciding predictions anywhere
    sent the search there)."""
    model = cantilever_of_beams(BEAMS, LENGTH)
    beam = model.beams[0]
    lam = mp.findroot(lambda x: mp.cos(x) + mp.sech(x), 7 * mp.pi / 2)  # the fourth clamped-free root
    bending = float(lam**2 * mp.sqrt(beam.E * beam.Iy / (beam.rho * beam.A * LENGTH**4)) / (2 * mp.pi))
    J = (4 * LENGTH * bending) ** 2 * beam.rho * beam.Ip / beam.G  # first torsion frequency = bending
    model = dataclasses.replace(model, beams=tuple(dataclasses.replace(b, J=J) for b in model.beams))
    reference = cantilever_reference_hz(model.beams[0], 8)
    assert reference[6] == pytest.approx(reference[7], rel=1e-12)  # the double root, above the six
    got = natural_frequencies(model, 6)
    np.testing.assert_allclose(got.frequencies_hz, reference[:6], rtol=1e-12)
    assert got.evaluations < 10 * 6
