"""Predict, polish, certify: the root search that starts from a coarse FE model.

The predictions only say where to look; completeness is the closing count's.
Checked here: the search is certified with few evaluations per root on the
launcher and agrees with the FE route; a prediction list with a root left
out, or with one root twice, is caught by the count and repaired.
"""
from __future__ import annotations

import numpy as np
import pytest

from linmstmm.fe import fe_frequencies
from linmstmm.model import load_model
from linmstmm.coarse_prediction import coarse_predictions, predict_frequencies
from linmstmm.predicted import predicted_roots
from linmstmm.solve import frequency_finder

LAUNCHER = "models/mlrs/mlrs.toml"


@pytest.fixture(scope="module")
def launcher():
    return load_model(LAUNCHER)


def test_launcher_first_20_in_few_evaluations_agree_with_fe(launcher):
    _, finder, _ = frequency_finder(launcher)
    roots = predicted_roots(finder, predict_frequencies(launcher, 21), 20)[:20]
    assert roots is not None
    assert finder.determinant.evaluations / 20 <= 10
    fe = fe_frequencies(launcher, 20)
    np.testing.assert_allclose(np.array(roots) / (2 * np.pi), fe.frequencies_hz,
                               rtol=max(1e-9, 3 * np.nanmax(fe.error_estimate)))


@pytest.mark.parametrize("change", ["leave one out", "one twice"])
def test_wrong_predictions_are_caught_by_the_count_and_repaired(launcher, change):
    """A root the predictions miss, or one predicted twice, leaves the closing count
    non-zero; counts halve the range to where, and the segment search fills it in."""
    _, finder, _ = frequency_finder(launcher)
    predictions = predict_frequencies(launcher, 12)
    if change == "leave one out":
        predictions = np.delete(predictions, 4)
    else:
        predictions = np.sort(np.r_[predictions, predictions[4] * (1 + 1e-6)])
    roots = predicted_roots(finder, predictions, 10)[:10]
    fe = fe_frequencies(launcher, 10)
    np.testing.assert_allclose(np.array(roots) / (2 * np.pi), fe.frequencies_hz,
                               rtol=max(1e-9, 3 * np.nanmax(fe.error_estimate)))


def test_too_few_predictions_are_refused(launcher):
    _, finder, _ = frequency_finder(launcher)
    assert predicted_roots(finder, predict_frequencies(launcher, 5), 10) is None


def free_strip(Iz: float):
    from builders import single_beam_model

    return single_beam_model(None, None, length=9.9, A=0.088, Iy=8.9e-4, Iz=Iz, J=1e-9,
                             material=dict(E=3.9e9, G=1.5e9, rho=1200.0))


def test_free_strip_with_a_soft_plane_agrees_with_fe():
    """Iy/Iz = 6e5: refused as a mechanism before (fixed probe frequencies)."""
    from linmstmm.solve import natural_frequencies

    model = free_strip(1.4e-9)
    result, fe = natural_frequencies(model, count=4), fe_frequencies(model, count=4)
    assert result.rigid_body_modes == fe.rigid_body_modes == 6
    np.testing.assert_allclose(result.frequencies_hz, fe.frequencies_hz, rtol=1e-6)


@pytest.mark.parametrize("Iz", [1e-12, 1e-14, 1e-18, 1e-22])
def test_modes_far_below_the_other_plane_agree_with_fe(Iz):
    """Iz = 1e-12 down to 1e-22 m⁴ put the first bending mode at 2.2e-4 down to 2.2e-9 Hz.
    Below an absolute floor of 1e-3 rad/s the search returned a double root at 6.1e-4 Hz,
    or five wrong values, then refused; the floor now follows the model's own scale, and
    a coarse prediction below it (0 Hz: rounding of the stiff plane) is not used."""
    from linmstmm.solve import natural_frequencies

    result, fe = natural_frequencies(free_strip(Iz), count=4), fe_frequencies(free_strip(Iz), count=4)
    assert result.rigid_body_modes == fe.rigid_body_modes == 6
    np.testing.assert_allclose(result.frequencies_hz, fe.frequencies_hz,
                               rtol=max(1e-9, 3 * float(fe.error_estimate.max())))


