"""The compiled count on the sparse D(ω) (LDLᵀ without pivoting in a minimum-degree
order, the dense Bunch–Kaufman count where that is not sure) against the dense
count and against eigenvalues.

References:

* a dense LDLᵀ without pivoting written out in numpy, in the plan's order, for
  the kernel's factorisation (the same numbers, refusals included);
* the minimum-degree order and joins derived in numpy, every degree counted
  afresh (:func:`reference_minimum_degree`), for the compiled order;
* the plan's slots and updates derived in numpy from the minimum-degree order
  (:func:`reference_plan`), for the compiled plan, array for array, and so the
  beams' slots and the springs' and bodies' terms there, and the patterns of
  D(ω) (numpy's masks and products) for the compiled ones;
* LAPACK's symmetric eigenvalues (dsyevd) for every count decided;
* the dense count (:func:`linmstmm._stiffness_kernels.count`, LAPACK's dsytrf,
  itself compared with the numpy reference in test_wittrick_williams.py) at
  frequencies beside natural frequencies, beside the beams' clamped–clamped
  frequencies and between them, on the bundled launchers and random models.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg as la

from linmstmm import _stiffness_kernels as kernels
from linmstmm.dynamic_stiffness import BeamTable, clamped_counts
from linmstmm.fe import fe_frequencies
from linmstmm.model import load_model
from linmstmm._ordering_kernels import count_patterns, minimum_degree, pattern_with_beams, slot_terms
from linmstmm.ordered_ldlt import elimination_plan
from linmstmm.dense_inertia import block_inertia
from linmstmm.wittrick_williams import MOST_GROWTH, SINGULAR_PIVOT, ModeCounter, _plan_of
from random_models import KINDS, random_model

LAUNCHERS = ("models/mlrs/mlrs.toml", "models/launcher2/launcher2.toml")
#: Relative offsets from natural and clamped–clamped frequencies counted at.
OFFSETS = np.array([-1e-5, -1e-7, -1e-9, -1e-11, -1e-12, 0.0, 1e-12, 1e-11, 1e-9, 1e-7, 1e-5])


def reference_inertia(matrix, order, singular, most_growth):
    """Negative eigenvalues of the symmetric ``matrix`` by LDLᵀ without pivoting in
    ``order`` (dense), −1 where a pivot is below ``singular`` or an entry of
    diag(|L| |D| |L|ᵀ) above ``most_growth``."""
    work = matrix[np.ix_(order, order)].copy()
    growth = np.zeros(len(order))
    negatives = 0
    for k in range(len(order)):
        pivot = work[k, k]
        growth[k] += abs(pivot)
        if abs(pivot) < singular or growth[k] > most_growth:
            return -1
        negatives += pivot < 0
        column = work[k + 1:, k]
        multipliers = column / pivot
        growth[k + 1:] += np.abs(column * multipliers)
        work[k + 1:, k + 1:] -= np.outer(multipliers, column)
    return negatives


def reference_minimum_degree(pattern):
    """(order, joined) of minimum-degree elimination in numpy, every degree counted
    afresh: at each step the unknown joined to the fewest others left (the lowest
    index among equals) is eliminated, and the others it was joined to are joined."""
    n = len(pattern)
    live = pattern & ~np.eye(n, dtype=bool)
    left = np.ones(n, bool)
    order, joined = [], np.zeros((n, n), np.int64)
    for _ in range(n):
        k = int(np.argmin(np.where(left, live.sum(axis=1), n + 1)))
        near = np.flatnonzero(live[k])
        order.append(k)
        joined[k, near] = 1
        left[k] = False
        live[k, :] = live[:, k] = False
        live[np.ix_(near, near)] = True
        live[near, near] = False
    return np.array(order, np.int64), joined


def patterns_to_plan(seed: int, densities: tuple) -> list:
    """Random patterns of 1 to 120 unknowns at each of ``densities``, and the launchers' counters'."""
    rng = np.random.default_rng(seed)
    patterns = [random_sparse(rng, n, density)[1] for n in (1, 2, 5, 20, 60, 120) for density in densities]
    for path in LAUNCHERS:
        counter = ModeCounter(load_model(path), "compiled")
        patterns.append((counter._static != 0) | (counter._mass != 0) | np.eye(counter.n_dof, dtype=bool))
    return patterns


def test_minimum_degree_is_the_numpy_derivation():
    for pattern in patterns_to_plan(5, (0.02, 0.1, 0.5)):
        for ours, theirs in zip(minimum_degree(pattern.astype(np.int64)), reference_minimum_degree(pattern)):
            assert ours.dtype == np.int64 and np.array_equal(ours, theirs)


def test_count_patterns_are_the_numpy_derivation():
    """Where D(ω) may be nonzero, compiled, against numpy's masks and products of them,
    on the launchers' counters and on random maps with zeros, ±0.0 and tiny entries."""
    rng = np.random.default_rng(8)
    cases = []
    for path in LAUNCHERS:
        counter = ModeCounter(load_model(path), "compiled")
        cases.append((counter._static, counter._mass, counter._maps))
    for n_beams, k in ((1, 3), (4, 9), (3, 14)):
        maps = rng.standard_normal((n_beams, 12, k)) * (rng.random((n_beams, 12, k)) < 0.3)
        maps[0, 0, 0], maps[-1, -1, -1] = -0.0, 1e-300
        static = np.where(rng.random((k, k)) < 0.2, rng.standard_normal((k, k)), 0.0)
        mass = np.where(rng.random((k, k)) < 0.1, rng.standard_normal((k, k)), -0.0)
        cases.append((static, mass, maps))
    local = kernels.LOCAL_PATTERN
    for static, mass, maps in cases:
        pattern, beam_pattern = count_patterns(static, mass, maps, local)
        reach = np.abs(maps) > 0
        assert np.array_equal(pattern, (static != 0) | (mass != 0))
        assert np.array_equal(beam_pattern, np.swapaxes(reach, 1, 2).astype(float) @ local @ reach > 0)


