"""The certifying logic on Wittrick–Williams counts, with a counter that knows the
true natural frequencies (the counts themselves are checked against the FE route
in tests/test_wittrick_williams.py): what the certification accepts, what it
refuses, and what it repairs."""
from __future__ import annotations

import numpy as np
import pytest

from linmstmm.roots import CERTIFIED_STEP, certify


class KnownSpectrum:
    """A finder whose counter answers J(ω) exactly for the frequencies ``true`` (rad/s),
    certifying roots to ``rtol``."""

    def __init__(self, true, rigid=0, rtol=CERTIFIED_STEP):
        self.true, self.rigid, self.last_step, self.rtol = np.sort(true), rigid, {}, rtol

    def counter(self, omega):
        return self.rigid + int(np.sum(self.true < omega))

    def rigid_body_modes(self):
        return self.rigid


def test_complete_roots_with_their_multiplicities_are_certified():
    finder = KnownSpectrum([10.0, 20.0, 20.0, 30.0], rigid=6)
    assert certify.stiffness_other_zeros(finder, [10.0, 20.0, 20.0, 30.0], None, 35.0) == 0


def test_a_root_is_certified_to_the_finders_rtol_and_no_closer():
    """A root 5e-7 (relative) off its true value: at rtol 1e-5 the count across it
    (±1e-5) holds the true one and it stands as certified; at the default rtol the
    counts at ±1e-9 … 1e-7 hold nothing and only ±1e-6 holds it, so that width
    becomes its last step (the caller refines it in mpmath)."""
    true, off = [10.0, 20.0, 30.0], 20.0 * (1 + 5e-7)
    loose, default = KnownSpectrum(true, rtol=1e-5), KnownSpectrum(true)
    for finder in (loose, default):
        assert certify.stiffness_other_zeros(finder, [10.0, off, 30.0], None, 35.0) == 0
    assert off not in loose.last_step
    assert default.last_step[off] == 1e-6


def test_a_pair_each_on_the_end_of_the_others_count_is_decided_by_a_narrower_count():
    """At rtol 1e-4 a pair 1.05e-4 apart (relative): the count across each at ±rtol has
    the other within a tenth of its width of an end, where it says nothing (the second
    launcher's pair at 5109 rad/s, which the argument principle then had to decide, 124
    evaluations). A count at half the gap, narrower than rtol and so certifying more,
    decides for each: both roots stand, and a value between them that is no root does not."""
    pair = [5109.38, 5109.38 * (1 + 1.05e-4)]
    finder = KnownSpectrum([1000.0, *pair, 9000.0], rtol=1e-4)
    assert certify._on_an_end(sorted(pair), pair[0], 1e-4)
    assert certify.stiffness_other_zeros(finder, [1000.0, *pair, 9000.0], None, 9500.0) == 0
    assert not finder.last_step
    between = 5109.38 * (1 + 0.5e-4)
    assert certify.stiffness_other_zeros(finder, [1000.0, pair[0], between, 9000.0], None, 9500.0) != 0


def test_multiplicities_of_a_pair_each_on_the_end_of_the_others_count_are_counted_narrower():
    """The same pair at rtol 1e-4, its upper member listed twice: the counts of the
    multiplicities take the same narrower width as the certificate, half the gap, and
    drop the copy there (at ±rtol alone no count decides and the copy stood, for the
    certificate to catch later at a higher price)."""
    pair = [5109.38, 5109.38 * (1 + 1.05e-4)]
    finder = KnownSpectrum([1000.0, *pair, 9000.0], rtol=1e-4)
    listed = [1000.0, pair[0], pair[1], pair[1], 9000.0]
    assert certify.counted_multiplicities(finder, listed, None, 9500.0) == [1000.0, *pair, 9000.0]
    assert not finder.last_step


def test_a_narrower_count_is_not_offered_to_a_root_known_less_closely():
    """A root whose last step is 1e-4 (float64 could not certify it to rtol 1e-6) is
    counted no narrower than four times that step, whatever its neighbours."""
    assert certify._clear_of_neighbours([10.0, 10.0 * (1 + 4e-4)], 10.0, [4e-4], 4e-4) == [4e-4]
    assert certify._clear_of_neighbours([10.0, 10.0 * (1 + 4e-4)], 10.0, [4e-4], 0.0) == pytest.approx([2e-4, 4e-4])


