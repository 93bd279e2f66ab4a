"""Compiled kernels of the Wittrick–Williams count (:mod:`linmstmm.wittrick_williams`).

Compiled once by numba (``@njit(cache=True)``), float64 arrays and integers
only, each mirroring a numpy counterpart that stays the readable reference and
the test oracle (tests/test_wittrick_williams.py compares them):

* :func:`assembled` — :func:`linmstmm.dynamic_stiffness.clamped_counts` and
  :meth:`linmstmm.wittrick_williams.ModeCounter.matrices` (at one ω): J₀(ω) and the reduced
  exact dynamic stiffness D(ω) with the scale of its terms;
* :func:`block_inertia` — :func:`linmstmm.dense_inertia.block_inertia`;
* :func:`count` — :meth:`linmstmm.wittrick_williams.ModeCounter._numpy_at`: the
  whole count J(ω) in one call (J₀, D(ω), its equilibration, and LDLᵀ
  factorisations by LAPACK's ``dsytrf`` of it shifted up and down), compiled
  ``nogil``, so that counts at several frequencies can run on threads side by
  side;
* :func:`ordered_count` — the same count on the sparse D(ω) (assembled by
  :func:`_assembled_slots`, factorised by :func:`ordered_inertia`, LDLᵀ without
  pivoting in the order of a :class:`~linmstmm.ordered_ldlt.EliminationPlan`),
  the same answer wherever it gives one and REFUSED where :func:`count` is to
  decide (a small pivot or growth); tests/test_sparse_count.py compares it with
  :func:`count` and its factorisation with a dense numpy LDLᵀ;
* :func:`counts` — :meth:`linmstmm.wittrick_williams.ModeCounter.prefetch` one
  frequency at a time: :func:`ordered_count` at each of many frequencies, and
  :func:`count` where it refuses, in one call (the dispatch of fifteen
  arguments per frequency was 2.5 of the 10 µs a count took on the launcher).

* :func:`touched_rows` — each beam's rows of T as
  :func:`linmstmm.wittrick_williams._beam_maps` picks them in numpy;
* :func:`rayleigh_roots` — :func:`linmstmm.rayleigh.rayleigh_values_in_numpy`: Rayleigh
  quotient iteration on D(ω) from approximate modes, its functional xᵀ D(ω) x
  (:func:`_form`, from the terms :func:`_form_parts` makes of x:
  :meth:`~linmstmm.wittrick_williams.ModeCounter.forms`), D′(ω) x by differences
  (:func:`_difference_applied`: :meth:`~linmstmm.wittrick_williams.ModeCounter.differences`)
  and the solve of its inverse steps by the LDLᵀ of :func:`ordered_inertia`
  (:func:`_ordered_solve`); tests/test_rayleigh.py compares them.

The plan of that factorisation is made by :mod:`linmstmm._ordering_kernels`.

Kept whole: numba invalidates a cached kernel when the file that defines it
changes, not when a kernel it calls in another file does; the count and the
Rayleigh quotient iteration share the beams' blocks and the sparse factorisation
here, and split across files an edit to one of those would leave the other's
callers running the old code from the cache.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from linmstmm._compile_notice import announce_compiles
from linmstmm._lapack import lapack_routine
from linmstmm.dynamic_stiffness import POLE, SERIES_BELOW, SERIES_COEFFICIENTS, SERIES_TERMS

announce_compiles()  # one line on stderr if this run compiles (linmstmm._compile_notice)

#: Columns of the beam table the kernels take (see :func:`beam_columns`).
EA, GJ, EIY, EIZ, RHO_A, RHO_IP, LENGTH, AXIAL, TORSION = range(9)
_X_Y = np.array([1, 5, 7, 11])
_X_Z = np.array([2, 4, 8, 10])
#: Signs of the bending planes' DOFs: the x–z plane's θ is −θy, the x–y plane's θz as it is.
_FLIP = np.array([1.0, -1.0, 1.0, -1.0])
_SAME = np.ones(4)
#: (12, 12) 1.0 where a beam's local dynamic stiffness may be nonzero: the rods
#: (axial, torsion) and the two bending planes, each coupling its own DOFs only.
LOCAL_PATTERN = np.zeros((12, 12))
for _dofs in ([0, 6], [3, 9], _X_Y, _X_Z):
    LOCAL_PATTERN[np.ix_(_dofs, _dofs)] = 1.0
_DSYTRF = lapack_routine("dsytrf", 8)
#: What :func:`ordered_count` answers where the dense :func:`count` is to decide.
REFUSED = -2
#: Workspace LAPACK's dsytrf is given per unknown: its block size (64), with which
#: it factorises blocked, as scipy's wrapper lets it.
WORK_PER_UNKNOWN = 64


def beam_columns(beams) -> np.ndarray:
    """(n_beams, 9) float64 table of a :class:`~linmstmm.dynamic_stiffness.BeamTable`
    in the column order EA … TORSION above (flags as 0.0 / 1.0)."""
    columns = [beams.EA, beams.GJ, beams.EIy, beams.EIz, beams.rhoA, beams.rhoIp, beams.L, beams.axial, beams.torsion]
    return np.array(columns, dtype=float).T.copy()


@njit(cache=True)
def _combinations(lam, out):
    """The seven bending combinations of :func:`linmstmm.dynamic_stiffness._scaled`
    (λ ≥ SERIES_BELOW) or ``_series`` (below) into ``out``; True for the series."""
    if lam < SERIES_BELOW:
        x = lam ** 4
        out[:] = 0.0
        power = 1.0
        for j in range(SERIES_TERMS):
            for i in range(7):
                out[i] += SERIES_COEFFICIENTS[j, i] * power
            power *= x
        return True
    c, s = math.cos(lam), math.sin(lam)
    decay = math.exp(-2 * lam)
    inv_c, t = 2 * math.sqrt(decay) / (1 + decay), (1 - decay) / (1 + decay)
    out[0], out[1], out[2] = inv_c - c, c * t + s, s * t
    out[3], out[4], out[5], out[6] = s * inv_c + t, 1.0 - c * inv_c, s - c * t, t - s * inv_c
    return False


@njit(cache=True)
def _bending_entries(stiffness, inertia, length, omega, combos):
    """The six distinct entries (K11, K12, K13, K14, K22, K24) of one plane's exact
    bending block over (v₁, θ₁, v₂, θ₂) (:func:`linmstmm.dynamic_stiffness._bending`),
    ``combos`` (7,) scratch."""
    beta = (inertia * omega * omega / stiffness) ** 0.25
    series = _combinations(beta * length, combos)
    b1, b2, b3 = (1 / length, 1 / length ** 2, 1 / length ** 3) if series else (beta, beta ** 2, beta ** 3)
    f = stiffness / combos[0]
    return (f * b3 * combos[1], f * b2 * combos[2], -f * b3 * combos[3], f * b2 * combos[4], f * b1 * combos[5],
            f * b1 * combos[6])


@njit(cache=True)
def _bending(stiffness, inertia, length, omega, local, dofs, signs, combos):
    """Write one plane's 4 × 4 exact bending block (``signs`` flip θ) into ``local``."""
    block = _bending_block(_bending_entries(stiffness, inertia, length, omega, combos))
    for i in range(4):
        for j in range(4):
            local[dofs[i], dofs[j]] = block[i][j] * signs[i] * signs[j]


