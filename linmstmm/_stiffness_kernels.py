"""Compiled kernels of the Wittrick–Williams count (:mod:`linmstmm.wittrick_williams`).

Compiled once by numba (``@njit(cache=True)``), float64 arrays and integers
only, each mirroring a numpy counterpart that stays the readable reference and
the test oracle (tests/test_wittrick_williams.py compares them):

* :func:`assembled` — :func:`linmstmm.dynamic_stiffness.clamped_counts` and
  :meth:`linmstmm.wittrick_williams.ModeCounter.matrices` (at one ω): J₀(ω) and the reduced
  exact dynamic stiffness D(ω) with the scale of its terms;
* :func:`block_inertia` — :func:`linmstmm.wittrick_williams._block_inertia`;
* :func:`count` — :meth:`linmstmm.wittrick_williams.ModeCounter._numpy`: the
  whole count J(ω) in one call (J₀, D(ω), its equilibration, and LDLᵀ
  factorisations by LAPACK's ``dsytrf`` of it shifted up and down), compiled
  ``nogil``, so that counts at several frequencies can run on threads side by
  side.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from linmstmm._lapack import lapack_routine
from linmstmm.dynamic_stiffness import POLE, SERIES_BELOW, SERIES_COEFFICIENTS, SERIES_TERMS

#: Columns of the beam table the kernels take (see :func:`beam_columns`).
EA, GJ, EIY, EIZ, RHO_A, RHO_IP, LENGTH, AXIAL, TORSION = range(9)
_X_Y = np.array([1, 5, 7, 11])
_X_Z = np.array([2, 4, 8, 10])
_FLIP = np.array([1.0, -1.0, 1.0, -1.0])
_DSYTRF = lapack_routine("dsytrf", 8)
#: Workspace LAPACK's dsytrf is given per unknown: its block size (64), with which
#: it factorises blocked, as scipy's wrapper lets it.
WORK_PER_UNKNOWN = 64


def beam_columns(beams) -> np.ndarray:
    """(n_beams, 9) float64 table of a :class:`~linmstmm.dynamic_stiffness.BeamTable`
    in the column order EA … TORSION above (flags as 0.0 / 1.0)."""
    return np.column_stack([beams.EA, beams.GJ, beams.EIy, beams.EIz, beams.rhoA, beams.rhoIp,
                            beams.L, beams.axial.astype(float), beams.torsion.astype(float)])


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
def _bending(stiffness, inertia, length, omega, local, dofs, signs, combos):
    """Write one plane's 4 × 4 exact bending block (``signs`` flip θ) into ``local``."""
    beta = (inertia * omega * omega / stiffness) ** 0.25
    series = _combinations(beta * length, combos)
    b1, b2, b3 = (1 / length, 1 / length ** 2, 1 / length ** 3) if series else (beta, beta ** 2, beta ** 3)
    f = stiffness / combos[0]
    k11, k12, k13, k14 = f * b3 * combos[1], f * b2 * combos[2], -f * b3 * combos[3], f * b2 * combos[4]
    k22, k24 = f * b1 * combos[5], f * b1 * combos[6]
    block = np.array([[k11, k12, k13, k14], [k12, k22, -k14, k24],
                      [k13, -k14, k11, -k12], [k14, k24, -k12, k22]])
    for i in range(4):
        for j in range(4):
            local[dofs[i], dofs[j]] = block[i, j] * signs[i] * signs[j]


@njit(cache=True)
def _rod(stiffness, inertia, length, omega, deformable, local, a, b):
    """Write one rod's 2 × 2 block at DOFs ``a``, ``b`` into ``local`` (the consistent
    mass alone where it is rigid)."""
    if not deformable:
        m = -omega * omega * inertia * length / 6
        local[a, a], local[a, b], local[b, a], local[b, b] = 2 * m, m, m, 2 * m
        return
    k = omega * math.sqrt(inertia / stiffness)
    kl = k * length
    if kl < 1e-8:
        scale, diagonal, off = stiffness / length, 1.0 - kl * kl / 3, -1.0 - kl * kl / 6
    else:
        scale, diagonal, off = stiffness * k / math.sin(kl), math.cos(kl), -1.0
    local[a, a], local[a, b], local[b, a], local[b, b] = scale * diagonal, scale * off, scale * off, scale * diagonal


@njit(cache=True)
def _clamped(beam, omega):
    """J₀ of one beam at ``omega``; −1 within POLE of a clamped–clamped frequency."""
    total = 0
    for stiffness, inertia, flag in ((beam[EA], beam[RHO_A], beam[AXIAL]), (beam[GJ], beam[RHO_IP], beam[TORSION])):
        if flag > 0:
            phase = omega * beam[LENGTH] * math.sqrt(inertia / stiffness) / math.pi
            nearest = math.floor(phase + 0.5)
            if nearest >= 1 and abs(phase - nearest) < POLE * phase:
                return -1
            total += int(math.floor(phase))
    combos = np.empty(7)
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
    clamped = 0
    for i in range(n):
        for j in range(n):
            matrix[i, j] = static[i, j] - omega * omega * mass[i, j]
            magnitude[i, j] = abs(static[i, j]) + omega * omega * abs(mass[i, j])
    local = np.zeros((12, 12))
    combos = np.empty(7)
    for b in range(beams.shape[0]):
        beam = beams[b]
        count = _clamped(beam, omega)
        if count < 0:
            return -1
        clamped += count
        local[:] = 0.0
        _rod(beam[EA], beam[RHO_A], beam[LENGTH], omega, beam[AXIAL] > 0, local, 0, 6)
        _rod(beam[GJ], beam[RHO_IP], beam[LENGTH], omega, beam[TORSION] > 0, local, 3, 9)
        _bending(beam[EIZ], beam[RHO_A], beam[LENGTH], omega, local, _X_Y, np.ones(4), combos)
        _bending(beam[EIY], beam[RHO_A], beam[LENGTH], omega, local, _X_Z, _FLIP, combos)
        _add_mapped(local, maps[b], columns[b], matrix, magnitude)
    return clamped


@njit(cache=True)
def _add_mapped(local, map_, columns, matrix, magnitude):
    """Add ``map_.T @ local @ map_`` at ``columns`` of ``matrix`` (and its absolute
    value to ``magnitude``)."""
    rows, width = map_.shape
    mapped = np.zeros((rows, width))
    for p in range(rows):
        for q in range(rows):
            if local[p, q] != 0.0:
                for j in range(width):
                    mapped[p, j] += local[p, q] * map_[q, j]
    for i in range(width):
        for j in range(width):
            value = 0.0
            for p in range(rows):
                value += map_[p, i] * mapped[p, j]
            matrix[columns[i], columns[j]] += value
            magnitude[columns[i], columns[j]] += abs(value)


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
    (:data:`linmstmm.wittrick_williams.SINGULAR_PIVOT`); work : (n · WORK_PER_UNKNOWN,)
    float64. D(ω) is equilibrated by the diagonal of |D|(ω), shifted by ± the rounding
    level and factorised both ways, whose counts must agree
    (:func:`linmstmm.wittrick_williams._negative_eigenvalues`, the same numbers in
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
