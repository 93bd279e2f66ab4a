"""How many natural frequencies lie below ω, from one factorisation: the
Wittrick–Williams count.

Wittrick and Williams (1971): for a structure whose dynamic stiffness matrix
D(ω) is exact, the number of natural frequencies below ω (counted with their
multiplicity, zero-frequency modes included) is

    J(ω) = J₀(ω) + s{D(ω)},

where s{D} is the number of negative eigenvalues of D (Sylvester's law of
inertia: the negative pivots of a symmetric LDLᵀ factorisation) and J₀ the
natural frequencies below ω of the elements with their ends clamped
(:func:`linmstmm.dynamic_stiffness.clamped_counts`). It needs no frequency
scan, no contour and no roots: a real symmetric factorisation of the order of
the model's nodes.

D(ω) here is built on the nodes of the FE route with one element per beam
(:func:`linmstmm.fe.assembly.constrained_parts`: the same points, ports,
boundaries, springs, joints and constraint elimination): each beam's exact
dynamic stiffness (:func:`linmstmm.dynamic_stiffness.dynamic_stiffness`)
rotated to the inertial frame, plus the springs' stiffness, minus ω² times the
rigid bodies' mass. No mesh: the count is exact for the same Euler–Bernoulli
model that det Ū_all describes, and independent of the transfer matrices.

The compiled count factorises D(ω) on its sparsity pattern, the same at every
ω, in a minimum-degree order (:mod:`linmstmm.ordered_ldlt`), and leaves to the
dense factorisation the frequencies where its pivots are not safe
(:func:`linmstmm._stiffness_kernels.ordered_count`).

Where float64 cannot decide it (ω within rounding of a natural frequency or of
an element's clamped one, a degree of freedom with neither stiffness nor mass)
the count answers None, and callers count another way.
"""
from __future__ import annotations

import functools

import numpy as np

from linmstmm.counter_parts import counter_parts
from linmstmm.dense_inertia import SINGULAR_PIVOT, negative_eigenvalues
from linmstmm.determinant import resolved_engine
from linmstmm.dynamic_stiffness import BeamTable, clamped_counts_at, dynamic_stiffnesses
from linmstmm.fe.products import (
    congruence,
    dense_product,
    dense_rows,
    rows_scaled,
    transposed,
)
from linmstmm.fe.sparse import compressed_rows
from linmstmm.model import Model
from linmstmm.model_structure import KeptByKey
from linmstmm.spread import spread

#: Largest order of D(ω) counted: its dense factorisation grows as n³ (72 unknowns: 75 µs, 120:
#: 160 µs compiled), and a count is made twice per root; a longer model (a chain of 1,000 bodies:
#: 3,000 unknowns, 12.8 s instead of 0.13 s) is counted by the argument principle. (The compiled
#: count is sparse, but leaves frequencies where its pivots are not safe to the dense one.)
MAX_ORDER = 150

#: Largest order of D(ω) counted for a model above MAX_ORDER, once its search must part roots that
#: det Ū_all and its pencil cannot (:func:`late_counter`): there the counts are made only where a
#: stretch is bisected, not twice per root. Measured where the sparse count leaves D(ω) to the dense
#: one (ω within 1e-5 of a root of clamped beam chains): 15 ms a count at 600 unknowns, 0.1 s at
#: 1,200, 0.3 s at 1,800, 0.7 s at 2,400; and the dense count's undecided width grows with the
#: order (at 1,200 it could not decide within ±1e-7 of a double root, at 2,400 within ±1e-5). An
#: octahedral star of 120 beams (690 unknowns), bending planes 1e-5 apart, took the
#: argument-principle segment search 100-190 s for its ten lowest, and takes 1 s with it.
CLUSTER_ORDER = 1000


