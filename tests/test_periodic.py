"""Repeated cells carried by powers of the cell matrix (linmstmm.periodic).

The powered carry must give the same determinant as the element-by-element
carry (which the closed-form chain tests in test_extremes.py check on their
own), find exactly the runs a chain has, and step aside where a cell is too
ill-conditioned to power.
"""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from test_extremes import chain_along_x, chain_reference_hz

from linmstmm import periodic
from linmstmm.deduction import Deduction
from linmstmm.elements.frames import SYMPLECTIC_FORM
from linmstmm.solve import natural_frequencies
from linmstmm.topology import build_topology


def deduction_of(model) -> Deduction:
    return Deduction(build_topology(model))


def element_by_element(model) -> Deduction:
    deduction = deduction_of(model)
    deduction._runs = []  # no runs: the carry it replaces
    return deduction


def test_a_uniform_chain_is_one_run_of_its_mass_spring_cell():
    deduction = deduction_of(chain_along_x([1.0] * 40, [1e6] * 40))
    runs = deduction.periodic_runs()
    assert [(len(run.cell), run.repetitions) for run in runs] == [(2, 40)]
    kinds = [deduction.topology.elements[e].kind for e in runs[0].cell]
    assert sorted(kinds) == ["rigid", "spring"]


def test_a_different_mass_splits_the_chain_into_two_runs():
    masses = [1.0] * 40
    masses[20] = 2.0
    runs = deduction_of(chain_along_x(masses, [1e6] * 40)).periodic_runs()
    assert sorted(run.repetitions for run in runs) == [19, 20]


@pytest.mark.parametrize("field", ["mass", "stiffness"])
def test_a_difference_of_1e_12_splits_the_chain(field):
    """Equal means equal to 1e-14 of the quantity itself: a cell 1e-12 off is not the same cell."""
    masses, stiffnesses = [1.0] * 40, [1e6] * 40
    (masses if field == "mass" else stiffnesses)[20] *= 1 + 1e-12
    runs = deduction_of(chain_along_x(masses, stiffnesses)).periodic_runs()
    assert len(runs) == 2


def test_a_chain_far_from_the_origin_is_still_one_run():
    """Cells are compared by differences of positions (lever arms), not by positions: 1e6 m
    away, rounding of the coordinates (1e-10 m) must not split the run."""
    model = chain_along_x([1.0] * 40, [1e6] * 40)
    shift = np.array([1e6 + 0.1, -3e5, 0.0])
    moved = dataclasses.replace(
        model, points={name: x + shift for name, x in model.points.items()},
        rigids=tuple(dataclasses.replace(body, com=body.com + shift) for body in model.rigids))
    runs = deduction_of(moved).periodic_runs()
    assert [(len(run.cell), run.repetitions) for run in runs] == [(2, 40)]


def test_short_chains_have_no_runs():
    n = periodic.MIN_REPETITIONS - 1
    assert deduction_of(chain_along_x([1.0] * n, [1e6] * n)).periodic_runs() == []


@pytest.mark.parametrize("omega", [
    pytest.param(np.array([0.3, 7.0, 150.0, 1999.0]), id="propagating"),
    pytest.param(np.array([2100.0, 3000.0, 2e4]), id="above the cutoff 2√(k/m)"),
    pytest.param(np.array([50 + 40j, 800 + 300j, 1500 + 900j]), id="complex (counting contour)"),
])
def test_powered_carry_equals_the_element_by_element_carry(omega):
    model = chain_along_x([1.0] * 300, [1e6] * 300)
    powered, plain = deduction_of(model), element_by_element(model)
    assert powered.periodic_runs()
    sign, log_abs = powered.log_det(omega)
    sign_ref, log_ref = plain.log_det(omega)
    assert np.all(np.isfinite(log_abs)) and np.all(np.isfinite(log_ref))
    np.testing.assert_allclose(sign, sign_ref, atol=1e-8)
    np.testing.assert_allclose(log_abs, log_ref, atol=1e-8)


def test_a_cell_too_ill_conditioned_to_power_is_refused():
    """m ω² / k = 1e7 per cell: growing and decaying solutions mix at once."""
    model = chain_along_x([1e3] * 20, [1.0] * 20)
    deduction = deduction_of(model)
    run, = deduction.periodic_runs()
    omega = np.array([100.0])
    cell = deduction._cell_matrix(run, omega)
    assert periodic.pairing_growth(cell)[0] > periodic.PAIRING_LIMIT
    assert periodic.carry_run(cell, run.repetitions, np.eye(12, 6)[None], lambda m: m) is None
    np.testing.assert_allclose(deduction.log_det(omega)[1], element_by_element(model).log_det(omega)[1],
                               rtol=1e-12)


def test_pairing_growth_is_one_for_a_stretch_and_large_where_solutions_mix():
    stretch = np.eye(12)
    stretch[:6, :6] *= 1e3  # displacements ×λ, forces ×1/λ: symplectic, nothing to lose
    stretch[6:, 6:] /= 1e3
    assert np.allclose(stretch.T @ SYMPLECTIC_FORM @ stretch, SYMPLECTIC_FORM)
    rotation = np.eye(12)  # 45° in the (x, Qx) plane: det 1 there, so symplectic
    rotation[np.ix_([0, 9], [0, 9])] = np.array([[1.0, 1.0], [-1.0, 1.0]]) / np.sqrt(2)
    mixed = rotation @ stretch @ rotation.T  # the stretch along mixed directions
    assert np.allclose(mixed.T @ SYMPLECTIC_FORM @ mixed, SYMPLECTIC_FORM)
    growth = periodic.pairing_growth(np.stack([np.eye(12), stretch, mixed]))
    np.testing.assert_allclose(growth[:2], [1.0, 1.0])
    assert growth[2] > 1e5


def test_chain_with_a_heavier_middle_mass_against_its_k_and_m():
    """Two runs and the odd cell between them: frequencies from the 1-D K, M in mpmath."""
    masses, stiffnesses = [1.0] * 60, [1e6] * 60
    masses[30] = 5.0
    reference = np.repeat(chain_reference_hz(masses, stiffnesses), 3)[:9]
    got = natural_frequencies(chain_along_x(masses, stiffnesses), count=9)
    np.testing.assert_allclose(got.frequencies_hz, reference, rtol=1e-9)


def test_streaks_count_consecutive_repeats_as_a_loop_does():
    """The consecutive-repeat counts of find_runs, computed at once, against the loop
    they replace, on random patterns of every density (and none)."""
    from linmstmm.periodic import _streaks

    rng = np.random.default_rng(3)
    for size in (0, 1, 2, 7, 300):
        for density in (0.0, 0.2, 0.5, 0.9, 1.0):
            good = rng.random(size) < density
            looped = np.zeros(size + 1, dtype=int)
            for j in range(size - 1, -1, -1):
                looped[j] = looped[j + 1] + 1 if good[j] else 0
            assert np.array_equal(_streaks(good, size + 1), looped)