@njit(cache=True)
def _bending_block(entries):
    """One plane's 4 × 4 bending block, rows as tuples, from its six distinct ``entries``
    (:func:`_bending_entries`)."""
    k11, k12, k13, k14, k22, k24 = entries
    return ((k11, k12, k13, k14), (k12, k22, -k14, k24), (k13, -k14, k11, -k12), (k14, k24, -k12, k22))


@njit(cache=True)
def _rod_entries(stiffness, inertia, length, omega, deformable):
    """(diagonal, off-diagonal) entries of one rod's 2 × 2 block (the consistent mass
    alone where it is rigid)."""
    if not deformable:
        m = -omega * omega * inertia * length / 6
        return 2 * m, m
    k = omega * math.sqrt(inertia / stiffness)
    kl = k * length
    if kl < 1e-8:
        scale, diagonal, off = stiffness / length, 1.0 - kl * kl / 3, -1.0 - kl * kl / 6
    else:
        scale, diagonal, off = stiffness * k / math.sin(kl), math.cos(kl), -1.0
    return scale * diagonal, scale * off


@njit(cache=True)
def _rod(stiffness, inertia, length, omega, deformable, local, a, b):
    """Write one rod's 2 × 2 block at DOFs ``a``, ``b`` into ``local`` (the consistent
    mass alone where it is rigid)."""
    diagonal, off = _rod_entries(stiffness, inertia, length, omega, deformable)
    local[a, a], local[a, b], local[b, a], local[b, b] = diagonal, off, off, diagonal


@njit(cache=True)
def _clamped(beam, omega, combos):
    """J₀ of one beam at ``omega``; −1 within POLE of a clamped–clamped frequency
    (``combos`` (7,) scratch)."""
    total = 0
    for stiffness, inertia, flag in ((beam[EA], beam[RHO_A], beam[AXIAL]), (beam[GJ], beam[RHO_IP], beam[TORSION])):
        if flag > 0:
            phase = omega * beam[LENGTH] * math.sqrt(inertia / stiffness) / math.pi
            nearest = math.floor(phase + 0.5)
            if nearest >= 1 and abs(phase - nearest) < POLE * phase:
                return -1
            total += int(math.floor(phase))
    for stiffness in (beam[EIY], beam[EIZ]):
        lam = beam[LENGTH] * (beam[RHO_A] * omega * omega / stiffness) ** 0.25
        if lam >= SERIES_BELOW:
            _combinations(lam, combos)
            if abs(combos[0]) < POLE:
                return -1
            i = math.floor(lam / math.pi)
            parity = 1.0 if i % 2 == 0 else -1.0
            total += int(i - (1 - parity * (1.0 if combos[0] > 0 else -1.0)) / 2)
    return total


