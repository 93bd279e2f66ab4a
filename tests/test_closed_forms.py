"""Chains against closed forms (independent of the transfer matrices).

Beam eigenvalues λ = βL are roots of the classical frequency equations
(e.g. Blevins, *Formulas for Natural Frequency and Mode Shape*, table 8-1),
solved here with mpmath to 30 digits; ω = λ² √(EI/(ρA L⁴)).
"""
from __future__ import annotations

import mpmath as mp
import numpy as np
import pytest
from builders import fixed, make_rigid, single_beam_model, spring_mass_chain

from linmstmm.counting import EVALUATION_CHUNK, count_zeros, count_zeros_many, deflated
from linmstmm.model import Model
from linmstmm.precision import arb_determinant
from linmstmm.roots import CIRCLE_MAX_POINTS, CIRCLE_POINTS, RootFinder
from linmstmm.solve import frequency_finder, natural_frequencies

mp.mp.dps = 30
FREQUENCY_EQUATIONS = {
    "cantilever": lambda x: mp.cos(x) * mp.cosh(x) + 1,
    "free-free": lambda x: mp.cos(x) * mp.cosh(x) - 1,
    "clamped-clamped": lambda x: mp.cos(x) * mp.cosh(x) - 1,
    "pinned-pinned": lambda x: mp.sin(x),
    "clamped-pinned": lambda x: mp.tan(x) - mp.tanh(x),
}
# Published starting values (Blevins table 8-1), refined by mpmath.
STARTS = {
    "cantilever": [1.8751, 4.6941, 7.8548, 10.9955, 14.1372],
    "free-free": [4.7300, 7.8532, 10.9956, 14.1372, 17.2788],
    "clamped-clamped": [4.7300, 7.8532, 10.9956, 14.1372, 17.2788],
    "pinned-pinned": [np.pi * n for n in range(1, 6)],
    "clamped-pinned": [3.9266, 7.0686, 10.2102, 13.3518, 16.4934],
}
ENDS = {
    "cantilever": (fixed(), None),
    "free-free": (None, None),
    "clamped-clamped": (fixed(), fixed()),
    "pinned-pinned": (fixed("x", "y", "z", "rx"), fixed("y", "z")),
    "clamped-pinned": (fixed(), fixed("y", "z")),
}


def beam_lambdas(case):
    return np.array([float(mp.findroot(FREQUENCY_EQUATIONS[case], x0)) for x0 in STARTS[case]])


def bending_frequencies_hz(lambdas, EI, rhoA, L):
    return lambdas**2 * np.sqrt(EI / (rhoA * L**4)) / (2 * np.pi)


@pytest.mark.parametrize("case", sorted(FREQUENCY_EQUATIONS))
def test_beam_bending_in_one_plane(case):
    """Iz ≠ Iy separates the two planes; axial/torsion pushed out of the band."""
    L, Iz, Iy = 2.0, 2e-7, 7e-7
    model = single_beam_model(*ENDS[case], length=L, Iz=Iz, Iy=Iy, axial=False, torsion=False)
    beam = model.beams[0]
    lambdas = beam_lambdas(case)
    want_z = bending_frequencies_hz(lambdas, beam.E * Iz, beam.rho * beam.A, L)
    want_y = bending_frequencies_hz(lambdas, beam.E * Iy, beam.rho * beam.A, L)
    want = np.sort(np.r_[want_z, want_y])
    want = want[want <= want_z[-1]]
    got = natural_frequencies(model, fmax=want_z[-1] * (1 + 1e-6), count=None)
    np.testing.assert_allclose(got.frequencies_hz, want, rtol=1e-9)
    assert got.rigid_body_modes == (6 if case == "free-free" else 0)