def reference_plan(pattern):
    """(starts, rows, high, low, updates, targets) of the elimination plan of ``pattern``
    derived in numpy from its minimum-degree order: slots step by step (the diagonal,
    then each later step joined to it), and for each step every pair of its
    off-diagonal slots (s, t), t <= s, the slot of their rows' entry."""
    order, joined = minimum_degree(pattern.astype(np.int64))
    n = order.size
    steps, rows = np.nonzero((joined[np.ix_(order, order)] > 0) | np.eye(n, dtype=bool))
    starts = np.searchsorted(steps, np.arange(n + 1))
    lookup = np.full((n, n), -1)
    lookup[rows, steps] = np.arange(rows.size)
    off = np.flatnonzero(rows != steps)
    pairs = off - starts[steps[off]]
    a = np.repeat(off, pairs)
    b = np.repeat(starts[steps[off]] + 1, pairs) + np.arange(a.size) - np.repeat(np.cumsum(pairs) - pairs, pairs)
    updates = np.concatenate([[0], np.cumsum(np.bincount(steps[off], weights=pairs, minlength=n))])
    first, second = order[rows], order[steps]
    return starts, rows, np.maximum(first, second), np.minimum(first, second), updates, lookup[rows[a], rows[b]]


def test_compiled_plan_is_the_numpy_derivation():
    for pattern in patterns_to_plan(11, (0.02, 0.2, 0.9)):
        plan = elimination_plan(pattern)
        ours = (plan.starts, plan.rows, plan.high, plan.low, plan.updates, plan.targets)
        for mine, theirs in zip(ours, reference_plan(pattern)):
            assert mine.dtype == np.int64 and np.array_equal(mine, theirs)


