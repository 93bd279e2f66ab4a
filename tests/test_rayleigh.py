"""Predictions refined by the Rayleigh functional of the exact dynamic stiffness
(:mod:`linmstmm.rayleigh`), and the secant's bracket about them.

References, none of them the transfer matrices:

* the closed-form bending frequencies of a cantilever (tests/test_closed_forms.py's
  frequency equation in mpmath), for the refined values themselves;
* the FE route (``fe_frequencies``) for the launchers' refined values;
* the numpy reference of each kernel (:meth:`~linmstmm.wittrick_williams.ModeCounter.forms`,
  :func:`~linmstmm.rayleigh.rayleigh_values_in_numpy` and its inverse step, LU with
  partial pivoting on the dense D(ω));
* a polynomial with known roots for the secant's bracket.
"""
from __future__ import annotations

import numpy as np
import pytest
from builders import fixed, single_beam_model
from test_closed_forms import beam_lambdas, bending_frequencies_hz

from linmstmm import _stiffness_kernels as kernels
from linmstmm import rayleigh
from linmstmm.coarse_prediction import predicted_modes
from linmstmm.fe import fe_frequencies
from linmstmm.model import load_model
from linmstmm.rayleigh import refined_predictions
from linmstmm.roots.settings import predictions_wanted
from linmstmm.secant import secant_roots
from linmstmm.solve import natural_frequencies
from linmstmm.wittrick_williams import ModeCounter

LAUNCHERS = ("models/mlrs/mlrs.toml", "models/launcher2/launcher2.toml")


def launcher_modes(path: str, count: int):
    """(model, its PredictedModes for the ``count`` lowest as a search asks for them)."""
    model = load_model(path)
    return model, predicted_modes(model, predictions_wanted(count))


@pytest.mark.parametrize("path", LAUNCHERS)
def test_compiled_form_sums_the_terms_of_the_numpy_reference(path):
    """xᵀ D(ω) x of random vectors, from below the beams' series range to above their
    first clamped–clamped frequencies, to 1e-13 of the sum of the terms' magnitudes."""
    model = load_model(path)
    counter = ModeCounter(model, "compiled")
    rng = np.random.default_rng(7)
    vectors = rng.standard_normal((6, counter.n_dof))
    omegas = np.geomspace(1e-2, 2e4, 6)
    reference = counter.forms(vectors, omegas)
    plan, terms = counter._plan
    ends, combos = np.empty((counter._maps.shape[0], 12)), np.empty(7)
    for x, omega, expected in zip(vectors, omegas, reference):
        static, mass = kernels._form_parts(x, counter._maps, counter._columns, plan[3], plan[4], terms, ends)
        value = kernels._form(omega, counter._beam_table(), ends, static, mass, combos)
        magnitude = np.abs(x) @ counter.matrices([omega])[1][0] @ np.abs(x)
        assert abs(value - expected) <= 1e-13 * magnitude


@pytest.mark.parametrize("path", LAUNCHERS)
def test_compiled_differences_mirror_the_numpy_reference(path):
    """(D(ω(1 − h)) − D(ω(1 + h))) x of random vectors, to 1e-13 of the terms' sizes."""
    model = load_model(path)
    counter = ModeCounter(model, "compiled")
    rng = np.random.default_rng(8)
    vectors = rng.standard_normal((4, counter.n_dof))
    omegas = np.geomspace(1.0, 2e4, 4)
    reference = counter.differences(vectors, omegas, 1e-6)
    plan, terms = counter._plan
    for x, omega, expected in zip(vectors, omegas, reference):
        out = np.empty(counter.n_dof)
        kernels._difference_applied(omega, 1e-6, x, counter._beam_table(), counter._maps, counter._columns, plan[3],
                                    plan[4], terms, np.empty(7), out)
        sizes = counter.matrices([omega])[1][0] @ np.abs(x)
        assert np.all(np.abs(out - expected) <= 1e-13 * sizes)


@pytest.mark.parametrize("path", LAUNCHERS)
def test_compiled_inverse_step_mirrors_a_dense_solve(path):
    """One inverse step between two roots by the sparse LDLᵀ without pivoting: D(ω) y
    along D′(ω) x to a backward error of 1e-11 of D's terms, and the vector of numpy's
    LU of the dense D(ω) to 1e-8 (its largest entry 1; D(ω) is only as far from singular
    as the roots beside it)."""
    model, modes = launcher_modes(path, 10)
    counter = ModeCounter(model, "compiled")
    omega = float(np.sqrt(modes.values[3] * modes.values[4]))
    x = np.ascontiguousarray(modes.nodal[3, counter.masters])
    side = counter.differences(x[None], [omega], rayleigh.DERIVATIVE_STEP)[0]
    expected = x[None].copy()
    assert rayleigh._inverse_steps(counter, expected, np.array([omega]), np.array([0]))[0]
    plan, terms = counter._plan
    assert kernels._inverse_step(omega, x, rayleigh.DERIVATIVE_STEP, counter._beam_table(), counter._maps,
                                 counter._columns, rayleigh.SOLVE_GROWTH, plan, terms, counter._sparse_scratch(),
                                 np.empty(counter.n_dof), np.empty(counter.n_dof))
    matrix, magnitude = (part[0] for part in counter.matrices([omega]))
    applied = matrix @ x
    residual = applied - (applied @ side) / (side @ side) * side
    assert np.max(np.abs(residual)) <= 1e-11 * np.max(magnitude @ np.abs(x))
    np.testing.assert_allclose(x, expected[0], rtol=0, atol=1e-8)