@njit(cache=True)
def assembled(omega, beams, maps, columns, static, mass, matrix, magnitude):
    """J₀(ω) (−1 where undecided), with D(ω) and |D|(ω) written into the first
    n × n of ``matrix`` and ``magnitude`` ((n + 1, n + 1); row n takes the padding).

    beams : (n_beams, 9) :func:`beam_columns`. maps : (n_beams, 12, k) reduced →
    local DOFs. columns : (n_beams, k) reduced DOFs of each map (n for padding).
    static, mass : (n, n) springs' stiffness and bodies' mass, reduced.
    """
    n = static.shape[0]
    for i in range(n):
        for j in range(n):
            matrix[i, j] = static[i, j] - omega * omega * mass[i, j]
            magnitude[i, j] = abs(static[i, j]) + omega * omega * abs(mass[i, j])
    size, width = matrix.shape[1], columns.shape[1]
    places = np.empty((beams.shape[0], width, width), dtype=np.int64)  # in matrix.ravel()
    for b in range(beams.shape[0]):
        for i in range(width):
            for j in range(width):
                places[b, i, j] = columns[b, i] * size + columns[b, j]
    return _added_beams(omega, beams, maps, places, matrix.reshape(matrix.size), magnitude.reshape(magnitude.size))


@njit(cache=True)
def _added_beams(omega, beams, maps, places, values, magnitudes):
    """J₀(ω) of the beams (−1 where undecided), each beam's ``map.T @ local @ map``
    added in order: its entry (i, j) at ``places[b, i, j]`` of ``values`` and its
    absolute value there in ``magnitudes``; in ``magnitudes`` alone where that place
    is values.size or more, nowhere where it is negative."""
    clamped = 0
    local = np.zeros((12, 12))
    combos = np.empty(7)
    for b in range(beams.shape[0]):
        count = _beam_local(beams[b], omega, local, combos)
        if count < 0:
            return -1
        clamped += count
        mapped = _mapped(local, maps[b])
        for i in range(places.shape[1]):
            for j in range(places.shape[2]):
                place = places[b, i, j]
                if place >= 0:
                    value = _entry(maps[b], mapped, i, j)
                    if place < values.size:
                        values[place] += value
                    magnitudes[place] += abs(value)
    return clamped


@njit(cache=True)
def _beam_local(beam, omega, local, combos):
    """J₀ of one beam (:func:`_clamped`, −1 where undecided), with its (12, 12) exact
    dynamic stiffness written into ``local`` (unless undecided)."""
    count = _clamped(beam, omega, combos)
    if count < 0:
        return -1
    local[:] = 0.0
    _rod(beam[EA], beam[RHO_A], beam[LENGTH], omega, beam[AXIAL] > 0, local, 0, 6)
    _rod(beam[GJ], beam[RHO_IP], beam[LENGTH], omega, beam[TORSION] > 0, local, 3, 9)
    _bending(beam[EIZ], beam[RHO_A], beam[LENGTH], omega, local, _X_Y, _SAME, combos)
    _bending(beam[EIY], beam[RHO_A], beam[LENGTH], omega, local, _X_Z, _FLIP, combos)
    return count


@njit(cache=True)
def _mapped(local, map_):
    """``local @ map_`` (12, k), skipping the zeros of ``local``."""
    rows, width = map_.shape
    mapped = np.zeros((rows, width))
    for p in range(rows):
        for q in range(rows):
            if local[p, q] != 0.0:
                for j in range(width):
                    mapped[p, j] += local[p, q] * map_[q, j]
    return mapped


@njit(cache=True)
def _entry(map_, mapped, i, j):
    """Entry (i, j) of ``map_.T @ local @ map_`` from ``mapped`` (:func:`_mapped`)."""
    value = 0.0
    for p in range(map_.shape[0]):
        value += map_[p, i] * mapped[p, j]
    return value


@njit(cache=True)
def block_inertia(factor, pivots, singular):
    """Negative eigenvalues of the block-diagonal D of LAPACK's ``?sytrf`` (lower);
    −1 where a pivot or a 2 × 2 block's eigenvalue is below ``singular``."""
    negatives, k, n = 0, 0, pivots.size
    while k < n:
        if pivots[k] > 0:
            d = factor[k, k]
            if abs(d) < singular:
                return -1
            if d < 0:
                negatives += 1
            k += 1
            continue
        a, b, c = factor[k, k], factor[k + 1, k], factor[k + 1, k + 1]
        half_trace, root = (a + c) / 2, math.sqrt(((a - c) / 2) ** 2 + b * b)
        for eigenvalue in (half_trace - root, half_trace + root):
            if abs(eigenvalue) < singular:
                return -1
            if eigenvalue < 0:
                negatives += 1
        k += 2
    return negatives


