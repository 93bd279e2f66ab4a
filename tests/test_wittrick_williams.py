"""The exact dynamic stiffness of a beam and the Wittrick–Williams count J(ω).

References independent of the transfer matrices:

* the FE route's Hermite element: D(ω) = K − ω² M_consistent + O(ω⁴), and a
  fine FE mesh condensed onto the beam's ends converges on D(ω) at any ω;
* the clamped–clamped frequency equations cos λ cosh λ = 1 and sin kL = 0;
* the FE route's frequencies: J(ω) between two of them is the number below.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg as la
from scipy.optimize import brentq

from builders import fixed, make_rigid, make_spring, single_beam_model
from linmstmm import _stiffness_kernels as kernels
from linmstmm.dynamic_stiffness import BeamTable, clamped_counts, dynamic_stiffness
from linmstmm.fe import assemble, fe_frequencies
from linmstmm.fe.elements import beam_element
from linmstmm.model import Model, load_model
from linmstmm.solve import natural_frequencies
from linmstmm.dense_inertia import block_inertia
from linmstmm.wittrick_williams import MAX_ORDER, ModeCounter, mode_counter
from random_models import KINDS, random_model
from test_sparse_count import dense_count
from varied_models import in_units, varied_model

BUNDLED = ("models/mlrs/mlrs.toml", "models/launcher2/launcher2.toml", "models/cantilever_tip_mass.toml",
           "models/spring_mass_chain.toml")


def _beam(**options):
    options = {"A": 1e-3, "Iy": 2e-7, "Iz": 5e-7, "J": 6e-7, "Ip": 7e-7, "length": 2.0} | options
    return single_beam_model(**options).beams[0]


@pytest.mark.parametrize("options", [{}, {"axial": False}, {"torsion": False}])
def test_static_part_is_the_hermite_stiffness_and_the_next_term_the_consistent_mass(options):
    beam = _beam(**options)
    g, d, m, c = beam_element(beam, beam.length)
    stiffness = (g.T * d) @ g
    # directions declared rigid keep only their inertia: their stiffness rows are constraints
    for row in c:
        free = row != 0
        stiffness[np.ix_(free, free)] = 0.0
    table = BeamTable.of((beam,))
    errors = []
    for omega in (2.0, 1.0):  # λ ≈ 0.15 and 0.1 in the softer plane
        dynamic = dynamic_stiffness(table, omega)[0]
        errors.append(np.abs((dynamic - stiffness) / omega ** 2 + m).max() / np.abs(m).max())
    assert errors[1] < 1e-5
    assert errors[1] / errors[0] == pytest.approx(0.25, abs=0.02)  # the next term is O(ω⁴)


def _condensed_fine_mesh(beam, omega, elements):
    """(12, 12) dynamic stiffness of ``beam`` on its two ends by a fine FE mesh."""
    model = single_beam_model(A=beam.A, Iy=beam.Iy, Iz=beam.Iz, J=beam.J, Ip=beam.Ip, length=beam.length)
    fe = assemble(model, elements)
    dynamic = (fe.K - omega ** 2 * fe.M).toarray()
    ends = np.concatenate([fe.dof_index.point("a"), fe.dof_index.point("b")])
    columns = np.array([np.flatnonzero(fe.T[:, j].toarray())[0] for j in range(fe.n_dof)])
    keep = np.flatnonzero(np.isin(columns, ends))
    inner = np.setdiff1d(np.arange(fe.n_dof), keep)
    schur = dynamic[np.ix_(keep, keep)] - dynamic[np.ix_(keep, inner)] @ la.solve(
        dynamic[np.ix_(inner, inner)], dynamic[np.ix_(inner, keep)])
    order = np.argsort(columns[keep])
    return schur[np.ix_(order, order)]


@pytest.mark.parametrize("omega", [800.0, 3000.0])  # between the first and second clamped modes, and above
def test_equals_a_fine_mesh_condensed_onto_the_ends(omega):
    beam = _beam()
    exact = dynamic_stiffness(BeamTable.of((beam,)), omega)[0]
    coarse, fine = (_condensed_fine_mesh(beam, omega, n) for n in (64, 128))
    scale = np.abs(exact).max(axis=1)
    error = lambda mesh: np.abs(mesh - exact).max(axis=1) / scale  # noqa: E731
    # linear rod elements converge as h²: the finer mesh is four times closer
    assert np.all(error(fine) < 1e-4)
    assert error(fine).max() < 0.3 * error(coarse).max()


def test_clamped_counts_follow_the_frequency_equations():
    # bending alone (axial and torsion rigid), both planes alike: each root of
    # cos λ cosh λ = 1 is two clamped modes
    bending = _beam(length=1.5, Iy=3e-7, Iz=3e-7, axial=False, torsion=False)
    table = BeamTable.of((bending,))
    for k in range(1, 8):
        lam = brentq(lambda x: math.cos(x) * math.cosh(x) - 1, (k + 0.5) * math.pi - 0.5, (k + 0.5) * math.pi + 0.5)
        omega = (lam / bending.length) ** 2 * math.sqrt(bending.E * bending.Iy / (bending.rho * bending.A))
        assert clamped_counts(table, omega * (1 - 1e-7)) == 2 * (k - 1)
        assert clamped_counts(table, omega * (1 + 1e-7)) == 2 * k
        assert clamped_counts(table, omega) is None            # a pole of D: left undecided
        assert clamped_counts(table, omega, at_least=True) == 2 * (k - 1)   # or counted from below
    # a rod's clamped modes at kL = nπ: the n-th axial one adds one to the count
    beam = _beam(length=1.5)
    stiff_only = BeamTable.of((_beam(length=1.5, axial=False),))
    for n in (1, 2):
        omega = n * math.pi / beam.length * math.sqrt(beam.E / beam.rho)
        below, above = omega * (1 - 1e-7), omega * (1 + 1e-7)
        table = BeamTable.of((beam,))
        assert clamped_counts(stiff_only, above) == clamped_counts(stiff_only, below)
        assert clamped_counts(table, above) - clamped_counts(table, below) == 1
        assert clamped_counts(table, above) - clamped_counts(stiff_only, above) == n


def _midpoints(frequencies_hz):
    """rad/s between the distinct ``frequencies_hz`` (and below the first), geometric;
    values within 1e-6 of each other are one (multiple) frequency."""
    omegas = np.sort(2 * np.pi * np.asarray(frequencies_hz))
    distinct = omegas[np.concatenate([[True], np.diff(omegas) > 1e-6 * omegas[1:]])]
    return np.concatenate([[distinct[0] / 2], np.sqrt(distinct[:-1] * distinct[1:])])


def _assert_counts_fe(model, count=12, engines=("numpy", "compiled")):
    fe = fe_frequencies(model, count=count, rtol=1e-8)
    omegas = 2 * np.pi * np.asarray(fe.frequencies_hz)
    counters = [ModeCounter(model, engine) for engine in engines]
    decided = 0
    for omega in _midpoints(fe.frequencies_hz):
        expected = fe.rigid_body_modes + int(np.sum(omegas < omega))
        answers = [counter(omega) for counter in counters]
        assert len(set(answers)) == 1, f"engines disagree at {omega} rad/s: {answers}"
        assert answers[0] in (None, expected), f"J({omega}) = {answers[0]}, FE says {expected}"
        decided += answers[0] is not None
    return decided


@pytest.mark.parametrize("path", BUNDLED)
def test_counts_the_fe_frequencies_of_the_bundled_models(path):
    model = load_model(path)
    assert _assert_counts_fe(model, count=30) == len(_midpoints(fe_frequencies(model, count=30).frequencies_hz))


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("seed", range(3))
def test_counts_the_fe_frequencies_of_random_models(kind, seed):
    assert _assert_counts_fe(random_model(kind, seed)) > 0


@pytest.mark.parametrize("seed", [1, 3, 5, 10, 23, 50, 77])
def test_varied_models_counted_right_or_left_undecided(seed):
    """Slender strips with bending planes 1e12 apart, massless dangling points and
    other units: the count is the FE route's or None, never another number."""
    _assert_counts_fe(varied_model(seed)[0])