@pytest.mark.parametrize("path", LAUNCHERS)
@pytest.mark.parametrize("inverse_steps", [rayleigh.INVERSE_STEPS, 0])
def test_compiled_rayleigh_values_mirror_the_numpy_reference(path, inverse_steps):
    model, modes = launcher_modes(path, 20)
    vectors = modes.nodal[:, ModeCounter(model, "numpy").masters]
    compiled = ModeCounter(model, "compiled").rayleigh_values(vectors, modes.values, inverse_steps)
    reference = ModeCounter(model, "numpy").rayleigh_values(vectors, modes.values, inverse_steps)
    assert np.array_equal(np.isnan(compiled), np.isnan(reference))
    assert np.sum(np.isfinite(compiled)) >= 0.9 * compiled.size
    np.testing.assert_allclose(compiled, reference, rtol=1e-12)


def cantilever_frequencies(case: str, length: float, Iz: float, Iy: float, beam) -> np.ndarray:
    """rad/s: the bending frequencies of both planes from ``case``'s frequency equation, ascending."""
    lambdas = beam_lambdas(case)
    return 2 * np.pi * np.sort(np.r_[bending_frequencies_hz(lambdas, beam.E * Iz, beam.rho * beam.A, length),
                                     bending_frequencies_hz(lambdas, beam.E * Iy, beam.rho * beam.A, length)])


@pytest.mark.parametrize("engine", ["numpy", "compiled"])
def test_refined_predictions_of_a_cantilever_meet_the_closed_form(engine):
    """Bending in two planes (Iy = 3.5 Iz), eight lowest: the coarse model's are up to
    1e-4 off, the six lowest refined within 1e-13 of the frequency equation's roots. The
    seventh and eighth lie within 2e-5 of the beam's clamped–clamped frequencies, poles
    of D(ω) whose terms swamp the functional there; whatever their refinement gives,
    the solve polishes them on det Ū_all to the closed form."""
    length, Iz, Iy = 2.0, 2e-7, 7e-7
    model = single_beam_model(fixed(), None, length=length, Iz=Iz, Iy=Iy, axial=False, torsion=False)
    exact = cantilever_frequencies("cantilever", length, Iz, Iy, model.beams[0])[:8]
    modes = predicted_modes(model, 8)
    values, spans = refined_predictions(ModeCounter(model, engine), modes, 8, 1e-9)
    refined = spans > 0
    assert np.max(np.abs(modes.values[:6] / exact[:6] - 1)) > 1e-5
    assert refined[:6].all()
    np.testing.assert_allclose(values[:6], exact[:6], rtol=1e-13)
    result = natural_frequencies(model, 8, engine=engine)
    np.testing.assert_allclose(2 * np.pi * result.frequencies_hz, exact, rtol=1e-12)


@pytest.mark.parametrize("path", LAUNCHERS)
def test_refined_launcher_predictions_agree_with_the_fe_route(path):
    """The twenty lowest, refined where alone, against the FE route's refinement: within
    three times its own error estimate (or 1e-10), where the coarse predictions are up
    to 5e-4 off."""
    model, modes = launcher_modes(path, 20)
    values, spans = refined_predictions(ModeCounter(model, "compiled"), modes, 20, 1e-9)
    refined = spans > 0
    fe = fe_frequencies(model, count=20)
    reference = 2 * np.pi * fe.frequencies_hz
    assert refined[:20].sum() >= 18
    error = np.abs(values[:20] / reference - 1)[refined[:20]]
    assert np.all(error <= np.maximum(1e-10, 3 * fe.error_estimate[refined[:20]]))


