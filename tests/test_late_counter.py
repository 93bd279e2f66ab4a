"""Models too large for a Wittrick–Williams count at every root (over MAX_ORDER unknowns)
but within CLUSTER_ORDER: their search polishes predictions and certifies by the argument
principle, and makes the counter only where a stretch of roots must be searched, whose
clusters det Ū_all and its pencil cannot part. The model is an octahedral star: six arms
of beams clamped at their far ends, each section's bending planes a relative ``gap``
apart, so that arms along different axes make clusters of roots about gap / 2 apart and
double roots where they mirror. The references are the FE route on the same model (a
mesh fine enough to tell the roots that were wrong from the right ones) and the same star
of one beam an arm, which has a counter at every root."""
from __future__ import annotations

import numpy as np
import pytest

from linmstmm import fe_frequencies
from linmstmm.builders import beam_star
from linmstmm.solve import natural_frequencies
from linmstmm.wittrick_williams import CLUSTER_ORDER, MAX_ORDER, late_counter, mode_counter


def test_the_star_has_a_counter_only_late():
    """Twenty beams an arm: 690 unknowns, no counter at every root, one made late."""
    star = beam_star(20, 1e-5)
    assert mode_counter(star) is None
    made = late_counter(star)()
    assert MAX_ORDER < made.n_dof <= CLUSTER_ORDER


def test_a_count_that_ends_on_a_double_root_keeps_both_its_copies():
    """The 20 lowest end on a double root with two more 5e-6 and 1e-5 above it. Its circle,
    drawn among the roots found, held all six; the pencil showed the highest beside it, which
    took one of its two copies: the 20th came back 1e-5 high, with no note."""
    star = beam_star(20, 1e-5)
    got = natural_frequencies(star, 20)
    fe = fe_frequencies(beam_star(20, 1e-5), 20, elements_per_beam=8).frequencies_hz
    np.testing.assert_allclose(got.frequencies_hz, fe, rtol=1e-7)  # FE's mesh error: 3e-8
    assert got.frequencies_hz[-1] == pytest.approx(got.frequencies_hz[-2], rel=1e-12)
    assert got.precision == "float64" and got.note == ""
    counted = natural_frequencies(beam_star(1, 1e-5), 20)  # a counter at every root
    np.testing.assert_allclose(got.frequencies_hz, counted.frequencies_hz, rtol=1e-11)


@pytest.mark.parametrize("gap", [1e-7, 1e-6])
def test_clusters_are_parted_by_the_late_counts(gap):
    """Roots gap / 2 apart in clusters of three, and double roots. The argument-principle
    search of their stretches took some 2,000 evaluations of det Ū_all a root (100 to 190 s
    at twenty beams an arm); the late counts bisect them in a few hundred."""
    star = beam_star(6, gap)
    got = natural_frequencies(star, 10)
    fe = fe_frequencies(beam_star(6, gap), 10, elements_per_beam=8).frequencies_hz
    np.testing.assert_allclose(got.frequencies_hz, fe, rtol=1e-7)
    counted = natural_frequencies(beam_star(1, gap), 10)
    # (at gap 1e-6 the 9th and 10th are 1.3e-11 apart, FE at 128 elements a beam: each
    # search reports them as a double root, within the default rtol of 1e-9, at one or the other)
    np.testing.assert_allclose(got.frequencies_hz, counted.frequencies_hz, rtol=1e-10)
    assert got.evaluations < 150 * 10
    assert got.precision == "float64"


@pytest.mark.parametrize("beams_per_arm", [3, 6])
def test_roots_exactly_rtol_apart_at_a_loose_rtol_are_all_listed(beams_per_arm):
    """Planes 2e-6 apart, so the members of a cluster lie 1e-6 apart, asked for at rtol
    1e-6: a value may stand for two roots within rtol of it (listed twice). A root listed
    twice was one root and another 0.95e-6 below it; the count tight about it found one,
    the bisection within half the distance to the root below found that one only, and
    the other copy was dropped: 17 or 19 roots came back with the note that only so many
    exist. The 20 must each lie within rtol of a root of the one-beam star (to 1e-9, that
    reference's accuracy at the default rtol: members exactly rtol apart lie on the edge of
    a count's window). The compiled engine: the numpy one takes 12 s here."""
    got = natural_frequencies(beam_star(beams_per_arm, 2e-6), 20, rtol=1e-6, engine="compiled")
    counted = natural_frequencies(beam_star(1, 2e-6), 20, engine="compiled")  # a counter at every root
    assert got.note == ""
    np.testing.assert_allclose(got.frequencies_hz, counted.frequencies_hz, rtol=1e-6 + 1e-9)


def test_a_search_that_loses_a_root_says_so(monkeypatch):
    """Where a search for the 20 lowest ends with fewer and the count finds more below its
    ceiling, it raises rather than list fewer with the note that only so many exist; a
    search at a looser rtol is then made again at the default one (here the loss is
    forced, at every rtol)."""
    from linmstmm.roots import RootFinder

    separated = RootFinder._separated_above_floor
    monkeypatch.setattr(RootFinder, "_separated_above_floor", lambda self, roots: separated(self, roots)[:-1])
    for rtol in (None, 1e-6):
        with pytest.raises(RuntimeError, match="the search ended with 19 roots where the count finds"):
            natural_frequencies(beam_star(1, 1e-3), 20, rtol=rtol)


def test_clusters_exactly_rtol_apart_are_parted_in_float64():
    """One beam an arm, planes 2e-7 apart (cluster members 1e-7 apart), at rtol 1e-7: the
    search at that rtol left a 4-fold value to mpmath, where it did not settle (an
    UnsettledRoot error after 9 s), while the default rtol parts the cluster in float64.
    A loose-rtol search that leaves roots to mpmath is made again at the default rtol."""
    got = natural_frequencies(beam_star(1, 2e-7), 20, rtol=1e-7, engine="compiled")
    counted = natural_frequencies(beam_star(1, 2e-7), 20, engine="compiled")
    assert got.precision == "float64" and got.note == ""
    np.testing.assert_allclose(got.frequencies_hz, counted.frequencies_hz, rtol=1e-7 + 1e-9)


def test_a_stretch_the_counts_cannot_search_at_a_loose_rtol_is_searched_at_the_default():
    """Three beams an arm, planes 2e-5 apart, at rtol 1e-5 (cluster members 1e-5 apart): the
    counted search of a stretch whose ends lie on roots cannot move them off at a loose
    rtol, and the argument-principle search of that stretch took 18,675 evaluations of
    det; the search is now made again at the default rtol, whose counts move the ends."""
    got = natural_frequencies(beam_star(3, 2e-5), 20, rtol=1e-5, engine="compiled")
    counted = natural_frequencies(beam_star(1, 2e-5), 20, engine="compiled")
    np.testing.assert_allclose(got.frequencies_hz, counted.frequencies_hz, rtol=1e-5 + 1e-9)
    assert got.evaluations < 8000