@njit(cache=True)
def _ldlt_inertia(transposed, singular, pivots, work, integers):
    """Negative eigenvalues of a symmetric matrix, −1 where a pivot is below ``singular``.

    transposed : (n, n) C-ordered: the matrix's transpose, which LAPACK (column
    major) reads as the matrix itself, lower triangle; overwritten by the factors
    of ``dsytrf`` (Bunch–Kaufman LDLᵀ). pivots : (n,) int32; work : float64,
    its workspace; integers : (4,) int32 scratch.
    """
    n = transposed.shape[0]
    uplo = np.array([76], dtype=np.uint8)  # "L"
    integers[0], integers[1], integers[2], integers[3] = n, n, work.size, 0
    _DSYTRF(uplo.ctypes, integers[0:].ctypes, transposed.ctypes, integers[1:].ctypes, pivots.ctypes,
            work.ctypes, integers[2:].ctypes, integers[3:].ctypes)
    if integers[3] != 0:  # > 0: an exactly zero pivot
        return -1
    return block_inertia(transposed.T, pivots, singular)


@njit(cache=True, nogil=True)
def count(omega, beams, maps, columns, static, mass, singular_pivot, matrix, magnitude, work):
    """J(ω): natural frequencies below ``omega`` (rad/s), −1 where float64 cannot decide.

    The arguments of :func:`assembled`, and singular_pivot: a pivot below this
    fraction of the largest equilibrated term is rounding
    (:data:`linmstmm.dense_inertia.SINGULAR_PIVOT`); work : (n · WORK_PER_UNKNOWN,)
    float64. D(ω) is equilibrated by the diagonal of |D|(ω), shifted by ± the rounding
    level and factorised both ways, whose counts must agree
    (:func:`linmstmm.dense_inertia.negative_eigenvalues`, the same numbers in
    the same order of operations).
    """
    clamped = assembled(omega, beams, maps, columns, static, mass, matrix, magnitude)
    n = static.shape[0]
    if clamped < 0:
        return -1
    for i in range(n):
        for j in range(n):
            if not math.isfinite(matrix[i, j]):
                return -1
    if n == 0:
        return clamped
    weights = np.empty(n)
    for i in range(n):
        if not magnitude[i, i] > 0:
            return -1  # a DOF with neither stiffness nor mass
        weights[i] = 1.0 / math.sqrt(magnitude[i, i])
    first, second = np.empty((n, n)), np.empty((n, n))  # transposed, as LAPACK reads them
    largest = 0.0
    for i in range(n):
        for j in range(n):
            equilibrated = matrix[i, j] * weights[i] * weights[j]
            first[j, i] = equilibrated
            second[j, i] = equilibrated
            largest = max(largest, magnitude[i, j] * weights[i] * weights[j])
    singular = singular_pivot * largest
    for i in range(n):
        first[i, i] = first[i, i] + singular
        second[i, i] = second[i, i] - singular
    pivots, integers = np.empty(n, dtype=np.int32), np.empty(4, dtype=np.int32)
    negatives = _ldlt_inertia(first, singular, pivots, work, integers)
    if negatives < 0 or negatives != _ldlt_inertia(second, singular, pivots, work, integers):
        return -1  # an eigenvalue within rounding of zero (a small one need not show as a small pivot)
    return clamped + negatives


@njit(cache=True)
def _assembled_slots(omega, beams, maps, beam_slots, terms, values, magnitudes):
    """:func:`assembled` on the slots of an :class:`~linmstmm.ordered_ldlt.EliminationPlan`:
    J₀(ω) (−1 where undecided), D(ω)'s lower triangle into ``values`` (slots,) and
    |D|(ω) into ``magnitudes`` (2 · slots,: the lower triangle, then the upper one),
    each entry the same number as there, summed in the same order.

    beam_slots : (n_beams, k, k) int64, where entry (i, j) of a beam's map goes:
    its slot in the lower triangle, slots + its slot in the upper one (|D| only),
    or −1 (padding, or an entry that no term of the beam's local stiffness reaches). terms : (4, slots) the springs' stiffness and the bodies'
    mass in the lower triangle, then the same in the upper one.
    """
    slots = values.size
    squared = omega * omega
    for s in range(slots):
        values[s] = terms[0, s] - squared * terms[1, s]
        magnitudes[s] = abs(terms[0, s]) + squared * abs(terms[1, s])
        magnitudes[slots + s] = abs(terms[2, s]) + squared * abs(terms[3, s])
    return _added_beams(omega, beams, maps, beam_slots, values, magnitudes)