def test_a_missing_member_of_a_double_root_is_seen_and_added():
    finder = KnownSpectrum([10.0, 20.0, 20.0, 30.0])
    known = [10.0, 20.0, 30.0]
    assert certify.stiffness_other_zeros(finder, known, None, 35.0) == 1
    assert certify.counted_multiplicities(finder, known, None, 35.0) == [10.0, 20.0, 20.0, 30.0]


def test_a_value_that_is_no_root_cannot_stand_in_for_a_missing_one():
    """The total count balances (a false root at 25, the double root's second member
    missing); the counts across each root do not."""
    finder = KnownSpectrum([10.0, 20.0, 20.0, 30.0])
    known = [10.0, 20.0, 25.0, 30.0]
    assert certify.stiffness_count(finder, known, None, 35.0) == 0
    assert certify.stiffness_other_zeros(finder, known, None, 35.0) != 0
    assert certify.counted_multiplicities(finder, known, None, 35.0) == [10.0, 20.0, 20.0, 30.0]


def test_a_root_placed_off_by_more_than_its_last_step_is_marked_for_refinement():
    """True root 20, float64 put it 5e-9 high with a last step of 1e-12: the count
    across ±1e-9 misses it, ±1e-8 holds it; its last step becomes 1e-8."""
    finder = KnownSpectrum([10.0, 20.0, 30.0])
    off = 20.0 * (1 + 5e-9)
    finder.last_step = {10.0: 1e-13, off: 1e-12, 30.0: 1e-13}
    assert certify.stiffness_other_zeros(finder, [10.0, off, 30.0], None, 35.0) == 0
    assert finder.last_step[off] == pytest.approx(1e-8)
    assert finder.last_step[10.0] == 1e-13


def test_a_close_pair_is_certified_by_counts_that_see_both():
    pair = [20.0, 20.0 * (1 + 3e-9)]
    finder = KnownSpectrum([10.0, *pair])
    assert certify.stiffness_other_zeros(finder, [10.0, *pair], None, 35.0) == 0
    assert certify.counted_multiplicities(finder, [10.0, *pair], None, 35.0) == [10.0, *pair]


def test_no_counter_means_no_answer_from_counts():
    finder = KnownSpectrum([10.0])
    finder.counter = None
    assert certify.stiffness_other_zeros(finder, [10.0], None, 35.0) is None
    assert certify.counted_multiplicities(finder, [10.0], None, 35.0) == [10.0]


def test_a_certified_last_step_does_not_widen_the_count():
    """A root float64 calls certified (last step 7.3e-10, below 1e-9) but 2.5e-9 off, as the
    second launcher's at 4.90 krad/s was: the count across ±1e-9 still judges it, and its
    last step becomes the width that holds it (1e-8), so it is refined in mpmath."""
    finder = KnownSpectrum([10.0, 20.0, 30.0])
    off = 20.0 * (1 + 2.5e-9)
    finder.last_step = {off: 7.3e-10}
    assert certify.stiffness_other_zeros(finder, [10.0, off, 30.0], None, 35.0) == 0
    assert finder.last_step[off] == pytest.approx(1e-8)


def test_a_root_float64_could_not_certify_is_placed_by_bisection_on_the_count():
    """True root 20, float64 put it 5e-9 high and the counts made its last step 1e-8:
    bisection on J(ω) from ±4e-8 puts it within the rtol of 1e-9 and certifies that
    as its last step; a root with a neighbour inside the bracket, and a double root,
    are left for mpmath."""
    finder = KnownSpectrum([10.0, 20.0, 30.0])
    off = 20.0 * (1 + 5e-9)
    finder.last_step = {10.0: 1e-13, off: 1e-8, 30.0: 1e-13}
    placed = certify.placed_by_counts(finder, [10.0, off, 30.0])
    assert placed[0] == 10.0 and placed[2] == 30.0
    assert abs(placed[1] / 20.0 - 1) <= 1e-9 and finder.last_step[placed[1]] <= 1e-9
    crowded = KnownSpectrum([10.0, 20.0, 20.0 * (1 + 2e-8)])
    crowded.last_step = {off: 1e-8}
    assert certify.placed_by_counts(crowded, [10.0, off, 20.0 * (1 + 2e-8)])[1] == off
    double = KnownSpectrum([10.0, 20.0, 20.0])
    double.last_step = {off: 1e-8}
    assert certify.placed_by_counts(double, [10.0, off, off]) == [10.0, off, off]