def reference_beam_slots(pattern, beam_pattern, columns):
    """(the pattern planned, beam_slots) of :func:`linmstmm.wittrick_williams._plan_of`
    derived in numpy: each beam's reached entries added to ``pattern`` (symmetric), and
    each one's slot in the plan of that pattern (+ slots in the upper triangle)."""
    n = pattern.shape[0]
    i, j = np.broadcast_arrays(columns[:, :, None], columns[:, None, :])
    present = beam_pattern & (i < n) & (j < n)
    joined = pattern.copy()
    joined[i[present], j[present]] = True
    joined |= joined.T
    plan = elimination_plan(joined)
    lookup = np.full((n, n), -1)
    lookup[plan.high, plan.low] = np.arange(plan.high.size)
    placed = np.where(present, lookup[np.maximum(i, j).clip(max=n - 1), np.minimum(i, j).clip(max=n - 1)], -1)
    return joined, np.where(present & (i < j), placed + plan.high.size, placed)


def test_beams_slots_are_the_numpy_derivation():
    for path in LAUNCHERS + tuple(random_model(kind, 0) for kind in KINDS):
        counter = ModeCounter(load_model(path) if isinstance(path, str) else path, "compiled")
        pattern = (counter._static != 0) | (counter._mass != 0)
        reach = np.abs(counter._maps) > 0
        beam_pattern = np.swapaxes(reach, 1, 2).astype(float) @ kernels.LOCAL_PATTERN @ reach > 0
        joined, slots = reference_beam_slots(pattern, beam_pattern, counter._columns)
        assert np.array_equal(pattern_with_beams(pattern, beam_pattern, counter._columns), joined)
        plan, placed = _plan_of(pattern, beam_pattern, counter._columns)
        assert np.array_equal(placed, slots)
        planned = elimination_plan(joined)
        assert all(np.array_equal(getattr(plan, field), getattr(planned, field)) for field in planned.__dataclass_fields__)
        static, mass, high, low = counter._static, counter._mass, plan.high, plan.low
        assert np.array_equal(slot_terms(static, mass, high, low), np.stack([
            static[high, low], mass[high, low], np.where(high > low, static[low, high], 0.0),
            np.where(high > low, mass[low, high], 0.0)]))


def random_sparse(rng, n, density):
    """(n, n) symmetric matrix with a random pattern (a chain joining all, and
    ``density`` of the other entries), indefinite, and that pattern."""
    pattern = rng.random((n, n)) < density
    pattern |= np.eye(n, k=1, dtype=bool)
    pattern |= pattern.T | np.eye(n, dtype=bool)
    matrix = np.where(pattern, rng.standard_normal((n, n)), 0.0)
    matrix = (matrix + matrix.T) / 2
    return matrix + np.diag(rng.choice([-3.0, 3.0], n)), pattern


def slots_of(matrix, plan):
    """The lower triangle of ``matrix`` on the slots of ``plan``."""
    return matrix[plan.high, plan.low].copy()


@pytest.mark.parametrize("seed", range(6))
def test_ordered_inertia_mirrors_the_dense_reference_and_counts_the_eigenvalues(seed):
    rng = np.random.default_rng(seed)
    decided = refused = 0
    for n in (1, 5, 20, 60):
        matrix, pattern = random_sparse(rng, n, 3.0 / n)
        plan = elimination_plan(pattern)
        for shift in np.linspace(-4.0, 4.0, 17):
            shifted = matrix - shift * np.eye(n)
            for most_growth in (1e2, 1e9):
                found = kernels.ordered_inertia(slots_of(shifted, plan), plan.starts, plan.rows, plan.updates,
                                                plan.targets, 1e-12, most_growth, np.empty(n))
                assert found == reference_inertia(shifted, plan.order, 1e-12, most_growth)
                if found >= 0:
                    assert found == np.sum(np.linalg.eigvalsh(shifted) < 0)
                decided += found >= 0
                refused += found < 0
    assert decided > 0 and refused > 0  # both ways taken


