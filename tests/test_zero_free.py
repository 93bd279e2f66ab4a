"""Whether an interval holds no root (linmstmm.counting.zero_free), against the full count.

Opposite signs of det at the two ends of an interval mean an odd number of
roots between, so zero_free answers False from the count's first round; with
equal signs it counts as count_zeros does. Checked on sin ω (zeros at kπ) and
on the first scan chunks of random models and of a spring–mass chain, whose
roots are known in closed form.
"""
from __future__ import annotations

import numpy as np
import pytest
from random_models import KINDS, random_model

from linmstmm.builders import spring_chain
from linmstmm.counting import count_zeros, zero_free
from linmstmm.roots.settings import DEFLATED_POINTS, FIRST_CHUNK_RATIO
from linmstmm.solve import frequency_finder


def counted_sin(calls: list):
    """log det of sin ω, recording how many points each call is given."""
    def log_sin(omega):
        calls.append(len(omega))
        value = np.sin(np.asarray(omega, dtype=complex))
        return value / np.abs(value), np.log(np.abs(value))
    return log_sin


def test_opposite_signs_at_the_ends_answer_from_the_first_round():
    """(0.5, 75.5π) holds 75 zeros of sin ω, and sin has opposite signs at its ends."""
    first, full = [], []
    assert zero_free(counted_sin(first), 0.5, 75.5 * np.pi, initial_points=DEFLATED_POINTS) is False
    assert count_zeros(counted_sin(full), 0.5, 75.5 * np.pi, initial_points=DEFLATED_POINTS) == 75
    assert first == [2 * DEFLATED_POINTS]  # the values and their derivatives, once
    assert sum(full) > 10 * sum(first)


@pytest.mark.parametrize("b, zeros", [(3.0, 0), (2.5 * np.pi, 2), (40.5 * np.pi, 40)])
def test_equal_signs_at_the_ends_are_counted(b, zeros):
    """An even number of zeros (none among them) leaves det with one sign at both
    ends: the whole count decides, with the evaluations it takes."""
    calls, counted = [], []
    assert zero_free(counted_sin(calls), 0.5, b) is (zeros == 0)
    assert count_zeros(counted_sin(counted), 0.5, b) == zeros
    assert calls == counted


def first_chunk(model):
    """(log det, floor, top of the first scan chunk) of ``model``'s root finder."""
    _, finder, _ = frequency_finder(model, engine="numpy")
    return finder.log_det, finder.floor, FIRST_CHUNK_RATIO * finder.scale


@pytest.mark.parametrize("kind", KINDS)
def test_random_models_first_chunks_agree_with_the_count(kind):
    for seed in range(4):
        log_det, lo, hi = first_chunk(random_model(kind, seed))
        try:
            free = count_zeros(log_det, lo, hi, initial_points=DEFLATED_POINTS) == 0
        except RuntimeError:
            free = False
        assert zero_free(log_det, lo, hi, initial_points=DEFLATED_POINTS) is free


def test_a_chain_whose_first_chunk_holds_an_odd_number_of_roots():
    """spring_chain(2000): ω_j = 2 √(k/m) sin((2j − 1)π / (2(2n + 1))), each three times;
    an odd number of them lie in the first chunk, which zero_free sees at once."""
    n, k, m = 2000, 1e6, 1.0
    log_det, lo, hi = first_chunk(spring_chain(n, m, k))
    j = np.arange(1, n + 1)
    roots = 2 * np.sqrt(k / m) * np.sin((2 * j - 1) * np.pi / (2 * (2 * n + 1)))
    inside = 3 * np.count_nonzero((roots > lo) & (roots < hi))
    assert inside % 2 == 1
    calls = []

    def counted(omega):
        calls.append(len(omega))
        return log_det(omega)

    assert zero_free(counted, lo, hi, initial_points=DEFLATED_POINTS) is False
    assert calls == [2 * DEFLATED_POINTS]
    assert count_zeros(log_det, lo, hi, initial_points=DEFLATED_POINTS) == inside


def test_a_count_names_a_point_where_det_lost_its_digits_and_a_det_zero_everywhere():
    """det exactly 0 at one contour point (a value lost to rounding) is not Ū_all
    singular at every frequency: the message gives the point; where every point is 0,
    it says singular."""
    def log_sin_lost_near(omega):
        value = np.sin(np.asarray(omega, dtype=complex))
        sign, log_abs = value / np.abs(value), np.log(np.abs(value))
        lost = np.abs(omega - (2.0 + 0.5j)) < 0.3
        return np.where(lost, 0, sign), np.where(lost, -np.inf, log_abs)

    def zero_everywhere(omega):
        return np.zeros(len(omega), dtype=complex), np.full(len(omega), -np.inf)

    with pytest.raises(RuntimeError, match=r"exactly 0 or not finite at ω = [0-9.]+\+[0-9.]+j rad/s") as lost:
        count_zeros(log_sin_lost_near, 0.5, 3.5)
    assert "every frequency" not in str(lost.value)
    with pytest.raises(RuntimeError, match="singular at every frequency"):
        count_zeros(zero_everywhere, 0.5, 3.5)