def test_round_tube_cantilever_gives_double_roots():
    model = single_beam_model(fixed(), None, Iz=3e-7, Iy=3e-7, axial=False, torsion=False)
    beam = model.beams[0]
    want = bending_frequencies_hz(beam_lambdas("cantilever"), beam.E * 3e-7, beam.rho * beam.A, 2.0)
    got = natural_frequencies(model, count=10)
    np.testing.assert_allclose(got.frequencies_hz, np.repeat(want, 2), rtol=1e-9)


def test_axial_rod_and_torsional_shaft_fixed_free():
    """ω_n = (2n−1)π/(2L) √(E/ρ) and (2n−1)π/(2L) √(GJ/(ρ Ip)) (e.g. Blevins table 8-16)."""
    L = 3.0
    model = single_beam_model(fixed(), None, length=L, Iz=1.0, Iy=1.0, J=2e-7, Ip=4e-7)
    beam = model.beams[0]
    n = np.arange(1, 4)
    axial = (2 * n - 1) * np.pi / (2 * L) * np.sqrt(beam.E / beam.rho) / (2 * np.pi)
    torsion = (2 * n - 1) * np.pi / (2 * L) * np.sqrt(beam.G * beam.J / (beam.rho * beam.Ip)) / (2 * np.pi)
    fmax = 0.999 * min(axial[-1], torsion[-1])
    # Iy = Iz = 1 m^4 pushes bending far above fmax.
    want = np.sort(np.r_[axial, torsion])
    got = natural_frequencies(model, fmax=fmax, count=None)
    np.testing.assert_allclose(got.frequencies_hz, want[want <= fmax], rtol=1e-10)


def test_a_root_hidden_from_the_newton_pencil_is_taken_from_its_bracket():
    """Iy = Iz = 1 m^4: the torsion column's moments are 1e-4 of the bending
    ones, the QR of the carried state puts the 2nd torsion root (3·189.3 Hz)
    into R, and Newton from its sign change jumps to another root. Regula
    falsi on det itself finds it; the fast path needs no fallback."""
    L = 3.0
    model = single_beam_model(fixed(), None, length=L, Iz=1.0, Iy=1.0, J=2e-7, Ip=4e-7)
    beam = model.beams[0]
    torsion = np.pi / (2 * L) * np.sqrt(beam.G * beam.J / (beam.rho * beam.Ip))  # rad/s
    axial = np.pi / (2 * L) * np.sqrt(beam.E / beam.rho)
    _, finder, _ = frequency_finder(model)
    fast = finder._scan_ahead(None, 3.5 * torsion)
    assert fast is not None
    np.testing.assert_allclose(fast, [torsion, axial, 3 * torsion], rtol=1e-12)


def test_cantilever_with_tip_mass_ratio_one():
    """Tip mass = beam mass: λ² = 1.557298, 16.25009, 50.89584 (Blevins table 8-8, and the
    frequency equation 1 + cos λ cosh λ + λ (cos λ sinh λ − sin λ cosh λ) = 0)."""
    L = 2.0
    base = single_beam_model(fixed(), None, length=L, Iy=1e-2, axial=False, torsion=False)
    beam = base.beams[0]
    tip = make_rigid("payload", ["b"], beam.rho * beam.A * L, [L, 0.0, 0.0])
    model = Model("tip mass", base.points, rigids=(tip,), beams=base.beams, boundary=base.boundary)
    equation = lambda x: 1 + mp.cos(x) * mp.cosh(x) + x * (mp.cos(x) * mp.sinh(x) - mp.sin(x) * mp.cosh(x))
    lambdas = np.array([float(mp.findroot(equation, mp.sqrt(x))) for x in (1.557298, 16.25009, 50.89584)])
    np.testing.assert_allclose(lambdas**2, [1.557298, 16.25009, 50.89584], rtol=1e-6)
    scale = np.sqrt(beam.E * beam.Iz / (beam.rho * beam.A * L**4)) / (2 * np.pi)
    got = natural_frequencies(model, fmax=lambdas[-1] ** 2 * scale * 1.0001, count=None)
    np.testing.assert_allclose(got.frequencies_hz[:3], lambdas**2 * scale, rtol=1e-9)