def test_a_zero_leading_pivot_is_refused():
    matrix = np.array([[0.0, 1.0], [1.0, 0.0]])  # eigenvalues ±1: no 1 × 1 pivot in any order
    plan = elimination_plan(matrix != 0)
    assert kernels.ordered_inertia(slots_of(matrix, plan), plan.starts, plan.rows, plan.updates, plan.targets,
                                   1e-12, 1e2, np.empty(2)) == -1


def test_growth_is_refused_where_it_would_give_a_wrong_count():
    """A first pivot of 1.2e-11 (above the rounding level 1e-12) multiplies the
    rounding of what follows by about 1e11: without the growth bound the
    factorisation counts 2 negative eigenvalues, both shifted ways alike, where
    there is one (the smallest is 1.0e-7, far from the rounding level); with it,
    the count is refused and left to Bunch–Kaufman, which counts 1."""
    lower = np.tril([[1.2044960527902208e-11, 0, 0, 0],
                     [0.4135393632944674, 0.014893160655449888, 0, 0],
                     [0.4633272362319223, 0.04453662389456185, 0.36731674307196055, 0],
                     [-0.7185884611232655, 0.01512222084124585, 0.37731919824765775, 0.4862827725099736]])
    matrix = lower + np.tril(lower, -1).T
    assert np.sum(np.linalg.eigvalsh(matrix) < 0) == 1
    assert np.min(np.abs(np.linalg.eigvalsh(matrix))) > 1e-8
    plan = elimination_plan(np.ones((4, 4), dtype=bool))
    assert plan.order[0] == 0  # the tiny pivot first
    singular = 1e-12 * np.abs(matrix).max()

    def counted(most_growth):
        return [kernels.ordered_inertia(slots_of(matrix + sign * singular * np.eye(4), plan), plan.starts, plan.rows,
                                        plan.updates, plan.targets, singular, most_growth, np.empty(4))
                for sign in (1, -1)]

    assert counted(1e300) == [2, 2]
    assert counted(MOST_GROWTH * np.abs(matrix).max()) == [-1, -1]
    factor, pivots, info = la.lapack.dsytrf(matrix, lower=1)
    assert info == 0 and block_inertia(factor, pivots, singular) == 1


def test_the_plan_eliminates_the_launcher_with_little_fill():
    """The fill-reducing order keeps L of the launcher's 72 unknowns (684 nonzeros in
    D) to 398 entries, diagonal included, against the dense factorisation's 2,628."""
    counter = ModeCounter(load_model(LAUNCHERS[0]), "compiled")
    plan, terms = counter._plan
    assert sorted(plan[0]) == list(range(counter.n_dof))
    assert terms.shape[1] < counter.n_dof * (counter.n_dof + 1) // 2 / 4


def clamped_frequencies(beams: BeamTable) -> np.ndarray:
    """rad/s: each beam's first two clamped–clamped bending frequencies in both planes,
    and its first axial and torsional ones where those directions are deformable."""
    first_two = np.array([4.730040744862704, 7.853204624095838])  # cos λ cosh λ = 1
    found = []
    for b in range(beams.L.size):
        for stiffness in (beams.EIy[b], beams.EIz[b]):
            found.extend((first_two / beams.L[b]) ** 2 * math.sqrt(stiffness / beams.rhoA[b]))
        if beams.axial[b]:
            found.append(math.pi / beams.L[b] * math.sqrt(beams.EA[b] / beams.rhoA[b]))
        if beams.torsion[b]:
            found.append(math.pi / beams.L[b] * math.sqrt(beams.GJ[b] / beams.rhoIp[b]))
    return np.array(found)