def test_launcher_first_100_with_close_pairs_agree_with_fe(launcher):
    """The launcher's pairs 1e-4 apart near 11.2 and 15.9 krad/s: the secant on det with
    the known roots divided out finds each second member, where the segment search
    around them took 2,000-3,000 evaluations a pair (8,206 for the 100)."""
    _, finder, _ = frequency_finder(launcher)
    roots = predicted_roots(finder, predict_frequencies(launcher, 112), 100)[:100]
    assert finder.determinant.evaluations / 100 <= 12
    coarse, fine = (coarse_predictions(launcher, 100, n) for n in (16, 32))  # FE, dense, two meshes
    # each root within three times its own mesh change of the finer FE frequency, or 1e-6
    # (the fixed meshes' own rounding: mode 28 reads 196.519644, 196.519640 and 196.519692
    # rad/s on 16, 32 and 64 elements per beam), far inside the pairs' gaps of 1e-4
    error = np.abs(np.array(roots) / fine - 1)
    assert np.all(error <= np.maximum(1e-6, 3 * np.abs(fine / coarse - 1)))


def test_double_roots_of_a_symmetric_cantilever_come_whole():
    """Equal bending in y and z: every bending root is double. The secant on det with one
    member divided out must not report a second member a little off (it found
    42.4339063 beside 42.4339020 rad/s); each pair comes back as one root twice."""
    model = load_model("models/cantilever_tip_mass.toml")
    for engine in ("numpy", "compiled"):
        _, finder, _ = frequency_finder(model, engine=engine)
        roots = np.array(predicted_roots(finder, predict_frequencies(model, 12), 10)[:10])
        gaps = np.diff(roots) / roots[1:]
        assert np.all((gaps <= 1e-12) | (gaps > 1e-3)), (engine, roots)
        assert np.sum(gaps <= 1e-12) >= 3


def test_a_large_predicting_mesh_is_solved_sparse_and_agrees_with_the_fe_route(monkeypatch):
    """The second launcher on 16 elements per beam (636 unknowns, all with mass): block shift-invert
    Lanczos about minus half the lowest eigenvalue gives the same lowest 60 as the dense
    route to 1e-3, and both lie within the mesh's own error (1e-2) of the FE route's
    converged frequencies."""
    from linmstmm import coarse_prediction

    model = load_model("models/launcher2/launcher2.toml")
    dense = coarse_predictions(model, 60, 16)
    calls, lanczos = [], coarse_prediction.lowest_eigenvalues
    monkeypatch.setattr(coarse_prediction, "lowest_eigenvalues", lambda *a: calls.append(1) or lanczos(*a))
    sparse = coarse_predictions(model, 60, 16, shift=0.5 * dense[0] ** 2)
    assert calls  # the sparse route ran
    reference = 2 * np.pi * fe_frequencies(model, count=60).frequencies_hz
    np.testing.assert_allclose(sparse, dense, rtol=1e-3)
    np.testing.assert_allclose(sparse, reference, rtol=1e-2)


def test_at_a_loose_rtol_a_prediction_stands_only_where_counts_hold_a_root_within_rtol(launcher):
    """Each of the FE route's roots moved up by half rtol stands as it is; moved by
    three rtol, it does not (the secant polishes it instead)."""
    from linmstmm.predicted import _counted_predictions, clustered

    rtol = 1e-4
    _, finder, _ = frequency_finder(launcher, rtol=rtol, xtol=1e-6, unpolished=True)
    exact = 2 * np.pi * fe_frequencies(launcher, 8).frequencies_hz
    moved = exact * np.where(np.arange(8) % 2 == 0, 1 + 0.5 * rtol, 1 + 3 * rtol)
    standing, rest = _counted_predictions(finder, moved, clustered(moved), 0, 8)
    assert standing == list(moved[::2]) and list(rest) == [1, 3, 5, 7]
    assert all(finder.last_step[omega] == rtol for omega in standing)