@pytest.mark.parametrize("length, mass", [(1e3, 1e-3), (1e-3, 1.0), (1.0, 1e3)])
def test_count_does_not_depend_on_the_units(length, mass):
    model = random_model("loops", 2)
    scaled = in_units(model, length, mass)
    points = _midpoints(fe_frequencies(model, count=10).frequencies_hz)
    assert [ModeCounter(model)(w) for w in points] == [ModeCounter(scaled)(w) for w in points]


def test_free_free_beam_counts_its_six_rigid_body_modes():
    model = single_beam_model(Iy=2e-7, Iz=5e-7)
    counter = ModeCounter(model)
    first = fe_frequencies(model, count=1).frequencies_hz[0] * 2 * np.pi
    assert counter(first / 2) == 6
    assert counter(first * 1.01) == 7


def _pivot_sizes(factor, pivots) -> list[float]:
    """|eigenvalue| of each 1 × 1 pivot and 2 × 2 block of sytrf's D, block by block."""
    sizes, k = [], 0
    while k < len(pivots):
        width = 1 if pivots[k] > 0 else 2
        sizes += list(abs(la.eigvalsh(factor[k:k + width, k:k + width], lower=True)))
        k += width
    return sizes


def test_block_inertia_kernel_mirrors_the_reference():
    rng = np.random.default_rng(7)
    blocks = 0
    for zero_diagonal in (False, True):  # zero: Bunch–Kaufman takes 2 × 2 blocks, runs of them side by side
        for n in (2, 5, 12, 40) if zero_diagonal else (1, 2, 5, 12, 40):
            matrix = rng.standard_normal((n, n))
            matrix = matrix + matrix.T
            if zero_diagonal:
                np.fill_diagonal(matrix, 0.0)
            factor, pivots, info = la.lapack.dsytrf(matrix, lower=1)
            assert info == 0
            blocks += int(np.sum(pivots < 0)) // 2
            reference = block_inertia(factor, pivots, 1e-11)
            assert kernels.block_inertia(factor, pivots, 1e-11) == reference == int(np.sum(la.eigvalsh(matrix) < 0))
            # a threshold above the smallest pivot or block eigenvalue: undecided in both
            threshold = 1.01 * min(_pivot_sizes(factor, pivots))
            assert block_inertia(factor, pivots, threshold) is None
            assert kernels.block_inertia(factor, pivots, threshold) == -1
    assert blocks > 20  # 2 × 2 blocks were exercised