@njit(cache=True)
def _equilibrated(values, magnitudes, order, starts, high, low, weights):
    """Scale D(ω)'s lower-triangle slots ``values`` symmetrically by ``weights`` (n,),
    written here: one over the square root of each DOF's diagonal magnitude (``magnitudes``:
    (2 slots,) the terms' magnitudes, as :func:`_assembled_slots` gives them; ``order``,
    ``starts``, ``high``, ``low``: the elimination plan's). Returns the largest scaled
    magnitude, or −1.0 where a DOF has neither stiffness nor mass."""
    for k in range(order.size):
        if not magnitudes[starts[k]] > 0:
            return -1.0
        weights[order[k]] = 1.0 / math.sqrt(magnitudes[starts[k]])
    slots, largest = values.size, 0.0
    for s in range(slots):
        values[s] = values[s] * weights[high[s]] * weights[low[s]]
        largest = max(largest, magnitudes[s] * weights[high[s]] * weights[low[s]])
        largest = max(largest, magnitudes[slots + s] * weights[low[s]] * weights[high[s]])
    return largest


@njit(cache=True)
def ordered_inertia(values, starts, rows, updates, targets, singular, most_growth, growth):
    """Negative eigenvalues of a symmetric matrix by LDLᵀ without pivoting in the
    order of an :class:`~linmstmm.ordered_ldlt.EliminationPlan` (its ``starts``,
    ``rows``, ``updates``, ``targets``); −1 where a pivot is below ``singular`` or not finite, or
    an entry of diag(|L| |D| |L|ᵀ), which bounds every entry of it, is above
    ``most_growth`` (the factorisation's rounding is not known to be small then).

    values : (slots,) the matrix's lower triangle, overwritten; growth : (n,) scratch.
    """
    return _eliminated(values, starts, rows, updates, targets, singular, most_growth, growth)


@njit(cache=True)
def _eliminated(values, starts, rows, updates, targets, smallest, most_growth, growth):
    """The elimination of :func:`ordered_inertia` and :func:`_ordered_solve`: ``values``
    overwritten by the factors (each pivot at its column's start, L's column below it
    times the pivot); the number of negative pivots, or −1 where a pivot's magnitude is
    below ``smallest`` or not finite, or an entry of diag(|L| |D| |L|ᵀ) is above
    ``most_growth``."""
    n = starts.size - 1
    growth[:] = 0.0
    negatives = 0
    for k in range(n):
        pivot = values[starts[k]]
        growth[k] += abs(pivot)
        if abs(pivot) < smallest or not math.isfinite(pivot) or growth[k] > most_growth:
            return -1
        if pivot < 0:
            negatives += 1
        t = updates[k]
        for a in range(starts[k] + 1, starts[k + 1]):
            multiplier = values[a] / pivot
            growth[rows[a]] += abs(values[a] * multiplier)
            for b in range(starts[k] + 1, a + 1):
                values[targets[t]] -= multiplier * values[b]
                t += 1
    return negatives


@njit(cache=True, nogil=True)
def ordered_count(omega, beams, maps, singular_pivot, most_growth, plan, terms, buffers):
    """:func:`count` by LDLᵀ without pivoting on the sparse D(ω) in a fill-reducing
    order: the same answer wherever it gives one, and REFUSED where the dense
    :func:`count` is to decide.

    D(ω) and |D|(ω) are assembled on the slots of the plan only, equilibrated and
    shifted by ± the rounding level as in :func:`count` (the same numbers), and
    each shifted matrix factorised by :func:`ordered_inertia`. REFUSED where that
    refuses (a small pivot, or growth above ``most_growth`` times the largest
    equilibrated term) or where a term is not finite; −1, undecided, where both
    factorisations are sure and their counts differ: the shifted matrices' inertias
    are the dense count's then, which would differ as well (an eigenvalue within the
    rounding level of zero; 0.1 ms saved a count on the second launcher, whose lowest
    root's counts at ±1e-9 are such).

    beams, maps : as for :func:`assembled`. singular_pivot : as for :func:`count`.
    plan : (order, starts, rows, high, low, updates, targets, beam_slots) int64
    arrays of :class:`~linmstmm.ordered_ldlt.EliminationPlan` (beam_slots as in
    :func:`_assembled_slots`). terms : (4, slots) as there. buffers : float64
    scratch (values (slots,), magnitudes (2 · slots,), shifted (slots,), growth (n,)).
    """
    order, starts, rows, high, low, updates, targets, beam_slots = plan
    values, magnitudes, shifted, growth = buffers
    clamped = _assembled_slots(omega, beams, maps, beam_slots, terms, values, magnitudes)
    if clamped < 0:
        return -1
    for s in range(magnitudes.size):
        if not math.isfinite(magnitudes[s]):  # so too where an entry of D(ω) is not
            return REFUSED
    n = order.size
    if n == 0:
        return clamped
    largest = _equilibrated(values, magnitudes, order, starts, high, low, np.empty(n))
    if largest < 0:
        return -1  # a DOF with neither stiffness nor mass
    singular = singular_pivot * largest
    negatives = -1
    for sign in (1.0, -1.0):
        for s in range(values.size):
            shifted[s] = values[s]
        for k in range(n):
            shifted[starts[k]] += sign * singular
        found = ordered_inertia(shifted, starts, rows, updates, targets, singular, most_growth * largest, growth)
        if found < 0:
            return REFUSED
        if sign < 0 and found != negatives:
            return -1  # both factorisations sure, the counts apart: an eigenvalue within rounding of zero
        negatives = found
    return clamped + negatives