def test_at_the_default_rtol_no_prediction_stands_unpolished(launcher):
    """The default polishes every root to rounding: not even the FE route's roots stand,
    where the same finder told it may list them unpolished takes them."""
    from linmstmm.predicted import _counted_predictions, clustered

    exact = 2 * np.pi * fe_frequencies(launcher, 4, rtol=1e-11).frequencies_hz
    for unpolished, standing_expected in ((False, []), (True, list(exact))):
        _, finder, _ = frequency_finder(launcher, unpolished=unpolished)
        standing, rest = _counted_predictions(finder, exact, clustered(exact), 0, 4)
        assert standing == standing_expected and list(rest) == ([] if unpolished else [0, 1, 2, 3])


def test_rtol_1e9_asked_for_certifies_the_launchers_lowest_without_evaluating_det(launcher):
    """Asked for rtol 1e-9, the Rayleigh-refined predictions of the ten lowest stand:
    within 1e-9 of the FE route's roots, and of the default's, which polishes them
    with 20 evaluations of det."""
    from linmstmm.solve import natural_frequencies

    asked = natural_frequencies(launcher, 10, rtol=1e-9, engine="compiled")
    polished = natural_frequencies(launcher, 10, engine="compiled")
    fe = fe_frequencies(launcher, 10, rtol=1e-11)
    assert asked.evaluations == 0 < polished.evaluations
    for found in (asked, polished):
        np.testing.assert_allclose(found.frequencies_hz, fe.frequencies_hz,
                                   rtol=max(1e-9, 3 * float(fe.error_estimate.max())), atol=0)
    np.testing.assert_allclose(asked.frequencies_hz, polished.frequencies_hz, rtol=1e-9, atol=0)


def test_the_launcher_at_rtol_1e4_is_certified_from_its_predictions_without_evaluating_det(launcher):
    """Its coarse predictions of the ten lowest lie within about 2e-6 of the roots, so
    counts alone certify them to 1e-4; the FE route confirms they are within it."""
    from linmstmm.solve import natural_frequencies

    result = natural_frequencies(launcher, 10, rtol=1e-4)
    fe = fe_frequencies(launcher, 10)
    assert result.evaluations == 0
    assert np.max(np.abs(result.frequencies_hz / fe.frequencies_hz - 1)) <= 1e-4


def test_the_pencil_looks_for_no_partner_root_beyond_its_reach(monkeypatch):
    """A varied model whose pencil, at a root, had a real offset of 3e16 rad/s: the
    partner root it pointed at was polished from −3e16 rad/s, where the compiled
    kernels cut the beams into some 1e8 pieces (76 s). Only frequencies near the
    roots are evaluated now (one beyond three times the highest stops the search
    here at once), and the roots agree with the FE route."""
    import sys

    from linmstmm.determinant import CompiledDeterminant
    from linmstmm.solve import natural_frequencies

    sys.path.insert(0, "tests")
    from varied_models import varied_model

    model, _ = varied_model(90)
    fe = fe_frequencies(model, 10)
    reach = 3 * 2 * np.pi * fe.frequencies_hz[-1]
    matrix = CompiledDeterminant.matrix

    def near_the_roots_only(self, omega):
        omega = np.atleast_1d(omega)
        assert np.all((omega > 0) & (omega < reach)), f"Ū_all asked for at {omega[:2]} rad/s"
        return matrix(self, omega)

    monkeypatch.setattr(CompiledDeterminant, "matrix", near_the_roots_only)
    result = natural_frequencies(model, 10, engine="compiled")
    np.testing.assert_allclose(result.frequencies_hz, fe.frequencies_hz,
                               rtol=max(1e-9, 3 * np.nanmax(fe.error_estimate)))