#: The compiled count's sparse LDLᵀ without pivoting leaves D(ω) to the dense Bunch–Kaufman
#: factorisation where an entry of diag(|L| |D| |L|ᵀ) is above this times the largest equilibrated
#: term. Below it the factorisation's rounding, of order (entries of a column of L, at most 10 on
#: the launchers) · 1.1e-16 · growth, about 1e-13 at the bound, stays well below SINGULAR_PIVOT, and
#: a count it decides is the inertia the dense factorisation finds. Without the bound a 4 × 4 matrix
#: whose first pivot is 1.2e-11 counts 2 negative eigenvalues where there is 1
#: (tests/test_sparse_count.py).
MOST_GROWTH = 1e2

#: Counts below which a batch stays on the calling thread (:func:`linmstmm.spread.spread`): a
#: compiled count costs about a third of an evaluation of det Ū_all, so handing one to another
#: thread pays three times later. Measured side by side on the launchers (their 20 to 23 counts) and
#: the 18 firing scenes (14 a scene): spread from 8 counts, a solve of the ten lowest took 4.3-4.8
#: and 6.4-7.0 ms and the scenes 125-128 ms; from 24, 3.8 and 5.9 ms and 110 ms, as on one thread.
COUNT_BATCH = 24

#: Frequencies whose D(ω) the numpy engine forms at once (:meth:`ModeCounter.prefetch`): one at a
#: time, forming D(ω) took 176 of the 308 µs of a count on the launcher.
NUMPY_BATCH = 64


@functools.cache
def _stiffness_kernels():
    """:mod:`linmstmm._stiffness_kernels`, imported where a counter is first compiled (numba loads there)."""
    from linmstmm import _stiffness_kernels as kernels

    return kernels


def mode_counter(model: Model, engine: str = "auto", largest: int = MAX_ORDER) -> ModeCounter | None:
    """The :class:`ModeCounter` of ``model``, or None where D(ω) would be larger than
    ``largest`` (:func:`too_large_to_count`, else from the order after the constraints
    are eliminated)."""
    if too_large_to_count(model, largest):
        return None
    counter = ModeCounter(model, engine)
    return counter if counter.n_dof <= largest else None


def late_counter(model: Model, engine: str = "auto"):
    """For a model with no counter at MAX_ORDER: a callable that makes (on its first call,
    then keeps) its :class:`ModeCounter` up to CLUSTER_ORDER, or None where there is
    none (:func:`mode_counter`); None where the model is too large for that for certain.

    The search of such a model polishes its predictions and certifies them by the
    argument principle; it makes this counter only where a stretch of roots is to be
    searched, and then counts with it (:meth:`linmstmm.roots.RootFinder.counter_for_stretch`)."""
    if too_large_to_count(model, CLUSTER_ORDER):
        return None
    return functools.cache(functools.partial(mode_counter, model, engine, CLUSTER_ORDER))


def too_large_to_count(model: Model, largest: int = MAX_ORDER) -> bool:
    """Whether ``model`` has no counter of order ``largest`` or less for certain: over
    4 ``largest`` unknowns before elimination."""
    return 6 * (len(model.points) + len(model.rigids)) > 4 * largest