@njit(cache=True)
def touched_rows(t_indptr, t_indices, t_data, dofs, n):
    """Each beam's rows of T on the reduced DOFs they touch, as
    :func:`linmstmm.wittrick_williams._beam_maps` picks them in numpy.

    t_indptr, t_indices, t_data : CSR arrays of T (n_full, n). dofs : (n_beams, 12)
    the full DOFs of each beam's ends.

    Returns
    -------
    columns : (n_beams, k) int64, the reduced DOFs each beam's rows touch (a nonzero
        entry), ascending, then n for padding; k the most any beam touches.
    picked : (n_beams, 12, k) float64, those rows' entries there (0.0 at padding).
    """
    rows = np.zeros((dofs.shape[0], dofs.shape[1], n))
    touched = np.zeros((dofs.shape[0], n), dtype=np.bool_)
    width = 0
    for b in range(dofs.shape[0]):
        for a in range(dofs.shape[1]):
            for tt in range(t_indptr[dofs[b, a]], t_indptr[dofs[b, a] + 1]):
                rows[b, a, t_indices[tt]] = t_data[tt]
                touched[b, t_indices[tt]] |= t_data[tt] != 0.0
        width = max(width, touched[b].sum())
    columns = np.full((dofs.shape[0], width), n, dtype=np.int64)
    picked = np.zeros((dofs.shape[0], dofs.shape[1], width))
    for b in range(dofs.shape[0]):
        w = 0
        for c in range(n):
            if touched[b, c]:
                columns[b, w] = c
                for a in range(dofs.shape[1]):
                    picked[b, a, w] = rows[b, a, c]
                w += 1
    return columns, picked


@njit(cache=True, nogil=True)
def counts(omegas, beams, maps, columns, static, mass, singular_pivot, most_growth, plan, terms, buffers,
           matrix, magnitude, work, out):
    """J(ω) at each of ``omegas`` (m,) rad/s into ``out`` (m,) int64, −1 where undecided:
    :func:`ordered_count` with ``plan``, ``terms`` and ``buffers``, else :func:`count`
    with ``columns``, ``static``, ``mass`` and the scratch ``matrix``, ``magnitude``, ``work``.
    Kept in this file with the kernels it calls: numba's cache notices an edit to the
    file that defines a kernel, not to another file's kernel it calls."""
    for i in range(omegas.size):
        found = ordered_count(omegas[i], beams, maps, singular_pivot, most_growth, plan, terms, buffers)
        if found == REFUSED:
            found = count(omegas[i], beams, maps, columns, static, mass, singular_pivot, matrix, magnitude, work)
        out[i] = found


@njit(cache=True)
def _form_parts(x, maps, columns, high, low, terms, ends):
    """(xᵀ S x, xᵀ M x) of the springs' stiffness S and the bodies' mass M (``terms``
    at the slots (``high``, ``low``), as :func:`_assembled_slots` takes them) for the
    vector ``x`` (n,) on the reduced DOFs, with each beam's local end displacements
    ``maps[b] @ x[columns[b]]`` written into ``ends`` (n_beams, 12) (padding: 0)."""
    static, mass = 0.0, 0.0
    for s in range(high.size):
        product = x[high[s]] * x[low[s]]
        static += (terms[0, s] + terms[2, s]) * product
        mass += (terms[1, s] + terms[3, s]) * product
    for b in range(maps.shape[0]):
        _ends_of(maps, columns, b, x, ends[b])
    return static, mass


@njit(cache=True)
def _ends_of(maps, columns, b, x, out):
    """``out`` (12,) = beam ``b``'s local end displacements ``maps[b] @ x[columns[b]]`` from
    the vector ``x`` (n,) on the reduced DOFs (a column index of n or more: padding)."""
    n = x.size
    for p in range(12):
        total = 0.0
        for j in range(columns.shape[1]):
            if columns[b, j] < n:
                total += maps[b, p, j] * x[columns[b, j]]
        out[p] = total


@njit(cache=True)
def _form(omega, beams, ends, static, mass, combos):
    """xᵀ D(ω) x, the Rayleigh functional's value at ``omega`` (rad/s), from the parts
    :func:`_form_parts` made of x (not finite at a beam's clamped–clamped frequency)."""
    total = static - omega * omega * mass
    forces = np.empty(12)
    for b in range(beams.shape[0]):
        _beam_applied(beams[b], omega, ends[b], forces, combos)
        for p in range(12):
            total += ends[b, p] * forces[p]
    return total