def test_count_and_fmax_stop_at_the_count_when_it_comes_first():
    """The lowest 3 with fmax far above them: the search stops at the count, as it does
    without fmax (it searched every root up to fmax before: the MLRS's 10 with fmax
    100 Hz took 0.68 s where 10 alone take 0.04 s). Counted in evaluations of Ū_all."""
    model = single_beam_model(fixed(), None, length=2.0, Iy=1e-2, axial=False, torsion=False)
    evaluated = {}
    for fmax in (None, 3e4):
        _, finder, _ = frequency_finder(model)
        matrix, evaluated[fmax] = finder.matrix, []
        finder.matrix = lambda omega, matrix=matrix, seen=evaluated[fmax]: seen.append(len(omega)) or matrix(omega)
        log_det = finder.log_det
        finder.log_det = lambda omega, log_det=log_det, seen=evaluated[fmax]: seen.append(len(omega)) or log_det(omega)
        roots = finder.find(3, None if fmax is None else 2 * np.pi * fmax).roots.tolist()
        evaluated[fmax] = (roots, sum(evaluated[fmax]))
    assert evaluated[3e4][0] == evaluated[None][0]
    assert evaluated[3e4][1] <= 1.2 * evaluated[None][1]


@pytest.mark.parametrize("root", ["g0", "g3"])
def test_spring_mass_chain_exact(root):
    k, m = 1000.0, 2.0
    got = natural_frequencies(spring_mass_chain(k, m), count=6, root=root)
    omega2 = np.array([(4 - np.sqrt(7)) / 3, (4 + np.sqrt(7)) / 3]) * k / m
    np.testing.assert_allclose(got.frequencies_hz, np.repeat(np.sqrt(omega2) / (2 * np.pi), 3), rtol=1e-12)
    assert got.ubar_order == 12


def test_fast_path_takes_triple_roots_at_their_multiplicity():
    """Each frequency of the chain is triple: one sign change each, so the scan never
    sees 6 candidates; once a scan chunk adds none, the two are polished and their
    multiplicities make up the count (it used to fall back to the segment search)."""
    k, m = 1000.0, 2.0
    _, finder, _ = frequency_finder(spring_mass_chain(k, m))
    fast = finder._scan_ahead(6, None)
    exact = np.repeat(np.sqrt(np.array([(4 - np.sqrt(7)) / 3, (4 + np.sqrt(7)) / 3]) * k / m), 3)
    assert fast is not None
    np.testing.assert_allclose(fast, exact, rtol=1e-12)


def test_a_count_that_ends_inside_a_triple_root_raises_no_cluster_note():
    """``count=5`` ends inside the chain's second triple root: the two copies returned
    are a true triple, not a cluster float64 could not separate (the 10,000-body
    chain's note said so, after a 0.4 s search for a member that does not exist)."""
    k, m = 1000.0, 2.0
    result = natural_frequencies(spring_mass_chain(k, m), count=5)
    exact = np.repeat(np.sqrt(np.array([(4 - np.sqrt(7)) / 3, (4 + np.sqrt(7)) / 3]) * k / m), 3)[:5]
    np.testing.assert_allclose(2 * np.pi * result.frequencies_hz, exact, rtol=1e-12)
    assert result.note == ""


def test_count_with_known_roots_divided_out_sees_a_missing_or_a_false_one():
    """The fast path's closing count (det with the found roots divided out) against
    the closed form ω² = (4 ∓ √7)/3 · k/m (each triple) of the spring–mass chain."""
    k, m = 1000.0, 2.0
    _, finder, _ = frequency_finder(spring_mass_chain(k, m))
    exact = list(np.repeat(np.sqrt(np.array([(4 - np.sqrt(7)) / 3, (4 + np.sqrt(7)) / 3]) * k / m), 3))
    upper = 1.5 * exact[-1]
    assert finder.confirm_no_other_zeros(exact, upper)
    assert not finder.confirm_no_other_zeros(exact[:-1], upper)  # one of the triple root missing
    assert not finder.confirm_no_other_zeros(exact[:3], upper)  # the upper triple missing
    assert not finder.confirm_no_other_zeros(exact + [0.5 * exact[0]], upper)  # a root that is not one
    assert count_zeros(deflated(finder.log_det, exact[:3]), 1e-3, upper) == 3