def test_clamped_pivots_leave_the_count_undecided():
    model = single_beam_model(left=fixed(), right=fixed(), axial=False, torsion=False, Iy=3e-7, Iz=3e-7)
    beam = model.beams[0]
    lam = brentq(lambda x: math.cos(x) * math.cosh(x) - 1, 4.5, 5.0)
    omega = (lam / beam.length) ** 2 * math.sqrt(beam.E * beam.Iy / (beam.rho * beam.A))
    for engine in ("numpy", "compiled"):
        counter = ModeCounter(model, engine)
        assert counter(omega) is None
        assert counter(omega * (1 + 1e-6)) == 2           # both planes' first clamped-clamped mode
        together = ModeCounter(model, engine)             # and so made among others at once
        together.prefetch([omega * (1 - 1e-6), omega, omega * (1 + 1e-6)])
        assert [together(w) for w in (omega * (1 - 1e-6), omega, omega * (1 + 1e-6))] == [0, None, 2]


def test_a_model_too_long_for_a_dense_count_gets_no_counter():
    """A chain of 60 bodies (360 unknowns) is counted by the argument principle: the
    dense factorisation grows as n³ and is made twice per root (a 1,000-body chain
    took 12.8 s instead of 0.13 s); the launcher (72 unknowns) gets one."""
    points = {"ground": np.zeros(3)}
    for i in range(60):  # body i from x = i to i + 1, joined to the next by a spring
        points[f"a{i}"], points[f"b{i}"] = np.array([i, 0.0, 0.0]), np.array([i + 1.0, 0.0, 0.0])
    bodies = tuple(make_rigid(f"m{i}", [f"a{i}", f"b{i}"], 1.0, [i + 0.5, 0.0, 0.0], (0.1, 0.1, 0.1))
                   for i in range(60))
    springs = tuple(make_spring(f"k{i}", "ground" if i == 0 else f"b{i - 1}", f"a{i}", [1e4] * 6)
                    for i in range(60))
    chain = Model("chain", points, rigids=bodies, springs=springs, boundary={"ground": fixed()})
    assert mode_counter(chain) is None
    launcher = mode_counter(load_model("models/mlrs/mlrs.toml"))
    assert launcher is not None and launcher.n_dof <= MAX_ORDER


