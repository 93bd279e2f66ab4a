"""The segment search by Wittrick–Williams counts (linmstmm/roots/counted_search.py):
its logic on a finder whose det and counts know the true roots, and its roots on
the launcher against the FE route."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import linmstmm.roots.segments as segments
from linmstmm import fe_frequencies, load_model, natural_frequencies
from linmstmm.roots import certify
from linmstmm.roots.counted_search import _split, counted_segment

ROOT = Path(__file__).resolve().parents[1]


class KnownRoots:
    """A finder whose det is Π(ω − r) over ``roots`` (rad/s, with repeats) and whose
    counter answers J(ω) for them; a cluster polish that returns the roots within
    1e-6 of where it starts, as the pencil does."""

    xtol, rtol, CERTIFIED_WIDTH, same_root = 1e-14, 1e-9, 1e-9, 1e-9
    stiffness_count = certify.stiffness_count  # J(hi) − J(lo) by the counter below, as the finder's

    def __init__(self, roots, undecided=(), blind=0.0):
        """undecided : frequencies where the count cannot decide, and within ``blind``
        (relative) of them."""
        self.roots, self.undecided, self.blind = np.sort(roots), undecided, blind
        self.last_step, self.evaluations = {}, 0
        self._counted, self._circles = {}, {}  # multiplicities as the finder records them

    def counter_for_stretch(self):
        return self.counter

    @property
    def fine_rtol(self):
        return self.rtol <= 1e-9  # the finder's default

    def counter(self, omega):
        if any(abs(omega - u) <= self.blind * u for u in self.undecided):
            return None
        return int(np.sum(self.roots < omega))

    def log_det(self, omega):
        self.evaluations += np.size(omega)
        factors = np.asarray(omega)[:, None] - self.roots[None, :]
        with np.errstate(divide="ignore"):  # ω on a root: det 0, log −inf
            return np.prod(np.sign(factors), axis=1), np.sum(np.log(np.abs(factors)), axis=1)

    def cluster(self, omega):
        return [float(r) for r in self.roots if abs(r - omega) <= 1e-6 * omega]


def test_simple_roots_and_a_close_pair_are_each_found_in_their_bracket():
    roots = [3.0, 7.5, 10.0, 10.0 * (1 + 1e-7), 12.25]
    finder = KnownRoots(roots)
    found = counted_segment(finder, 1.0, 20.0)
    np.testing.assert_allclose(found, roots, rtol=1e-13)
    assert finder.evaluations <= 15 * len(roots)


def test_a_double_root_comes_whole_from_the_cluster_polish():
    finder = KnownRoots([4.0, 9.0, 9.0, 15.0])
    assert counted_segment(finder, 1.0, 20.0) == pytest.approx([4.0, 9.0, 9.0, 15.0], rel=1e-13)


def test_a_close_pair_the_pencil_merges_into_one_double_root_is_parted_by_the_counts():
    """The pencil takes offsets below SPLIT (1e-4) for one multiple root: a cantilever's
    pair 2.5e-6 apart came back as a double root at the lower member, the other 2.5 rtol
    off at rtol 1e-6. The counts across it show one root within rtol: bisection parts them."""
    pair = [9.0, 9.0 * (1 + 2.5e-6)]
    finder = KnownRoots([4.0, *pair, 15.0])
    finder.rtol = 1e-6
    finder.cluster = lambda omega: [pair[0], pair[0]] if abs(omega - 9.0) < 1e-4 * 9.0 else []
    assert counted_segment(finder, 1.0, 20.0) == pytest.approx([4.0, *pair, 15.0], rel=1e-13)


def test_ends_on_roots_where_the_count_cannot_decide_move_outward():
    """A stretch between two roots already found, where K(ω) is singular and the count
    cannot decide: the ends move out by the narrowest width that decides (1e-9 here),
    the lower root found again stays out, the upper one is in (lo, hi]."""
    roots = [4.0, 9.0, 9.0 * (1 + 1e-7), 15.0]
    finder = KnownRoots(roots, undecided=(4.0, 15.0))
    np.testing.assert_allclose(counted_segment(finder, 4.0, 15.0), roots[1:], rtol=1e-13)
    wider = KnownRoots(roots, undecided=(4.0, 15.0), blind=5e-9)  # 1e-9 undecided too: 1e-8 decides
    np.testing.assert_allclose(counted_segment(wider, 4.0, 15.0), roots[1:], rtol=1e-13)
    # a root between an end and where it moved to is not in (lo, hi]
    beyond = KnownRoots([4.0 * (1 - 5e-8), *roots[1:]], undecided=(4.0,), blind=5e-8)
    np.testing.assert_allclose(counted_segment(beyond, 4.0, 20.0), roots[1:], rtol=1e-13)
    # two there, a pair astride the end, which values cannot place: the search gives up
    astride = KnownRoots([4.0 * (1 - 5e-8), *roots, 15.0 * (1 + 5e-8)], undecided=(4.0, 15.0), blind=5e-8)
    assert counted_segment(astride, 4.0, 15.0) is None


def test_an_undecided_count_or_an_unresolved_cluster_hands_the_segment_back():
    assert counted_segment(KnownRoots([4.0, 9.0], undecided=(10.5,)), 1.0, 20.0) is None
    assert counted_segment(KnownRoots([4.0, 9.0], undecided=(1.0,), blind=1e-5), 1.0, 20.0) is None
    unresolved = KnownRoots([4.0, 9.0, 9.0])
    unresolved.cluster = lambda omega: []  # the pencil finds nothing there
    assert counted_segment(unresolved, 1.0, 20.0) is None


def test_a_double_root_the_pencil_sees_too_often_is_taken_as_the_counts_bound_it():
    """An octahedral star's pencil saw one double root of a cluster six times, and the count
    cannot decide within 1e-9 of it, so its piece cannot be halved: the counts within ±rtol
    of it, and over that and the piece together, find its two, which it then holds."""
    double = 9.0 * (1 + 5e-8)
    finder = KnownRoots([4.0, 9.0, double, double, 15.0], undecided=(double,), blind=1e-9)
    finder.cluster = lambda omega: [double] * 6 if abs(omega - double) < 1e-4 * 9.0 else []
    found = counted_segment(finder, 1.0, 20.0)
    assert found == pytest.approx([4.0, 9.0, double, double, 15.0], rel=1e-13)
    assert finder._counted[found[2]] == 2  # the counts' multiplicity, for the later checks
    # a value held by fewer than the piece holds within ±rtol: not taken
    lone = KnownRoots([4.0, 9.0, double, double * (1 + 3e-9), 15.0], undecided=(double,), blind=1e-8)
    lone.cluster = lambda omega: [double] * 6 if abs(omega - double) < 1e-4 * 9.0 else []
    assert counted_segment(lone, 1.0, 20.0) is None


def test_a_piece_whose_middle_the_count_cannot_decide_is_split_between_the_pencils_roots():
    """Two double roots 5e-8 apart whose piece's middle the count cannot decide (an
    octahedral star's, bending planes 1e-7 apart): the piece is split halfway between
    the pencil's two roots instead, where the count decides; where none decides, the
    middle is given back undecided."""
    lower, upper = 9.0 * (1 - 1e-8), 9.0 * (1 + 4e-8)
    lo, hi = 9.0 * (1 - 6e-8), 9.0 * (1 + 6e-8)
    finder = KnownRoots([4.0, lower, lower, upper, upper, 15.0], undecided=(0.5 * (lo + hi),))
    assert _split(finder, lo, hi, [lower, upper]) == (0.5 * (lower + upper), 3)
    assert _split(finder, lo, hi, [lower]) == (0.5 * (lo + hi), None)


def test_the_launchers_first_100_agree_with_the_fe_route(monkeypatch):
    """The 100th region holds a pair the secant and the pencil both land on one member
    of; the counted search finds the other (15.50 krad/s). Reference: the FE route on
    64 and 128 elements per beam, extrapolated as h² (its rods converge as h², its
    beams as h⁴ and are converged already), 3e-6 from the transfer matrices at worst."""
    counted = []
    monkeypatch.setattr(segments, "counted_segment",
                        lambda *args: counted.append(counted_segment(*args)) or counted[-1])
    model = load_model(ROOT / "models" / "mlrs" / "mlrs.toml")
    result = natural_frequencies(model, 100)
    assert any(counted), "the counted search was not needed: this test no longer checks it"
    coarse, fine = (fe_frequencies(model, count=100, elements_per_beam=n, estimate_error=False).frequencies_hz ** 2
                    for n in (64, 128))
    extrapolated = np.sqrt(fine + (fine - coarse) / 3)
    assert np.max(np.abs(result.frequencies_hz / extrapolated - 1)) <= 1e-5


def test_a_rods_close_pairs_are_resolved_by_counts_between_their_neighbours(monkeypatch):
    """A steel cantilever whose bending planes are 1e-7 apart, 30 lowest: the stretches
    the polish leaves troubled end on roots already found, where the count cannot
    decide. Each is resolved by counts from ends moved outward (before, every one went
    to the argument principle: 3,164 evaluations of det in all; 1,247 after, and 803 once
    the repair halves its stretches clear of close pairs). Reference:
    the closed form (tests/test_close_roots.py), to the default rtol 1e-9."""
    from test_close_roots import cantilever, cantilever_hz

    counted = []
    monkeypatch.setattr(segments, "counted_segment",
                        lambda *args: counted.append(counted_segment(*args)) or counted[-1])
    iz = 3.0e-7 * (1 + 1e-7) ** 2
    result = natural_frequencies(cantilever(iz), count=30)
    assert counted and all(found is not None for found in counted)
    np.testing.assert_allclose(result.frequencies_hz, cantilever_hz(iz, 30), rtol=1e-9)