@pytest.mark.parametrize("zeros", [80, 120, 200])
def test_a_count_sees_every_turn_of_a_steadily_winding_phase(zeros):
    """sin ω has its zeros at kπ. Along the top of the counting ellipse |sin ω| hardly
    changes while its phase winds steadily, so samples a whole turn apart look like
    none: the count of the zeros in (0.5, (n + ½)π) came out 40, 100 and 128 for
    n = 80, 120 and 200 before each point carried the derivative of log det."""
    def log_sin(omega):
        value = np.sin(np.asarray(omega, dtype=complex))
        return value / np.abs(value), np.log(np.abs(value))

    assert count_zeros(log_sin, 0.5, (zeros + 0.5) * np.pi) == zeros


def test_counts_on_rounding_noise_fail_within_their_limits():
    """Where det is rounding noise every contour step looks coarse. Many such circles in
    one count must each fail at their point limit, with log_det never handed more than
    EVALUATION_CHUNK points at once (random ring 5 up to 1e9 Hz: 125 circles round
    roots Newton settled on in the noise ran out of memory at 117,000 contour points
    in one round, 234,686 evaluations in one call)."""
    rng = np.random.default_rng(0)
    calls = []

    def noise(omega):
        calls.append(len(omega))
        return np.exp(2j * np.pi * rng.random(len(omega))), rng.normal(size=len(omega))

    circles = [(k - 1e-3, k + 1e-3) for k in range(1, 126)]
    counts = count_zeros_many(noise, circles, max_points=CIRCLE_MAX_POINTS, initial_points=CIRCLE_POINTS)
    assert all(isinstance(c, RuntimeError) for c in counts)
    assert max(calls) <= EVALUATION_CHUNK
    assert sum(calls) <= len(circles) * 2 * 2 * CIRCLE_MAX_POINTS  # value and derivative; the last round may double


def test_a_count_across_a_phase_jump_fails_fast():
    """Far above a discrete model's last root det is rounding noise and its phase
    can jump; the count must say it cannot count, not bisect towards the jump
    for thousands of rounds (a 2-mode ring asked for 4 took 4 s doing that)."""
    calls = []

    def jumping(omega):  # the phase of a zero-free function that jumps by π/2 at Re ω = 5
        calls.append(len(omega))
        return np.where(np.real(omega) < 5, 1.0, 1j), np.zeros(len(omega))

    with pytest.raises(RuntimeError, match="varies too fast"):
        count_zeros(jumping, 1.0, 10.0)
    assert len(calls) < 60
    # the fast path's closing count then says "not confirmed" (the segment search decides)
    assert RootFinder(jumping, matrix=None).confirm_no_other_zeros([], 10.0) is False


@pytest.mark.parametrize("option, match", [(dict(xtol=1e-5), "xtol must be in"),
                                           (dict(points_per_octave=16), "points_per_octave must be at least 24")])
def test_settings_that_cost_more_than_they_save_are_refused(option, match):
    """A looser xtol blurs distinct roots; a coarser scan is slower, not faster (the
    measurements are in MIN_POINTS_PER_OCTAVE's comment): both are refused by name."""
    with pytest.raises(ValueError, match=match):
        frequency_finder(spring_mass_chain(), **option)


