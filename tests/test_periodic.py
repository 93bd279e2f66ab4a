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
from linmstmm.builders import fixed, make_rigid, make_spring
from linmstmm.deduction import Deduction
from linmstmm.elements.frames import SYMPLECTIC_FORM
from linmstmm.model import Model
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


def sequence_model(letters: str, name: str):
    """A grounded line of elements, one per letter: springs A (k = 1e6) and B (3e6), rigid
    bodies X (1 kg) and Y (2 kg) 1 m long, each after the one before; a tip body ends it."""
    points, rigids, springs, x = {"p0": np.zeros(3)}, [], [], 0.0
    for i, letter in enumerate(letters + ("X" if letters[-1] in "AB" else "")):
        a, b = f"p{i}", f"p{i + 1}"
        if letter in "XY":
            x += 1.0
            points[b] = np.array([x, 0.0, 0.0])
            rigids.append(make_rigid(f"r{i}", (a, b), 1.0 if letter == "X" else 2.0, (x - 0.5, 0.0, 0.0),
                                     (0.1, 0.1, 0.1)))
        else:
            points[b] = np.array([x, 0.0, 0.0])
            springs.append(make_spring(f"s{i}", a, b, [1e6 if letter == "A" else 3e6] * 6))
    return Model(name, points, rigids=tuple(rigids), springs=tuple(springs), boundary={"p0": fixed()})


def runs_position_by_position(topology) -> list:
    """The greedy choice of find_runs written out plainly: at each position of the carry
    order, every cell length and its repetitions counted one element at a time; the run
    covering the most elements (the shortest cell among equals) taken, else the next position."""
    order, elements = topology.order, topology.elements
    ordered = [elements[e] for e in order]
    chained = [el.kind != "beam" and len(el.inputs) == 1 and not (el.kind == "spring" and el.record.released.size)
               for el in ordered]
    follows = [i > 0 and el.ports[el.inputs[0]].link[:2] == ("element", order[i - 1]) for i, el in enumerate(ordered)]
    values, scales = periodic.signatures(ordered, np.array(chained))

    def same(i, j):  # element j repeats element i, chained after its predecessor
        tolerance = periodic.SAME * np.maximum(scales[i], scales[j])
        return bool(np.all(np.abs(values[i] - values[j]) <= tolerance)) and chained[j] and follows[j]

    runs, i = [], 0
    while i < len(order):
        best = None
        for period in range(1, min(periodic.MAX_PERIOD, len(order) - 1) + 1):
            if i + period > len(order) or not all(chained[i:i + period]) or not all(follows[i + 1:i + period]):
                continue
            streak = 0
            while i + streak + period < len(order) and same(i + streak, i + streak + period):
                streak += 1
            repetitions = 1 + streak // period
            if repetitions >= periodic.MIN_REPETITIONS and (best is None or repetitions * period
                                                            > best.repetitions * len(best.cell)):
                best = periodic.Run(i, tuple(order[i:i + period]), repetitions)
        if best is None:
            i += 1
        else:
            runs.append(best)
            i = best.stop
    return runs


def test_runs_are_the_plain_greedy_choice_on_mixed_lines():
    """find_runs (the cover of every position computed at once) against the choice made
    position by position, on 120 random lines of repeated cells of 1 to 4 elements."""
    rng = np.random.default_rng(5)
    with_runs = 0
    for t in range(120):
        letters = "A" + "".join("".join(rng.choice(list("AXBY"), size=int(rng.integers(1, 5))))
                                * int(rng.integers(1, 20)) for _ in range(int(rng.integers(1, 4))))
        letters = "".join(c for i, c in enumerate(letters) if i == 0 or not (c in "AB" and letters[i - 1] in "AB"))
        topology = build_topology(sequence_model(letters, f"line {t}"))
        expected = runs_position_by_position(topology)
        assert periodic.find_runs(topology) == expected
        with_runs += bool(expected)
    assert with_runs > 60