@pytest.mark.parametrize("kind", KINDS)
def test_compiled_count_mirrors_the_reference_beside_the_roots(kind):
    """Within rounding of a natural frequency, where the count may be left undecided,
    the dense compiled count (one kernel, LAPACK's dsytrf called from it) gives the
    numpy reference's answer, None included (the sparse count the counter makes
    first is compared with it in test_sparse_count.py)."""
    model = random_model(kind, 1)
    omegas = 2 * np.pi * np.asarray(fe_frequencies(model, count=8, rtol=1e-8).frequencies_hz)
    reference, compiled = ModeCounter(model, "numpy"), ModeCounter(model, "compiled")
    near = np.outer(omegas, 1 + np.array([-1e-6, -1e-9, -1e-12, 0.0, 1e-12, 1e-9, 1e-6])).ravel()
    assert [reference(w) for w in near] == [dense_count(compiled, w) for w in near]


def test_twins_of_one_counter_count_side_by_side_on_two_threads():
    """Two searches of the same model at once each count with a fresh twin of its
    compiled counter (the kernel runs without Python's lock): every twin gives the
    counts one thread alone gives (sharing the kernel's buffers, hundreds of 4,000
    differed)."""
    import threading

    launcher = load_model("models/mlrs/mlrs.toml")
    counter = ModeCounter(launcher, "compiled")
    omegas = np.linspace(1.0, 2000.0, 4000)
    alone = [counter.fresh()(w) for w in omegas]
    side_by_side = {}

    def count(thread: int) -> None:
        twin = counter.fresh()
        side_by_side[thread] = [twin(w) for w in omegas]

    for _ in range(3):
        threads = [threading.Thread(target=count, args=(t,)) for t in range(2)]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        assert side_by_side[0] == alone and side_by_side[1] == alone


@pytest.mark.parametrize("engine", ["numpy", "compiled"])
def test_counts_beside_the_roots_of_a_very_flat_section_are_right_or_undecided(engine):
    """varied_model(35) (one section's Iy/Iz 1.5e9): 1e-8 to 1e-5 either side of each of its
    first 12 natural frequencies (the transfer matrix method's, rtol 1e-12) the count is
    the number of them below, or undecided. Its equilibrated D(ω) has an eigenvalue
    at rounding level there (1e-15 of its largest term; an mpmath D(ω) has none
    negative 1e-6 below the second) while no pivot is below 1e-9: without the shifted
    factorisations both engines counted 2 there, and beside its first 10 frequencies
    5 (numpy) and 6 (compiled) counts of 80 were wrong."""
    model = varied_model(35)[0]
    roots = 2 * np.pi * natural_frequencies(model, 12, rtol=1e-12).frequencies_hz
    counter = ModeCounter(model, engine)
    for root in roots[:-1]:
        for offset in (-1e-5, -1e-6, -1e-7, -1e-8, 1e-8, 1e-7, 1e-6, 1e-5):
            omega = root * (1 + offset)
            assert counter(omega) in (int(np.sum(roots < omega)), None), (root, offset)


@pytest.mark.parametrize("engine", ["numpy", "compiled"])
def test_counts_made_together_are_those_made_one_by_one(monkeypatch, engine):
    """prefetch: counts beside the roots of a random model made together, shared among
    threads (each piece with its own buffers), answer as counts made one at a time,
    undecided ones included."""
    from linmstmm import spread

    monkeypatch.setattr(spread, "cores", lambda: 2)
    model = random_model("loops", 1)
    omegas = 2 * np.pi * np.asarray(fe_frequencies(model, count=8, rtol=1e-8).frequencies_hz)
    near = np.outer(omegas, 1 + np.array([-1e-6, -1e-9, -1e-12, 1e-12, 1e-9, 1e-6])).ravel()
    counter = ModeCounter(model, engine)
    together, alone = counter.fresh(), counter.fresh()
    together.prefetch(near)
    assert [together(w) for w in near] == [alone(w) for w in near]