@pytest.mark.parametrize("path", LAUNCHERS)
def test_from_a_loose_rtol_the_rayleigh_values_are_taken_without_inverse_steps(path):
    """From rayleigh.UNSTEPPED_FROM up the coarse modes' own Rayleigh values stand for
    the predictions, with no bracket: closer to the FE route's refinement than the
    coarse values (up to 5e-4 and 2e-6 off), within 1e-5 of it, and each a root of the
    functional of its coarse mode (the numpy reference's, independently formed)."""
    model, modes = launcher_modes(path, 20)
    counter = ModeCounter(model, "compiled")
    values, spans = refined_predictions(counter, modes, 20, rayleigh.UNSTEPPED_FROM)
    assert not spans.any()
    reference = 2 * np.pi * fe_frequencies(model, count=20).frequencies_hz
    changed = values[:20] != modes.values[:20]
    assert changed.sum() >= 18
    coarse_error = np.abs(modes.values[:20] / reference - 1)
    error = np.abs(values[:20] / reference - 1)
    assert np.all(error[changed] <= 1e-5) and np.max(error[changed]) < 0.1 * np.max(coarse_error[changed])
    vectors = modes.nodal[:20][changed][:, counter.masters]
    forms = ModeCounter(model, "numpy").forms(vectors, values[:20][changed])
    magnitude = np.abs(ModeCounter(model, "numpy").forms(vectors, modes.values[:20][changed] * (1 + 1e-3)))
    assert np.all(np.abs(forms) <= 1e-9 * magnitude)


@pytest.mark.parametrize("path, count", [(LAUNCHERS[0], 60), (LAUNCHERS[0], 100), (LAUNCHERS[1], 100)])
def test_beyond_bisection_the_modes_come_and_refine_to_the_roots(path, count):
    """Beyond coarse_prediction.BISECTED wanted, the modes at the nodes come all the same:
    by divide and conquer on a dense pencil (the launcher's 60 lowest) or as the sparse
    route's Ritz vectors (the launchers' 100 lowest). Their Rayleigh values, refined
    where alone, stand within 1e-9 (median 1e-12) of the roots the search certifies on
    det Ū_all, a formulation of their own, where the coarse values are up to 1e-5 to
    7e-3 off (each value against the nearest of the 15 more roots than wanted)."""
    model, modes = launcher_modes(path, count)
    assert modes.nodal is not None
    values, spans = refined_predictions(ModeCounter(model, "compiled"), modes, count, 1e-9)
    refined = spans > 0
    assert refined[:count].sum() >= 0.8 * count
    roots = 2 * np.pi * natural_frequencies(model, count + 15, engine="compiled").frequencies_hz
    error = np.min(np.abs(values[refined][:, None] / roots[None, :] - 1), axis=1)
    coarse = np.min(np.abs(modes.values[refined][:, None] / roots[None, :] - 1), axis=1)
    assert error.max() <= 1e-9 and np.median(error) <= 1e-12 and coarse.max() > 1e-5


def test_no_refinement_without_modes_at_the_nodes_or_a_counter():
    model, modes = launcher_modes(LAUNCHERS[0], 10)
    for counter, given in ((None, modes), (ModeCounter(model, "compiled"), type(modes)(modes.values, None))):
        values, spans = refined_predictions(counter, given, 10, 1e-9)
        assert not spans.any() and np.array_equal(values, modes.values)


@pytest.mark.parametrize("engine", ["numpy", "compiled"])
def test_a_beam_held_at_both_ends_has_nothing_to_refine_and_meets_the_closed_form(engine):
    """Clamped at both ends, the one beam leaves D(ω) no unknown (the counter's J₀ counts
    every root): its predictions stay as they are, with no bracket (the numpy engine
    failed on the empty vectors), and the solve meets the frequency equation."""
    length, Iz, Iy = 2.0, 2e-7, 7e-7
    model = single_beam_model(fixed(), fixed(), length=length, Iz=Iz, Iy=Iy, axial=False, torsion=False)
    counter = ModeCounter(model, engine)
    assert counter.n_dof == 0
    modes = predicted_modes(model, 8)
    values, spans = refined_predictions(counter, modes, 8, 1e-9)
    assert not spans.any() and np.array_equal(values, modes.values)
    exact = cantilever_frequencies("clamped-clamped", length, Iz, Iy, model.beams[0])[:8]
    result = natural_frequencies(model, 8, engine=engine)
    np.testing.assert_allclose(2 * np.pi * result.frequencies_hz, exact, rtol=1e-12)


def test_brackets_only_where_rtol_is_ten_times_theirs_and_only_about_those_polished():
    """A refined prediction gets rayleigh.BRACKET at the default rtol, none at 1e-10 (a
    refined value only starts the secant there); those more than NEAR_COUNT above the
    count-th are not refined (they only place the certifying count)."""
    model, modes = launcher_modes(LAUNCHERS[0], 10)
    counter = ModeCounter(model, "compiled")
    values, spans = refined_predictions(counter, modes, 10, 1e-9)
    assert np.all((spans == rayleigh.BRACKET) | (spans == 0)) and spans[:10].all()
    assert not spans[values > values[9] * (1 + 2e-2)].any()
    tight_values, tight = refined_predictions(counter, modes, 10, 1e-10)
    assert not tight.any() and np.array_equal(tight_values, values)