@njit(cache=True)
def _beam_applied(beam, omega, ends, forces, combos):
    """``forces`` (12,) = the beam's exact local dynamic stiffness at ``omega`` (the blocks
    :func:`_beam_local` writes, without its count) times its ends' local displacements
    ``ends`` (12,)."""
    for stiffness, inertia, flag, i, j in ((beam[EA], beam[RHO_A], beam[AXIAL], 0, 6),
                                           (beam[GJ], beam[RHO_IP], beam[TORSION], 3, 9)):
        diagonal, off = _rod_entries(stiffness, inertia, beam[LENGTH], omega, flag > 0)
        forces[i], forces[j] = diagonal * ends[i] + off * ends[j], off * ends[i] + diagonal * ends[j]
    for stiffness, dofs, signs in ((beam[EIZ], _X_Y, _SAME), (beam[EIY], _X_Z, _FLIP)):
        block = _bending_block(_bending_entries(stiffness, beam[RHO_A], beam[LENGTH], omega, combos))
        for i in range(4):
            total = 0.0
            for j in range(4):
                total += block[i][j] * signs[j] * ends[dofs[j]]
            forces[dofs[i]] = signs[i] * total


@njit(cache=True)
def _form_root(start, first_step, steps, xtol, floor, beams, ends, static, mass, combos):
    """The root of ω ↦ xᵀ D(ω) x nearest ``start`` (rad/s) by the secant method from
    ``start`` and ``start`` (1 + ``first_step``), to a relative step below ``xtol``, or
    where the value is exactly 0 or stalls, or the secant rises after a step below
    ``floor`` (the functional's rounding); NaN where ``steps`` steps do not reach it, a
    value is not finite, or the secant rises after a longer step: the functional falls
    with ω between the beams' clamped–clamped frequencies (D′(ω) is negative
    definite), so such a secant straddles one of them, where it would converge on the pole."""
    old, omega = start, start * (1 + first_step)
    f_old = _form(old, beams, ends, static, mass, combos)
    f = _form(omega, beams, ends, static, mass, combos)
    for _ in range(steps):
        if not (math.isfinite(f_old) and math.isfinite(f)):
            return math.nan
        if f == 0.0 or f == f_old:  # a root, or the functional's rounding floor
            return omega
        if (f - f_old) * (omega - old) > 0.0:
            return omega if abs(omega - old) <= floor * omega else math.nan
        new = omega - f * (omega - old) / (f - f_old)
        if not (new > 0.0 and math.isfinite(new)):
            return math.nan
        if abs(new - omega) <= xtol * new:
            return new
        old, f_old, omega = omega, f, new
        f = _form(omega, beams, ends, static, mass, combos)
    return math.nan


#: The least pivot magnitude :func:`_ordered_solve` takes: any but an exact zero.
SMALLEST_PIVOT = 5e-324

@njit(cache=True)
def _ordered_solve(values, starts, rows, updates, targets, most_growth, growth, z):
    """Solve A z' = z in place (``z`` (n,) in elimination order) by the LDLᵀ without
    pivoting of :func:`ordered_inertia` (``values``, A's lower-triangle slots,
    overwritten), False where a pivot is exactly zero or not finite, or an entry of
    diag(|L| |D| |L|ᵀ) is above ``most_growth`` (the factors are not known to be
    accurate then); a small last pivot is what inverse iteration asks for."""
    if _eliminated(values, starts, rows, updates, targets, SMALLEST_PIVOT, most_growth, growth) < 0:
        return False
    n = starts.size - 1
    for k in range(n):  # L y = z, L's column k below the diagonal: values / pivot
        pivot = values[starts[k]]
        for a in range(starts[k] + 1, starts[k + 1]):
            z[rows[a]] -= values[a] / pivot * z[k]
    for k in range(n):
        z[k] /= values[starts[k]]
    for k in range(n - 1, -1, -1):  # Lᵀ z' = y
        pivot = values[starts[k]]
        for a in range(starts[k] + 1, starts[k + 1]):
            z[k] -= values[a] / pivot * z[rows[a]]
    return True


@njit(cache=True)
def _difference_applied(omega, step, x, beams, maps, columns, high, low, terms, combos, out):
    """``out`` = (D(ω (1 − step)) − D(ω (1 + step))) x, about −2 step ω D′(ω) x: the bodies'
    mass terms at the slots (``high``, ``low``) of ``terms`` (the springs' cancel) and the
    difference of the beams' exact local stiffness on their ends' displacements
    (:func:`_beam_applied`; not finite at a beam's clamped–clamped frequency)."""
    weight = 4 * step * omega * omega  # ω²(1 + step)² − ω²(1 − step)²
    out[:] = 0.0
    for s in range(high.size):
        i, j = high[s], low[s]
        out[i] += weight * terms[1, s] * x[j]
        if i != j:
            out[j] += weight * terms[3, s] * x[i]
    n = x.size
    ends, below, above = np.empty(12), np.empty(12), np.empty(12)
    for b in range(beams.shape[0]):
        _ends_of(maps, columns, b, x, ends)
        _beam_applied(beams[b], omega * (1 - step), ends, below, combos)
        _beam_applied(beams[b], omega * (1 + step), ends, above, combos)
        for j in range(columns.shape[1]):
            if columns[b, j] < n:
                total = 0.0
                for p in range(12):
                    total += maps[b, p, j] * (below[p] - above[p])
                out[columns[b, j]] += total