def test_a_root_equal_to_its_prediction_is_not_taken_for_one_that_stood(monkeypatch):
    """At the default rtol no prediction stands unpolished, so the roots are certified in
    one pass. A steel cantilever whose bending planes are 1e-7 apart (Iz = Iy (1 + 1e-7)²),
    its 60 lowest: secant roots from brackets about refined predictions came out equal to
    those predictions to the bit, were taken for predictions that had stood, and the whole
    polish was made again (9,088 evaluations for 4,544). The lowest bending roots of both
    planes (test_rayleigh's frequency equation) are checked among them."""
    from linmstmm import predicted
    from linmstmm.solve import natural_frequencies

    model = _rod_with_close_planes(1e-7)
    passes, certified = [], predicted._certified
    monkeypatch.setattr(predicted, "_certified", lambda *args, **kw: passes.append(1) or certified(*args, **kw))
    result = natural_frequencies(model, 60, engine="compiled")
    assert len(passes) == 1
    assert _worst_bending_error(model, result) <= 1e-12


def test_where_counts_alone_cannot_certify_only_the_predictions_that_stood_are_polished(monkeypatch):
    """The same cantilever's 30 lowest at rtol 1e-9 asked for: six lone predictions stand,
    and a Wittrick–Williams count by a pair cannot decide, so det's zeros are needed.
    Only the six are polished before the argument principle's count; polishing every
    prediction again, the pairs' on the pencil too, took 6,310 evaluations where this
    takes 3,159. The bending roots of both planes hold to rtol against their closed form."""
    from linmstmm import predicted
    from linmstmm.solve import natural_frequencies

    model = _rod_with_close_planes(1e-7)
    passes, certified = [], predicted._certified
    polished, stood_polished = [], predicted._stood_polished
    monkeypatch.setattr(predicted, "_certified", lambda *args, **kw: passes.append(1) or certified(*args, **kw))
    monkeypatch.setattr(predicted, "_stood_polished",
                        lambda *args, **kw: polished.append(args[4]) or stood_polished(*args, **kw))
    result = natural_frequencies(model, 30, engine="compiled", rtol=1e-9)
    assert len(passes) == 1 and len(polished) == 1 and len(polished[0]) > 0
    assert _worst_bending_error(model, result) <= 1e-9


def _rod_with_close_planes(gap: float):
    """A 1.5 m steel cantilever whose bending planes are ``gap`` apart: Iz = Iy (1 + gap)²
    (test_rtol's rods)."""
    from builders import fixed, single_beam_model

    iy = 3e-7
    return single_beam_model(fixed(), None, length=1.5, A=1e-3, Iy=iy, Iz=iy * (1 + gap) ** 2, J=2e-7,
                             Ip=4.2e-7, material=dict(E=2e11, G=8e10, rho=7800.0))


def _worst_bending_error(model, result) -> float:
    """The largest relative distance from a bending root of ``model``'s beam in range (its
    frequency equation, test_rayleigh's) to the nearest of ``result``'s frequencies;
    every such root must be in range."""
    from test_rayleigh import cantilever_frequencies

    beam = model.beams[0]
    omegas = 2 * np.pi * result.frequencies_hz
    bending = cantilever_frequencies("cantilever", beam.length, beam.Iz, beam.Iy, beam)
    found = [np.min(np.abs(omegas / exact - 1)) for exact in bending[bending <= omegas[-1]]]
    assert len(found) == bending.size
    return max(found)


def test_a_repaired_stretch_is_halved_in_a_wide_gap_not_beside_a_close_pair():
    """At the default rtol: the count 5e-8 from each member of a pair 1e-7 apart cannot
    decide, and halving there handed the stretch to the argument principle (a rod's 30
    lowest with bending planes 1e-7 apart: 1,247 evaluations of det; halved in its
    widest middle gap, 803). At a looser rtol the median split stays (see
    test_close_roots: pairs closer than rtol kept whole in a stretch came back as
    double roots)."""
    from linmstmm.prediction_groups import repair_split

    pair = [3.0, 3.0 * (1 + 1e-7)]
    inside = [1.0, 2.0, *pair, 5.0, 6.0]
    assert repair_split(inside, True) == pytest.approx(np.sqrt(2.0))
    assert repair_split([1.0, 2.0, 5.0], True) == pytest.approx(np.sqrt(10.0))  # the wider of two gaps
    # at a looser rtol the median gap, inside the pair: the searches of the halves part it
    assert repair_split(inside, False) == pytest.approx(np.sqrt(pair[0] * pair[1]))
