"""A range request whose top is a natural frequency, to rounding.

A root within ``rtol`` (the accuracy roots are certified to) above fmax
counts as on it and is listed; one further above is not, nor one below fmax
by more than that. References in closed form: √(k/m) of a body on a spring,
and the first bending pair (a double root) of a round cantilever,
ω = (β₁/L)² √(EI/ρA) with cos β₁ cosh β₁ = −1.
"""
from __future__ import annotations

import numpy as np
import pytest
from builders import fixed, make_rigid, make_spring, single_beam_model
from scipy.optimize import brentq

import linmstmm as lm
from linmstmm.studies import determinant_scan

LENGTH, E, RHO, AREA, I = 1.5, 2.0e11, 7800.0, 1.0e-3, 3.0e-7
DEFAULT_RTOL = 1e-9


def origin_points(*names):
    """Points at the origin, one per name."""
    return {name: np.zeros(3) for name in names}


def body_on_a_spring() -> lm.Model:
    """A 2 kg body on a spring to the ground: √(k / m) and √(k_r / I) give 10 rad/s (rx), then
    20 rad/s twice (x and ry)."""
    return lm.Model("one body on a spring", origin_points("ground", "a"),
                    rigids=(make_rigid("m", ["a"], 2.0, np.zeros(3), [0.5, 0.5, 0.5]),),
                    springs=(make_spring("k", "ground", "a", [800.0, 1800.0, 3200.0, 50.0, 200.0, 450.0]),),
                    boundary={"ground": fixed()})


def round_cantilever() -> lm.Model:
    """A steel cantilever with Iy = Iz: its bending frequencies are double roots."""
    return single_beam_model(fixed(), None, length=LENGTH, A=AREA, Iy=I, Iz=I, J=2 * I,
                             material=dict(E=E, G=8.0e10, rho=RHO))


def first_bending_hz() -> float:
    """The round cantilever's first bending frequency, Hz (closed form)."""
    beta = brentq(lambda x: np.cos(x) + 1 / np.cosh(x), 1.0, 2.5, xtol=1e-15) / LENGTH
    return beta ** 2 * np.sqrt(E * I / (RHO * AREA)) / (2 * np.pi)


def test_fmax_on_a_natural_frequency():
    """ω = √(k_x / m) = 20 rad/s; fmax = 20 / 2π Hz (the CLI gave exit status 1).
    Whether a root on fmax is in or out is rounding; either answer is right."""
    model = lm.Model("one body on a spring", origin_points("ground", "a"),
                     rigids=(make_rigid("m", ["a"], 2.0, np.zeros(3), [0.5, 0.5, 0.5]),),
                     springs=(make_spring("k", "ground", "a", [800.0, 1800.0, 3200.0, 50.0, 200.0, 450.0]),),
                     boundary={"ground": fixed()})
    lowest = 10.0 / np.pi / 2
    result = lm.natural_frequencies(model, count=None, fmax=lowest)
    assert len(result.frequencies_hz) <= 1
    np.testing.assert_allclose(result.frequencies_hz, [lowest][:len(result.frequencies_hz)], rtol=1e-12)


@pytest.mark.parametrize("offset", [0.0, 1e-12, -1e-12, -DEFAULT_RTOL, -0.99 * DEFAULT_RTOL, 1e-7])
def test_a_double_root_at_fmax_to_within_rtol_is_listed(offset):
    """fmax at the pair, and fmax = root / (1 + rtol) (the search's own ceiling on the root)."""
    exact = first_bending_hz()
    result = lm.natural_frequencies(round_cantilever(), count=None, fmax=exact * (1 + offset))
    np.testing.assert_allclose(result.frequencies_hz, [exact, exact], rtol=1e-9)


@pytest.mark.parametrize("offset", [-1e-7, -3 * DEFAULT_RTOL])
def test_a_root_above_fmax_by_more_than_rtol_is_not_listed(offset):
    result = lm.natural_frequencies(round_cantilever(), count=None, fmax=first_bending_hz() * (1 + offset))
    assert result.frequencies_hz.size == 0


def test_the_margin_is_the_accuracy_asked_for():
    exact = first_bending_hz()
    within = lm.natural_frequencies(round_cantilever(), count=None, fmax=exact * (1 - 5e-7), rtol=1e-6)
    np.testing.assert_allclose(within.frequencies_hz, [exact, exact], rtol=1e-6)


def test_modes_and_scan_up_to_a_root():
    hz = 20.0 / (2 * np.pi)
    modes = lm.mode_shapes(body_on_a_spring(), None, fmax=hz, rigid_body=False)
    np.testing.assert_allclose(modes.omega, [10.0, 20.0, 20.0], rtol=1e-12)
    scan = determinant_scan(body_on_a_spring(), hz, points=50)
    np.testing.assert_allclose(scan.roots, [10.0, 20.0, 20.0], rtol=1e-12)