def counted_frequencies(model) -> np.ndarray:
    """rad/s beside the first 12 natural frequencies (the FE route's) and the beams'
    clamped–clamped ones, and 60 between."""
    natural = 2 * np.pi * np.asarray(fe_frequencies(model, count=12, rtol=1e-8).frequencies_hz)
    natural = natural[natural > 0]
    near = np.concatenate([natural, clamped_frequencies(BeamTable.of(model.beams))])
    return np.concatenate([np.outer(near, 1 + OFFSETS).ravel(), np.geomspace(natural[0] / 3, natural[-1] * 1.2, 60)])


def eigenvalue_count(counter: ModeCounter, omega: float) -> int:
    """J(ω) from the eigenvalues of the equilibrated D(ω) (LAPACK dsyevd)."""
    matrix, magnitude = (part[0] for part in counter.matrices([omega]))
    weights = 1.0 / np.sqrt(magnitude.diagonal())
    equilibrated = matrix * weights[:, None] * weights[None, :]
    return clamped_counts(counter._beams, omega) + int(np.sum(np.linalg.eigvalsh(equilibrated) < 0))


def dense_count(counter: ModeCounter, omega: float) -> int | None:
    """J(ω) by the dense kernel alone (LAPACK's dsytrf)."""
    matrix, magnitude, work, _ = counter._new_scratch()
    found = kernels.count(omega, counter._beam_table(), counter._maps, counter._columns, counter._static,
                          counter._mass, SINGULAR_PIVOT, matrix, magnitude, work)
    return None if found < 0 else found


@pytest.mark.parametrize("source", [*LAUNCHERS, *((kind, seed) for kind in KINDS for seed in range(3))])
def test_sparse_count_is_the_dense_count_wherever_that_decides(source):
    """Every count the dense factorisation decides is the sparse one's; none it
    decides is left undecided (the sparse count falls back on it where unsure);
    where only the sparse one decides, its count is the eigenvalues'. Of the 5,970
    counts on these 17 models, 3,704 are decided by both, 2,256 by neither (most
    within 1e-11 of a natural or clamped frequency) and 10 by the sparse one only.
    235 are left to the dense factorisation; 2,201 the sparse one leaves undecided
    itself, its two shifted factorisations sure and their counts apart, where the
    dense one's differ too (before, those went to it as well: 1,206 dense counts)."""
    model = load_model(source) if isinstance(source, str) else random_model(*source)
    counter = ModeCounter(model, "compiled")
    same = 0
    for omega in counted_frequencies(model):
        dense, sparse = dense_count(counter, omega), counter(omega)
        if dense is not None:
            assert sparse == dense, (omega, dense, sparse)
            same += 1
        elif sparse is not None:
            assert sparse == eigenvalue_count(counter, omega), omega
    assert same > 0


@pytest.mark.parametrize("source", LAUNCHERS)
def test_a_plan_kept_for_a_pattern_is_the_plan_made_anew(source):
    """A parameter study's counters share the elimination plan of their pattern
    (wittrick_williams._planned): the counter of an edited launcher (its first
    body 30 % heavier, the same pattern) takes the plan and the terms a fresh
    plan gives, array for array; a counter whose pattern differs gets a plan of its own."""
    from linmstmm.parameters import parse_key, with_values
    from linmstmm.wittrick_williams import _plans, sparse_plan

    model = load_model(source)
    first = ModeCounter(model, "compiled")
    rigid = model.rigids[0].name
    edited = with_values(model, {parse_key(model, f"rigid.{rigid}.mass"): model.rigids[0].mass * 1.3})
    kept = ModeCounter(edited, "compiled")
    assert len(_plans) >= 1 and kept._plan[0][0] is first._plan[0][0]  # the same plan object
    _plans.clear()
    fresh = sparse_plan(kept._static, kept._mass, kept._maps, kept._columns)
    for a, b in zip(kept._plan[0], fresh[0]):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(kept._plan[1], fresh[1])
    other = ModeCounter(random_model(KINDS[0], 3), "compiled")
    assert other._plan[0][0] is not kept._plan[0][0]