class ModeCounter:
    """J(ω) of a model: ``counter(omega)`` is the number of natural frequencies
    below ``omega`` (rad/s), zero-frequency modes included, or None where float64
    cannot decide it.

    Parameters
    ----------
    model : Model
        The model (every element kind, joint and boundary the FE route takes).
    engine : str
        "numpy", "compiled" (numba kernels of :mod:`linmstmm._stiffness_kernels`)
        or "auto", as for det Ū_all (:func:`linmstmm.determinant.resolved_engine`).

    Attributes
    ----------
    n_dof : int
        Order of the reduced D(ω) that each count factorises.
    masters : numpy.ndarray, shape (n_dof,)
        Its unknowns as the full DOFs of the one-element mesh (six per point and
        mass centre, :mod:`linmstmm.fe.layout`).
    """

    def __init__(self, model: Model, engine: str = "auto"):
        self.engine = resolved_engine(engine)
        parts = counter_parts(model)  # its elimination kept by the model's structure where it can be
        self.n_dof = parts.T.shape[1]
        self.masters = parts.masters
        self._static, self._mass = _reduced_terms(parts, self.engine)
        self._beams = BeamTable.of(model.beams)
        self._maps, self._columns = _beam_maps(parts, self.engine)
        self._answers: dict[float, int | None] = {}
        self._table = None  # the beams as the compiled kernels take them, on their first call
        self._scratch = None  # this counter's own buffers for the compiled kernel, on its first call
        self._entries = None  # where the beams' terms go in the numpy reference's D(ω), on its first call
        # D(ω)'s sparse factorisation as the compiled kernel takes it, shared with the twins (0.2 ms)
        self._plan = sparse_plan(self._static, self._mass, self._maps, self._columns) if self.engine == "compiled" else None

    def fresh(self) -> ModeCounter:
        """This counter with no answers remembered: the same model's matrices (not
        copied), for a new search to count with afresh (:func:`linmstmm.solve.frequency_finder`).

        The compiled kernel writes D(ω) into buffers of the counter it is called
        for: the twin gets its own, so that searches of the same model on two
        threads at once (each with its own twin) do not write into each other's.
        One counter serves one thread at a time. The beams' table the kernels read
        (never write) is made here once and shared, not again for every twin.
        """
        if self.engine == "compiled":
            self._beam_table()
        twin = object.__new__(type(self))  # a shallow copy, with its own answers and buffers
        twin.__dict__.update(self.__dict__, _answers={}, _scratch=None)
        return twin

    def __call__(self, omega: float) -> int | None:
        omega = float(omega)
        if omega not in self._answers:  # the certifying steps ask at the same ω more than once
            self._count_now([omega])
        return self._answers[omega]

    def at(self, omegas) -> list[int | None]:
        """:meth:`__call__` at each of ``omegas`` (rad/s), those not counted yet counted
        together (:meth:`prefetch`).

        Parameters
        ----------
        omegas : iterable of float
            rad/s.

        Returns
        -------
        list of int or None
            J(ω) at each, None where float64 cannot decide it.
        """
        omegas = [float(omega) for omega in omegas]
        self.prefetch(omegas)
        answers = self._answers
        return [answers[omega] for omega in omegas]

    def _numpy_at(self, omegas) -> list[int | None]:
        """:meth:`__call__` at each of ``omegas`` (rad/s) by the numpy reference, J₀ and
        D(ω) formed for all of them at once (the same numbers as one at a time)."""
        clamped = clamped_counts_at(self._beams, omegas)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # a clamped pole: undecided below
            matrices, magnitudes = self.matrices(omegas)
        answers = []
        for known, matrix, magnitude in zip(clamped, matrices, magnitudes):
            negatives = None
            if known >= 0 and np.all(np.isfinite(matrix)):
                negatives = negative_eigenvalues(matrix, magnitude)
            answers.append(None if negatives is None else int(known) + negatives)
        return answers

    def prefetch(self, omegas) -> None:
        """Count now at each of ``omegas`` (rad/s) not counted yet, for :meth:`__call__`
        to answer from: with the compiled engine in one kernel call, shared among the
        cores from COUNT_BATCH frequencies up (:func:`linmstmm.spread.spread`; each
        piece with buffers of its own), with
        numpy D(ω) formed for NUMPY_BATCH of them at a time; the same answers as one
        by one.

        Parameters
        ----------
        omegas : iterable of float
            rad/s, the frequencies a search is about to count at.
        """
        answers = self._answers
        wanted = sorted({omega for omega in map(float, omegas) if omega not in answers})
        if wanted:
            self._count_now(wanted)

    def _count_now(self, wanted: list[float]) -> None:
        """Count at each of ``wanted`` (rad/s, none counted yet) and remember the answers:
        compiled, in one kernel call (:func:`linmstmm._stiffness_kernels.counts`) on this
        thread in this counter's own buffers, or from COUNT_BATCH of them shared among
        the cores, each piece in buffers of its own; by the numpy reference, D(ω) formed
        for NUMPY_BATCH of them at a time."""
        if self.engine != "compiled":
            for start in range(0, len(wanted), NUMPY_BATCH):
                batch = wanted[start:start + NUMPY_BATCH]
                self._answers.update(zip(batch, self._numpy_at(batch)))
            return
        omegas, found = np.array(wanted), np.empty(len(wanted), dtype=np.int64)
        if len(wanted) < COUNT_BATCH:
            if self._scratch is None:
                self._scratch = self._new_scratch()
            self._kernel_counts(omegas, found, self._scratch)
        else:
            self._beam_table()  # made here, not by two pieces at once
            spread(lambda start, stop: self._kernel_counts(omegas[start:stop], found[start:stop], self._new_scratch()),
                   len(wanted), COUNT_BATCH)
        self._answers.update((omega, None if count < 0 else count) for omega, count in zip(wanted, found.tolist()))

    def _new_scratch(self) -> tuple:
        """Buffers the compiled kernel writes into: D(ω) and |D|(ω) ((n_dof + 1)², a row
        for padding) and dsytrf's workspace for the dense count, and the sparse
        count's own (:func:`linmstmm._stiffness_kernels.ordered_count`)."""
        size = self.n_dof + 1
        return (np.empty((size, size)), np.empty((size, size)),
                np.empty(max(self.n_dof, 1) * _stiffness_kernels().WORK_PER_UNKNOWN), self._sparse_scratch())

    def _sparse_scratch(self) -> tuple:
        """The sparse kernels' buffers (:func:`linmstmm._stiffness_kernels.ordered_count`):
        values (slots,), magnitudes (2 · slots,), shifted values (slots,), growth (n_dof,)."""
        slots = self._plan[1].shape[1]
        return np.empty(slots), np.empty(2 * slots), np.empty(slots), np.empty(self.n_dof)

    def _beam_table(self) -> np.ndarray:
        """The beams as the compiled kernel takes them (:func:`linmstmm._stiffness_kernels.beam_columns`),
        made on the first call."""
        if self._table is None:
            self._table = _stiffness_kernels().beam_columns(self._beams)
        return self._table

    def _kernel_counts(self, omegas: np.ndarray, found: np.ndarray, scratch: tuple) -> None:
        """J(ω) at each of ``omegas`` (m,) rad/s into ``found`` (m,) int64, −1 where undecided,
        by :func:`linmstmm._stiffness_kernels.counts` in ``scratch`` (:meth:`_new_scratch`)."""
        matrix, magnitude, work, buffers = scratch
        _stiffness_kernels().counts(omegas, self._beam_table(), self._maps, self._columns, self._static, self._mass,
                          SINGULAR_PIVOT, MOST_GROWTH, *self._plan, buffers, matrix, magnitude, work, found)

    def forms(self, vectors, omegas) -> np.ndarray:
        """xᵀ D(ω) x (N m for x in m and rad) for each row x of ``vectors`` (m, n_dof) at its
        own ω of ``omegas`` (m,) rad/s, the beams' terms from their ends' displacements (not
        finite at a clamped–clamped frequency): the numpy reference of
        :func:`linmstmm._stiffness_kernels._form`."""
        vectors = np.asarray(vectors, dtype=float).reshape(-1, self.n_dof)
        omegas = np.asarray(omegas, dtype=float).ravel()
        static = np.sum((vectors @ self._static.T) * vectors, axis=1)
        mass = np.sum((vectors @ self._mass.T) * vectors, axis=1)
        ends = self._ends(vectors)                                                   # (m, n_beams, 12, 1)
        beams = (np.swapaxes(ends, 2, 3) @ dynamic_stiffnesses(self._beams, omegas) @ ends).sum(axis=(1, 2, 3))
        return static - omegas ** 2 * mass + beams

    def _ends(self, vectors: np.ndarray) -> np.ndarray:
        """(m, n_beams, 12, 1): each beam's local end displacements for each row of ``vectors`` (m, n_dof)."""
        padded = np.concatenate([vectors, np.zeros((vectors.shape[0], 1))], axis=1)  # the padding DOF n_dof
        return self._maps @ padded[:, self._columns][..., None]

    def differences(self, vectors, omegas, step: float) -> np.ndarray:
        """(m, n_dof): (D(ω (1 − step)) − D(ω (1 + step))) x, about −2 step ω D′(ω) x, for each
        row x of ``vectors`` (m, n_dof) at its own ω of ``omegas`` (m,) rad/s, the springs'
        terms cancelled: the numpy reference of :func:`linmstmm._stiffness_kernels._difference_applied`."""
        vectors = np.asarray(vectors, dtype=float).reshape(-1, self.n_dof)
        omegas = np.asarray(omegas, dtype=float).ravel()
        out = np.zeros((vectors.shape[0], self.n_dof + 1))                           # + the padding DOF
        out[:, :-1] = (4 * step * omegas ** 2)[:, None] * (vectors @ self._mass.T)
        below, above = (dynamic_stiffnesses(self._beams, omegas * (1 + sign * step)) for sign in (-1, 1))
        forces = (np.swapaxes(self._maps, 1, 2) @ (below - above) @ self._ends(vectors))[..., 0]  # (m, n_beams, k)
        rows = np.broadcast_to(np.arange(vectors.shape[0])[:, None, None], forces.shape)
        np.add.at(out, (rows, np.broadcast_to(self._columns, forces.shape)), forces)
        return out[:, :-1]

    def rayleigh_values(self, vectors, starts, inverse_steps: int) -> np.ndarray:
        """(m,) rad/s, NaN where it does not settle: Rayleigh quotient iteration on D(ω)
        (:mod:`linmstmm.rayleigh`), at most ``inverse_steps`` steps a row (0: the functional's
        root), from each row of ``vectors`` (m, n_dof), a mode's displacements (m) and
        rotations (rad) on D's unknowns, and its frequency ``starts`` (m,) rad/s; compiled
        (:func:`linmstmm._stiffness_kernels.rayleigh_roots`, from COUNT_BATCH rows on the
        cores, each piece in buffers of its own), else by
        :func:`linmstmm.rayleigh.rayleigh_values_in_numpy`."""
        from linmstmm import rayleigh

        starts = np.array(starts, dtype=float).ravel()
        if self.engine != "compiled":
            return rayleigh.rayleigh_values_in_numpy(self, vectors, starts, inverse_steps)
        vectors = np.array(vectors, dtype=float, order="C").reshape(starts.size, self.n_dof)  # each piece contiguous: one compiled signature
        out = np.empty(starts.size)
        kernel, table = _stiffness_kernels().rayleigh_roots, self._beam_table()

        def piece(start: int, stop: int) -> None:
            kernel(vectors[start:stop], starts[start:stop], table, self._maps, self._columns, rayleigh.SOLVE_GROWTH,
                   *self._plan, self._sparse_scratch(), rayleigh.FIRST_STEP, rayleigh.FORM_STEPS, rayleigh.FORM_XTOL,
                   rayleigh.FORM_FLOOR, rayleigh.SETTLED, inverse_steps, rayleigh.DERIVATIVE_STEP,
                   out[start:stop])

        spread(piece, starts.size, COUNT_BATCH)
        return out

    def matrices(self, omegas) -> tuple[np.ndarray, np.ndarray]:
        """(D(ω), |D|(ω)) at each of the m ``omegas`` (rad/s): the reduced exact dynamic
        stiffness (m, n_dof, n_dof), and the same assembled from the absolute values of
        every term (the scale each entry's rounding is relative to). The beams' terms
        are summed into the entries they reach only (:meth:`_beam_entries`), then the
        springs' and ω² times the bodies' added in place: the same numbers as summed into
        all n_dof² entries, in 60 % of the time (the launcher, 20 frequencies at once)."""
        omegas = np.asarray(omegas, dtype=float).ravel()
        local = dynamic_stiffnesses(self._beams, omegas)                 # (m, n_beams, 12, 12)
        parts = np.swapaxes(self._maps, 1, 2) @ local @ self._maps       # (m, n_beams, k, k)
        reached, entries, slots = self._beam_entries()
        m, n = omegas.size, self.n_dof
        scatter = (np.arange(m)[:, None] * entries.size + slots[None, :]).ravel()
        terms = parts[:, reached]                                        # (m, terms)
        matrix, magnitude = np.zeros((m, n, n)), np.zeros((m, n, n))
        matrix.reshape(m, -1)[:, entries] = np.bincount(scatter, terms.ravel(), minlength=m * entries.size).reshape(m, -1)
        magnitude.reshape(m, -1)[:, entries] = np.bincount(scatter, np.abs(terms).ravel(),
                                                           minlength=m * entries.size).reshape(m, -1)
        squared = (omegas ** 2)[:, None, None]
        matrix += self._static
        matrix -= squared * self._mass
        magnitude += np.abs(self._static)
        magnitude += squared * np.abs(self._mass)
        return matrix, magnitude

    def _beam_entries(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(reached (n_beams, k, k) bool: the terms of the beams' reduced stiffness
        that fall in D (no padding DOF); entries (e,): the flat places in D (n_dof²) they
        reach, ascending; slots: for each reached term, its entry's index in ``entries``),
        made on the first call."""
        if self._entries is None:
            columns, n = self._columns, self.n_dof
            reached = (columns[:, :, None] < n) & (columns[:, None, :] < n)
            entries, slots = np.unique((columns[:, :, None] * n + columns[:, None, :])[reached], return_inverse=True)
            self._entries = reached, entries, slots.ravel()
        return self._entries


def sparse_plan(static: np.ndarray, mass: np.ndarray, maps: np.ndarray, columns: np.ndarray) -> tuple[tuple, np.ndarray]:
    """The sparse factorisation of D(ω) as :func:`linmstmm._stiffness_kernels.ordered_count`
    takes it.

    Parameters
    ----------
    static, mass : (n, n) float64
        The springs' stiffness (N/m, N·m/rad) and the bodies' mass (kg, kg·m²), reduced.
    maps, columns : (n_beams, 12, k) float64, (n_beams, k) int
        Each beam's map from the reduced DOFs it touches to its local ones, and those
        DOFs (n for padding), as :func:`_beam_maps`.

    Returns
    -------
    plan : tuple of int64 arrays
        (order, starts, rows, high, low, updates, targets) of the
        :class:`~linmstmm.ordered_ldlt.EliminationPlan` of D(ω)'s pattern, and
        (n_beams, k, k) beam_slots: where each entry of a beam's map goes (its slot
        in the lower triangle, slots + its slot in the upper one, −1 for padding
        and for entries that no term of the beam's local stiffness reaches).
    terms : (4, slots) float64
        ``static`` and ``mass`` at the slots in the lower triangle, then in the upper.
    """
    from linmstmm._ordering_kernels import count_patterns, slot_terms

    pattern, beam_pattern = count_patterns(static, mass, maps, _stiffness_kernels().LOCAL_PATTERN)
    plan, beam_slots = _planned(pattern, beam_pattern, columns)
    terms = slot_terms(static, mass, plan.high, plan.low)
    return (plan.order, plan.starts, plan.rows, plan.high, plan.low, plan.updates, plan.targets, beam_slots), terms


#: Elimination plans kept by their pattern (:func:`_planned`): a parameter study's models
#: share one, whose minimum-degree order took 0.25-0.35 ms of a launcher counter's build.
PLANS_KEPT = 8
_plans = KeptByKey(PLANS_KEPT)


def _planned(pattern: np.ndarray, beam_pattern: np.ndarray, columns: np.ndarray) -> tuple:
    """(:class:`~linmstmm.ordered_ldlt.EliminationPlan`, beam_slots) of D(ω)'s pattern:
    ``pattern`` (n, n) bool, the springs' and bodies' entries; ``beam_pattern``
    (n_beams, k, k) bool, the entries of each beam's ``columns`` its stiffness reaches
    (see :func:`sparse_plan`). Kept for the last PLANS_KEPT patterns
    (:func:`linmstmm.model_structure.forget_structures` forgets them)."""
    key = b"".join(np.ascontiguousarray(part).tobytes() for part in (pattern, beam_pattern, columns))
    key += repr((pattern.shape, beam_pattern.shape)).encode()
    return _plans.value(key, lambda: _plan_of(pattern, beam_pattern, columns))


def _plan_of(pattern: np.ndarray, beam_pattern: np.ndarray, columns: np.ndarray) -> tuple:
    """:func:`_planned` made anew, in one call (:func:`linmstmm._ordering_kernels.beams_plan`)."""
    from linmstmm._ordering_kernels import beams_plan
    from linmstmm.ordered_ldlt import EliminationPlan

    *plan, placed = beams_plan(pattern, beam_pattern, columns)
    return EliminationPlan(*plan), placed


def _reduced_terms(parts, engine: str) -> tuple[np.ndarray, np.ndarray]:
    """(n, n) springs' stiffness (N/m, N m/rad) and bodies' mass (kg, kg m²) on the
    reduced DOFs of ``parts`` (:class:`~linmstmm.fe.assembly.ConstrainedParts`), dense,
    each entry summed as scipy.sparse sums it: by :mod:`linmstmm.fe.products`, or for
    the compiled ``engine`` from the triplets by
    :func:`linmstmm._product_kernels.counter_terms` (the same numbers)."""
    if engine == "compiled":
        from linmstmm._product_kernels import counter_terms  # numba: imported where a count is compiled

        formed = counter_terms(parts)
        if formed is not None:
            return formed
    T = parts.T
    springs = compressed_rows(dense_product(parts.spring_strains.compressed(parts.n_full), T))
    stiffness = np.concatenate(parts.spring_stiffness) if parts.spring_stiffness else np.zeros(0)
    mass = parts.rigid_mass.compressed(parts.n_full, parts.n_full)
    return dense_product(transposed(springs), rows_scaled(springs, stiffness)), congruence(T, mass)


def _beam_maps(parts, engine: str) -> tuple[np.ndarray, np.ndarray]:
    """((n_beams, 12, k) maps from the reduced DOFs each beam touches to its local
    ones, (n_beams, k) those DOFs), beams in ``model.beams`` order, of the
    :class:`~linmstmm.fe.assembly.ConstrainedParts` of one element per beam. k: the
    most reduced DOFs one beam touches; shorter lists are padded with the extra DOF
    n_dof and zero columns. The rows of T each beam touches are picked by the
    compiled :func:`~linmstmm._stiffness_kernels.touched_rows` for the compiled
    ``engine``, the same arrays."""
    T, n = parts.T, parts.T.shape[1]
    dofs, to_local = (part[:, 0] for part in parts.beam_maps)           # (n_beams, 12), (n_beams, 12, 12)
    if engine == "compiled":
        columns, picked = _stiffness_kernels().touched_rows(T.indptr, T.indices, T.data, dofs, n)
        present = columns < n
    else:
        rows = dense_rows(T, dofs)                                       # (n_beams, 12, n_dof)
        touched = np.any(rows != 0.0, axis=1)                            # (n_beams, n_dof)
        width = int(touched.sum(axis=1).max(initial=0))
        # each beam's touched DOFs ascending, then the padding DOF n (a stable sort of "untouched")
        columns = np.argsort(~touched, axis=1, kind="stable")[:, :width]
        present = np.take_along_axis(touched, columns, axis=1)
        picked = np.take_along_axis(rows, np.broadcast_to(columns[:, None, :], rows.shape[:2] + (width,)), axis=2)
    return np.where(present[:, None, :], to_local @ picked, 0.0), np.where(present, columns, n)