def polynomial(roots, evaluations):
    """log_det of Π (ω − r) over ``roots``, counting its evaluations into ``evaluations``."""
    def log_det(omega):
        omega = np.asarray(omega, dtype=float)
        evaluations.append(omega.size)
        value = np.prod(omega[:, None] - np.asarray(roots)[None, :], axis=1)
        with np.errstate(divide="ignore"):  # a point on a root: log 0, sign 0
            return np.sign(value), np.log(np.abs(value))
    return log_det


def test_a_bracket_whose_ends_change_sign_ends_the_secant_at_its_first_step():
    """Starts 3e-11 and 3e-9 above simple roots, brackets of ±1e-10: the first is taken
    from the bracket (two evaluations, its last step the bracket's width), to 1e-15;
    the second has no sign change there and goes on to xtol."""
    roots, evaluations = np.array([10.0, 17.0, 23.0]), []
    starts = np.array([10.0 * (1 + 3e-11), 17.0 * (1 + 3e-9)])
    found, steps = secant_roots(polynomial(roots, evaluations), starts, 1e-14, 1e-7, np.array([1e-10, 1e-10]))
    np.testing.assert_allclose(found, roots[:2], rtol=1e-15)
    assert steps[0] == pytest.approx(2e-10, rel=1e-6) and steps[1] <= 1e-14
    assert evaluations[0] == 4 and sum(evaluations) > 4  # both brackets in one batch, then the second alone


def test_without_spans_the_secant_starts_as_before():
    """No spans: the start and a point FIRST_STEP beside it, the same roots and steps as spans of 0."""
    roots, first, second = np.array([10.0, 17.0]), [], []
    starts = np.array([10.001, 16.99])
    found, steps = secant_roots(polynomial(roots, first), starts, 1e-14, 1e-7)
    again, steps_again = secant_roots(polynomial(roots, second), starts, 1e-14, 1e-7, np.zeros(2))
    assert np.array_equal(found, again) and np.array_equal(steps, steps_again) and first == second


def noisy(root: float, band: float):
    """log_det of (ω − root) plus rounding noise of relative size ``band`` (a fixed
    pseudo-random sign per ω): within about ``band`` of the root det's sign is noise."""
    def log_det(omega):
        omega = np.asarray(omega, dtype=float)
        noise = band * root * np.sin(omega.view(np.int64) * 0.7548776662466927)
        value = omega - root + noise
        return np.sign(value), np.log(np.abs(value))
    return log_det


def flipped(root: float, flip: float, band: float):
    """log_det of (ω − root) outside ``band`` (relative) of the root; inside, det at its
    rounding floor (1e-12 within a factor of 3, at random), its sign flipping at
    root (1 + ``flip``) instead of at the root."""
    def log_det(omega):
        omega = np.asarray(omega, dtype=float)
        floor = 1e-12 * (1 + 0.5 * np.sin(omega.view(np.int64) * 0.7548776662466927))
        value = np.where(np.abs(omega / root - 1) > band, omega - root,
                         np.where(omega > root * (1 + flip), floor, -floor))
        return np.sign(value), np.log(np.abs(value))
    return log_det


@pytest.mark.parametrize("det", ["noise", "a flip beside the root"])
def test_a_secant_on_dets_rounding_noise_keeps_the_start(det):
    """Within 5e-9 of the root det is at its rounding floor, so the bracket of ±1e-10
    about a start on the root (a Rayleigh value, exact) shows no sign change and the
    secant settles in the noise (on a random sign; or 1.5e-9 off, the floor flipping
    sign 1.5e-10 below the root). The start is kept, with an uncertainty no smaller
    than the bracket's. (A start 3e-9 off a clean det's root keeps the secant's root:
    the test above.)"""
    root = 4900.778745994314
    log_det = noisy(root, 1e-9) if det == "noise" else flipped(root, -1.5e-10, 5e-9)
    found, steps = secant_roots(log_det, np.array([root]), 1e-14, 1e-7, np.array([1e-10]))
    assert found[0] == root
    assert steps[0] >= 1e-10  # what det confirms, no better


@pytest.mark.parametrize("path", LAUNCHERS)
def test_launchers_ten_lowest_take_two_evaluations_a_root_and_agree_with_the_fe_route(path):
    model = load_model(path)
    result, fe = natural_frequencies(model, 10, engine="compiled"), fe_frequencies(model, count=10)
    assert result.evaluations <= 2 * 10
    np.testing.assert_allclose(result.frequencies_hz, fe.frequencies_hz,
                               rtol=max(1e-9, 3 * float(np.nanmax(fe.error_estimate))))
