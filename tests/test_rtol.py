"""``rtol``: the accuracy a frequency request is certified to, against references
independent of the transfer matrices (the cantilever's closed-form frequency
equation, the FE route on the launcher), and the requests it refuses."""
from __future__ import annotations

import dataclasses
import subprocess
import sys
from pathlib import Path

import mpmath as mp
import numpy as np
import pytest
from builders import fixed, single_beam_model

from linmstmm import load_model, natural_frequencies
from linmstmm.fe import fe_frequencies

ROOT = Path(__file__).resolve().parents[1]


def cantilever_bending_hz(beam, count):
    """The lowest ``count`` bending frequencies (Hz) of a cantilever in its Iz plane:
    roots λ of cos λ cosh λ + 1 = 0 (Blevins, table 8-1) at 30 digits."""
    with mp.workdps(30):
        lambdas = [mp.findroot(lambda x: mp.cos(x) * mp.cosh(x) + 1, (2 * n - 1) * mp.pi / 2)
                   for n in range(1, count + 1)]
        return np.array([float(lam**2 * mp.sqrt(beam.E * beam.Iz / (beam.rho * beam.A * beam.length**4))
                               / (2 * mp.pi)) for lam in lambdas])


@pytest.fixture(scope="module")
def cantilever():
    """Bending in the Iz plane below 300 Hz only (the Iy plane's first mode is at 324 Hz,
    axial and torsion rigid): the closed form is the whole spectrum there."""
    return single_beam_model(fixed(), None, length=2.0, Iz=2e-7, Iy=2e-4, axial=False, torsion=False)


@pytest.mark.parametrize("rtol", [1e-4, 1e-8, 1e-12])
def test_every_frequency_lies_within_rtol_of_the_closed_form(cantilever, rtol):
    result = natural_frequencies(cantilever, 3, rtol=rtol)
    expected = cantilever_bending_hz(cantilever.beams[0], 3)
    assert np.max(np.abs(result.frequencies_hz / expected - 1)) <= rtol


def test_a_looser_rtol_takes_fewer_evaluations(cantilever):
    loose, tight = (natural_frequencies(cantilever, 3, rtol=rtol) for rtol in (1e-4, 1e-12))
    assert loose.evaluations < tight.evaluations


def test_the_launcher_at_rtol_1e4_agrees_with_the_fe_route():
    model = load_model(ROOT / "models" / "mlrs" / "mlrs.toml")
    result = natural_frequencies(model, 10, rtol=1e-4)
    fe = fe_frequencies(model, 10, rtol=1e-9)
    assert np.max(np.abs(result.frequencies_hz / fe.frequencies_hz - 1)) <= 1e-4


@pytest.mark.parametrize("count", [None, 8, 10])
def test_a_root_within_rtol_above_fmax_is_listed_whatever_the_count(cantilever, count):
    """fmax half rtol below the eighth root (closed form, both bending planes): the root
    counts as on fmax and is listed. Its coarse prediction, 0.72 rtol high at rtol
    1e-5, stood unpolished above fmax (1 + rtol), and with a count the list was cut
    by that value: seven frequencies."""
    rtol, beam = 1e-5, cantilever.beams[0]
    other_plane = dataclasses.replace(beam, Iz=beam.Iy)
    exact = np.sort(np.r_[cantilever_bending_hz(beam, 8), cantilever_bending_hz(other_plane, 3)])
    result = natural_frequencies(cantilever, count, fmax=exact[7] / (1 + 0.5 * rtol), rtol=rtol)
    assert len(result.frequencies_hz) == 8
    assert np.max(np.abs(result.frequencies_hz / exact[:8] - 1)) <= rtol