def test_a_misleading_guess_falls_back_to_the_full_search():
    """A warm start that misses roots is caught by the root count."""
    model = spring_mass_chain()
    cold = natural_frequencies(model, count=6)
    warm = natural_frequencies(model, count=6, guess_hz=[cold.frequencies_hz[-1]])
    np.testing.assert_allclose(warm.frequencies_hz, cold.frequencies_hz, rtol=1e-12)


def cantilever_bending_hz(beam, start: float):
    """Hz (mpf, working precision) of the fixed–free bending root of ``beam`` (z plane)
    with cos λ cosh λ + 1 = 0 solved from λ ≈ ``start``."""
    lam = mp.findroot(lambda x: mp.cos(x) * mp.cosh(x) + 1, start)
    stiffness = mp.mpf(beam.E) * mp.mpf(beam.Iz) / (mp.mpf(beam.rho) * mp.mpf(beam.A) * mp.mpf(beam.length) ** 4)
    return lam**2 * mp.sqrt(stiffness) / (2 * mp.pi)


@pytest.mark.parametrize("Iy", [pytest.param(7e-7, id="simple root"),
                                pytest.param(2e-7, id="double root (round section)")])
def test_thirty_digits_match_the_frequency_equation(Iy):
    """--digits 30: the mpmath path against the cantilever equation solved at 40 digits
    (a double root is refined by its own iteration: Newton times the multiplicity)."""
    model = single_beam_model(fixed(), None, Iz=2e-7, Iy=Iy, axial=False, torsion=False)
    got = natural_frequencies(model, count=2, digits=30)
    assert got.precision == "mpmath:30"
    with mp.workdps(40):
        want = cantilever_bending_hz(model.beams[0], 1.875)
        assert abs(mp.mpf(got.frequencies_text[0]) / want - 1) < mp.mpf(10) ** -28
        if Iy == model.beams[0].Iz:
            assert got.frequencies_text[1] == got.frequencies_text[0]


def test_digits_for_a_double_root_cut_by_the_count():
    """count=3 of a round cantilever ends inside its second (double) bending root: that
    root is still refined as double (as simple, the secant crawled and gave up)."""
    model = single_beam_model(fixed(), None, Iz=2e-7, Iy=2e-7, axial=False, torsion=False)
    got = natural_frequencies(model, count=3, digits=25)
    with mp.workdps(40):
        want = cantilever_bending_hz(model.beams[0], 4.694)
        assert abs(mp.mpf(got.frequencies_text[2]) / want - 1) < mp.mpf(10) ** -23


def test_arb_determinant_matches_mpmath_det():
    """The mpmath path's LU (in Arb) against mpmath.det, on a matrix with the
    zero pattern and mixed scales of Ū_all, and on an exactly singular one."""
    rng = np.random.default_rng(3)
    values = rng.normal(size=(9, 9)) * 10.0 ** rng.integers(-6, 7, size=(9, 1))
    values[rng.random((9, 9)) < 0.6] = 0.0
    np.fill_diagonal(values, 1.0 + np.abs(values.diagonal()))
    with mp.workdps(40):
        matrix = np.vectorize(mp.mpf, otypes=[object])(values)
        assert abs(arb_determinant(matrix) / mp.det(mp.matrix(matrix.tolist())) - 1) < mp.mpf(10) ** -35
        matrix[4] = matrix[2] * 3
        assert arb_determinant(matrix) == 0


def test_roots_not_refined_in_mpmath_are_written_as_plain_numbers():
    """A result where only some roots went to mpmath writes the others as decimal
    text too (they came out as "np.float64(40.93…)")."""
    from linmstmm.solve import _refined_in_mpmath

    model = spring_mass_chain()
    deduction, finder, _ = frequency_finder(model)
    omegas = finder.find(3, None).roots
    _, _, text, omega_text = _refined_in_mpmath(deduction, model, finder, omegas, [], {}, 20, False)
    assert [float(t) for t in text] == list(omegas / (2 * np.pi))
    assert [float(t) for t in omega_text] == list(omegas)