@njit(cache=True)
def _inverse_step(omega, x, derivative_step, beams, maps, columns, most_growth, plan, terms, buffers, z, rhs):
    """One step of nonlinear inverse iteration on D(ω): x ← D(ω)⁻¹ D′(ω) x, D′(ω) x by
    central differences ω (1 ± ``derivative_step``), then scaled to a largest entry of 1
    (an exact mode stays what it is). D(ω) is equilibrated by the diagonal of |D|(ω),
    as the count equilibrates it, and factorised by :func:`_ordered_solve`. False, x
    left as it was, where D(ω) cannot be formed (a beam's clamped–clamped frequency) or
    its factorisation refuses.

    The arguments as for :func:`ordered_count`; z, rhs : (n,) scratch."""
    order, starts, rows, high, low, updates, targets, beam_slots = plan
    values, magnitudes, _, growth = buffers
    n = order.size
    _difference_applied(omega, derivative_step, x, beams, maps, columns, high, low, terms, np.empty(7), rhs)
    if _assembled_slots(omega, beams, maps, beam_slots, terms, values, magnitudes) < 0:
        return False
    weights = np.empty(n)
    largest = _equilibrated(values, magnitudes, order, starts, high, low, weights)
    if largest < 0 or not math.isfinite(largest):
        return False
    for k in range(n):
        z[k] = rhs[order[k]] * weights[order[k]]
        if not math.isfinite(z[k]):
            return False
    if not _ordered_solve(values, starts, rows, updates, targets, most_growth * largest, growth, z):
        return False
    size = 0.0
    for k in range(n):
        z[k] *= weights[order[k]]
        size = max(size, abs(z[k]))
    if not (size > 0.0 and math.isfinite(size)):
        return False
    for k in range(n):
        x[order[k]] = z[k] / size
    return True


@njit(cache=True, nogil=True)
def rayleigh_roots(vectors, starts, beams, maps, columns, most_growth, plan, terms, buffers, first_step,
                   form_steps, form_xtol, form_floor, settled, inverse_steps, derivative_step, out):
    """Rayleigh values of the exact D(ω) from approximate nodal vectors, by Rayleigh
    quotient iteration: for each row x of ``vectors`` (m, n) from ω₀ = ``starts[i]``
    (rad/s), a step of inverse iteration at ω_k (:func:`_inverse_step`) and ω_(k+1) the
    root of xᵀ D(ω) x nearest ω_k (:func:`_form_root`), until ω_(k+1) lies within
    ``settled`` (relative) of ω_k: ω_(k+1) into ``out[i]``; NaN where that takes more
    than ``inverse_steps`` steps or a step fails. With ``inverse_steps`` 0, the root of
    xᵀ D(ω) x nearest ω₀ for x as given (NaN where that fails).

    beams, maps, columns, plan, terms, buffers : as for :func:`ordered_count`;
    most_growth : the largest entry of diag(|L| |D| |L|ᵀ) the solve takes, relative
    to the largest equilibrated term. first_step, form_steps, form_xtol, form_floor :
    the secant's of :func:`_form_root`. derivative_step : the inverse step's (relative).
    ``vectors`` is overwritten by the last vectors.
    """
    n = vectors.shape[1]
    ends = np.empty((maps.shape[0], 12))
    combos = np.empty(7)
    z, rhs = np.empty(n), np.empty(n)
    high, low = plan[3], plan[4]
    for i in range(starts.size):
        out[i] = math.nan
        x, omega = vectors[i], starts[i]
        for _ in range(inverse_steps):
            if not _inverse_step(omega, x, derivative_step, beams, maps, columns, most_growth, plan, terms, buffers,
                                 z, rhs):
                break
            static, mass = _form_parts(x, maps, columns, high, low, terms, ends)
            new = _form_root(omega, first_step, form_steps, form_xtol, form_floor, beams, ends, static, mass, combos)
            if not math.isfinite(new):
                break
            if abs(new - omega) <= settled * new:
                out[i] = new
                break
            omega = new
        if inverse_steps == 0:  # the functional's root of the vector as given
            static, mass = _form_parts(x, maps, columns, high, low, terms, ends)
            out[i] = _form_root(omega, first_step, form_steps, form_xtol, form_floor, beams, ends, static, mass, combos)