@pytest.mark.parametrize("rtol, count", [(1e-4, 10), (1e-5, 8)])
def test_double_roots_at_a_loose_rtol_cost_no_more_than_at_the_default(rtol, count):
    """Iy = Iz: every bending root is double, each one within rtol of the closed form. A
    double root's two predictions had stood for it unpolished, up to rtol off, where the
    count that tells a multiple root from a cluster of close ones looks 1e-6 around it:
    6,372 evaluations and a refinement in mpmath at rtol 1e-4 (10 roots), 6,322 at 1e-5
    (8 roots), against 423 and 338 at the default rtol."""
    model = single_beam_model(fixed(), None, length=2.0, Iy=2e-7, Iz=2e-7, axial=False, torsion=False)
    loose, default = natural_frequencies(model, count, rtol=rtol), natural_frequencies(model, count)
    expected = np.repeat(cantilever_bending_hz(model.beams[0], count // 2), 2)
    assert np.max(np.abs(loose.frequencies_hz / expected - 1)) <= rtol
    assert loose.precision == "float64" and loose.evaluations <= default.evaluations


def test_a_close_pair_at_a_loose_rtol_costs_no_more_than_at_the_default():
    """Bending pairs 1e-5 apart (Iz = Iy (1 + 1e-5)²) on a 1.5 m steel rod, at rtol 1e-6: the
    lower member of the third pair was predicted within 1e-6 of the upper one and stood for
    it, so the secant from the upper member's prediction found the upper root again, as a
    root not yet known: 19,110 evaluations and a refinement in mpmath, against 95 at the
    default rtol. Each frequency within rtol of the FE route's."""
    model = single_beam_model(fixed(), None, length=1.5, A=1e-3, Iy=3e-7, Iz=3e-7 * (1 + 1e-5) ** 2, J=2e-7,
                              Ip=4.2e-7, material=dict(E=2e11, G=8e10, rho=7800.0))
    loose, default = natural_frequencies(model, 10, rtol=1e-6), natural_frequencies(model, 10)
    fe = fe_frequencies(model, 10)
    assert np.all(np.abs(loose.frequencies_hz / fe.frequencies_hz - 1) <= 1e-6 + 3 * fe.error_estimate)
    assert loose.precision == "float64" and loose.evaluations <= default.evaluations


def test_a_pair_2_5_rtol_apart_costs_no_more_than_at_the_default():
    """Bending pairs 2.5e-6 apart (Iz = Iy (1 + 2.5e-6)²) on a 1.5 m steel cantilever at rtol
    1e-6. The secant from the second pair's prediction, between the two roots, overshot,
    stepped back, and took the short step after that (1.4e-9, from a point where det was
    e^13.6 times larger) for convergence: it stopped at det's extremum between the roots.
    The certifying count then failed and the full search ran: 3,811 evaluations against
    127 at the default rtol. Each frequency within rtol of the closed form."""
    iy = 3e-7
    model = single_beam_model(fixed(), None, length=1.5, A=1e-3, Iy=iy, Iz=iy * (1 + 2.5e-6) ** 2, J=2e-7,
                              Ip=4.2e-7, material=dict(E=2e11, G=8e10, rho=7800.0))
    loose, default = natural_frequencies(model, 10, rtol=1e-6), natural_frequencies(model, 10)
    beam = model.beams[0]
    bending = np.sort(np.r_[cantilever_bending_hz(beam, 5), cantilever_bending_hz(dataclasses.replace(beam, Iz=iy), 5)])
    assert np.max(np.abs(loose.frequencies_hz[:4] / bending[:4] - 1)) <= 1e-6
    assert loose.precision == "float64" and loose.evaluations <= default.evaluations


@pytest.mark.parametrize("engine", ["numpy", "compiled"])
def test_a_symmetric_rods_double_roots_cost_about_what_simple_roots_do(engine):
    """Iy = Iz: every bending root double, predicted as two equal values. The secant spent
    its twelve steps on each member of each double root in vain (det keeps its sign there,
    and a value equal to another prediction never stands), and each multiple root's
    argument-principle count over a small circle took some 20 evaluations: 245 for the ten
    lowest. Within 1e-9 of the closed form, multiplicities whole."""
    iy = 3e-7
    model = single_beam_model(fixed(), None, length=1.5, A=1e-3, Iy=iy, Iz=iy, J=2e-7, Ip=4.2e-7,
                              material=dict(E=2e11, G=8e10, rho=7800.0))
    result = natural_frequencies(model, 10, engine=engine)
    bending = np.repeat(cantilever_bending_hz(model.beams[0], 2), 2)
    assert np.max(np.abs(result.frequencies_hz[:4] / bending - 1)) <= 1e-9
    assert result.evaluations <= 60


def test_roots_the_polish_loses_are_found_by_counts_not_by_the_full_search():
    """Bending pairs 1e-5 apart (Iz = Iy (1 + 1e-5)²) on a 1.5 m steel cantilever, the 30
    lowest: the polish lost three roots onto their neighbours', and with fewer roots than
    asked for the predictions were dropped for the full search: 29,453 evaluations. The
    predictions not polished now place the count's upper end and counts find the lost
    roots below it. Every bending frequency of both planes (closed form) within the default
    rtol of one found, each pair's members apart; the list the FE route's."""
    iy = 3e-7
    model = single_beam_model(fixed(), None, length=1.5, A=1e-3, Iy=iy, Iz=iy * (1 + 1e-5) ** 2, J=2e-7,
                              Ip=4.2e-7, material=dict(E=2e11, G=8e10, rho=7800.0))
    result, fe = natural_frequencies(model, 30), fe_frequencies(model, 30)
    beam = model.beams[0]
    bending = np.r_[cantilever_bending_hz(beam, 8), cantilever_bending_hz(dataclasses.replace(beam, Iz=iy), 8)]
    bending = bending[bending <= result.frequencies_hz[-1]]
    nearest = np.min(np.abs(result.frequencies_hz[None, :] / bending[:, None] - 1), axis=1)
    assert bending.size >= 12 and np.all(nearest <= 1e-9)
    assert np.all(np.abs(result.frequencies_hz / fe.frequencies_hz - 1) <= 3 * fe.error_estimate + 1e-9)
    assert result.evaluations <= 1500


def test_guesses_a_fraction_of_rtol_off_with_one_missing_and_one_twice_give_every_root():
    """A floating pair of loops in km (sections 3.4e9 apart between the planes): guesses
    0.29 rtol below the FE route's ten lowest, the fourth left out and the seventh
    given twice. The sixth guess stood unpolished; the segment search around the
    seventh, reaching down to it as to a known root, found the sixth root again
    beside it, and where the Wittrick–Williams counts could not decide, the closing
    count by the argument principle took the value that is no root for the root
    missing: the fourth frequency came back 37 % high."""
    from varied_models import varied_model

    rtol, (model, _) = 1e-4, varied_model(163)
    fe = fe_frequencies(model, 10, rtol=1e-5)
    guesses = fe.frequencies_hz * (1 - 0.29 * rtol)
    guesses = np.sort(np.r_[np.delete(guesses, 3), guesses[6] * (1 + 0.3 * rtol)])
    result = natural_frequencies(model, 10, rtol=rtol, guess_hz=guesses)
    assert np.all(np.abs(result.frequencies_hz / fe.frequencies_hz - 1) <= rtol + 3 * fe.error_estimate)


@pytest.mark.parametrize("seed, moves", [(35, [-0.47, -1.16, -1.15, -1.31, -1.98, 0.27, -0.27, 1.06, 0.7, 2.26]),
                                         (61, [2.31, -1.32, -0.38, -0.07, 0.96, 2.35, 0.57, 1.8, -1.84, 0.81])])
def test_guesses_two_of_which_reach_one_root_give_every_root_at_a_loose_rtol(seed, moves):
    """Two random trees (sections 1e9 and 1e11 apart between the planes), guesses moved
    by ``moves`` rtol from the FE route's ten lowest, the fourth left out and the
    seventh given twice, rtol 1e-4. Newton from one of the twins reached the root
    below them, which the secant had found already: polished only to rtol/100, the
    two values were 2e-9 and 3e-9 apart, above the 1e-9 that made them one root, so
    it was taken twice; where the Wittrick–Williams counts could not decide, the
    closing count by the argument principle took the second copy for the root
    missing (the fourth frequency came back 46 % and 7 % high, the fifth 25 %)."""
    from varied_models import varied_model

    rtol, (model, _) = 1e-4, varied_model(seed)
    fe = fe_frequencies(model, 10, rtol=1e-5)
    guesses = fe.frequencies_hz * (1 + rtol * np.array(moves))
    guesses = np.sort(np.r_[np.delete(guesses, 3), guesses[6] * (1 + 0.3 * rtol)])
    result = natural_frequencies(model, 10, rtol=rtol, guess_hz=guesses)
    assert np.all(np.abs(result.frequencies_hz / fe.frequencies_hz - 1) <= rtol + 3 * fe.error_estimate)


@pytest.mark.parametrize("options", [{"rtol": 1e-3}, {"rtol": 1e-13}, {"rtol": 0.0}, {"rtol": 1e-6, "digits": 20}])
def test_requests_outside_the_range_or_with_digits_are_refused(cantilever, options):
    with pytest.raises(ValueError, match="rtol"):
        natural_frequencies(cantilever, 2, **options)


@pytest.mark.parametrize("arguments, message", [(["--rtol", "1e-3"], "must be at most 0.0001"),
                                                (["--rtol", "1e-13"], "must be at least 1e-12"),
                                                (["--rtol", "1e-6", "--digits", "20"], "not allowed with")])
def test_the_command_line_refuses_them_with_exit_status_2(arguments, message):
    done = subprocess.run([sys.executable, "-m", "linmstmm", "freqs", "models/spring_mass_chain.toml", *arguments],
                          cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert done.returncode == 2 and message in done.stderr and "Traceback" not in done.stderr


def test_the_table_says_what_rtol_its_frequencies_are_certified_to():
    """With --rtol the text table says the digits it prints beyond it are not certified;
    without, it says nothing of the kind (the default prints digits det polished)."""
    def table(*arguments):
        return subprocess.run([sys.executable, "-m", "linmstmm", "freqs", "models/spring_mass_chain.toml", *arguments],
                              cwd=ROOT, capture_output=True, text=True, timeout=120).stdout
    assert "certified to: rtol 1e-04 (each frequency within it of the root" in table("--rtol", "1e-4")
    assert "certified to" not in table()


def test_at_a_loose_rtol_roots_a_count_encloses_within_rtol_are_not_bisected_further():
    """Two bending roots 2e-6 apart (Iy = Iz (1 + 4e-6)): at rtol 1e-4 an interval
    narrower than rtol that the count says holds both gives both at its middle, each
    within rtol of the closed form, without evaluating det and without a refinement
    in mpmath (the second launcher's pair 3e-6 apart at 5.8 krad/s was bisected down
    to 1e-9 wide: 9,000 evaluations and an mpmath refinement at rtol 1e-4)."""
    from linmstmm.solve import frequency_finder

    model = single_beam_model(fixed(), None, length=2.0, Iz=2e-7, Iy=2e-7 * (1 + 4e-6), axial=False,
                              torsion=False)
    beam = model.beams[0]
    lower = 2 * np.pi * cantilever_bending_hz(beam, 1)[0]
    upper = lower * np.sqrt(1 + 4e-6)                       # the Iy plane's first root
    _, finder, _ = frequency_finder(model, rtol=1e-4, xtol=1e-6)
    before = finder.determinant.evaluations
    members = finder._isolate(lower * (1 - 3e-5), lower * (1 + 3e-5), 2, [])
    assert finder.determinant.evaluations == before and not finder.unseparated
    assert len(members) == 2
    assert all(abs(m / root - 1) <= 1e-4 for m, root in zip(members, (lower, upper)))


def test_isolating_roots_counts_them_by_the_stiffness_count_where_it_decides():
    """Bisection on the count (``isolate``) asks how many roots lie in each half: the
    Wittrick–Williams count answers without evaluating det where it decides, and
    agrees with the closed form; a pair 2.5e-6 apart took 5,800 evaluations of det
    for the argument principle's counts alone at rtol 1e-6."""
    from linmstmm.roots.segments import _root_count
    from linmstmm.solve import frequency_finder

    model = single_beam_model(fixed(), None, length=2.0, Iz=2e-7, Iy=2e-7 * (1 + 5e-6), axial=False,
                              torsion=False)
    lower = 2 * np.pi * cantilever_bending_hz(model.beams[0], 2)
    roots = np.sort(np.r_[lower, lower * np.sqrt(1 + 5e-6)])
    _, finder, _ = frequency_finder(model, rtol=1e-6, xtol=1e-8)
    before = finder.determinant.evaluations
    for lo, hi in ((roots[0] * 0.5, roots[0] * (1 + 1e-6)), (roots[0] * (1 + 1e-6), roots[3] * 1.1),
                   (roots[0] * 0.9, roots[1] * 1.01), (roots[1] * 1.01, roots[2] * 0.99)):
        assert _root_count(finder, lo, hi) == np.count_nonzero((roots > lo) & (roots <= hi))
    assert finder.determinant.evaluations == before
