"""Roots of det Ū_all(ω): scan, bracket, refine, multiplicity.

The determinant is handled as (sign, log|det|) so it never overflows. A
frequency grid is scanned in octaves; a sign change brackets a root of odd
multiplicity and Brent's method refines it; a sharp local minimum of
log|det| without a sign change is a candidate even-multiplicity root
(two bending planes of a round tube, symmetric structures) and is refined by
minimisation. Every candidate is confirmed, and its multiplicity measured, by
the numerical null-space dimension of the equilibrated Ū_all.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg
from scipy.optimize import brentq, minimize_scalar

#: Grid points per octave of the scan.
POINTS_PER_OCTAVE = 256
#: Lowest scanned circular frequency, rad/s.
OMEGA_FLOOR = 1e-3
#: The scan for ``count`` roots gives up above this circular frequency, rad/s.
OMEGA_CEILING = 1e9
#: A singular value below this fraction of the largest counts as zero.
NULL_TOLERANCE = 1e-8


def equilibration(matrix: np.ndarray, sweeps: int = 4):
    """Row and column scales (powers of two) giving every row and column max |a| ~ 1.

    Returns (rows (N,), cols (N,)) with ``rows[:, None] * matrix * cols`` balanced.
    Keeps the null space (up to column scaling) and makes singular values
    comparable across the mixed units of Ū_all (m, rad, N, N m).
    """
    rows = np.ones(matrix.shape[0])
    cols = np.ones(matrix.shape[1])
    for _ in range(sweeps):
        scaled = np.abs(rows[:, None] * matrix * cols)
        row_max = scaled.max(axis=1)
        rows /= np.exp2(np.round(np.log2(np.where(row_max > 0, row_max, 1.0))))
        scaled = np.abs(rows[:, None] * matrix * cols)
        col_max = scaled.max(axis=0)
        cols /= np.exp2(np.round(np.log2(np.where(col_max > 0, col_max, 1.0))))
    return rows, cols


def equilibrate(matrix: np.ndarray) -> np.ndarray:
    """The matrix with :func:`equilibration` applied."""
    rows, cols = equilibration(matrix)
    return rows[:, None] * matrix * cols


def nullity(matrix: np.ndarray, tolerance: float = NULL_TOLERANCE) -> int:
    """Number of singular values of the equilibrated matrix below ``tolerance`` × the largest."""
    sigma = np.linalg.svd(equilibrate(matrix), compute_uv=False)
    return int(np.sum(sigma < tolerance * sigma[0]))


class RootFinder:
    """Finds the natural frequencies of a deduced model.

    log_det : callable omega (n,) -> (sign (n,), log|det| (n,)).
    matrix : callable omega (n,) -> Ū_all stack (n, N, N).

    Candidates come from the scan; each is polished by local linearisation
    (Newton for the nonlinear eigenproblem Ū(ω) v = 0): with A = Ū(ω) and
    B = dŪ/dω the generalized eigenvalues μ of A v = μ B v are the offsets
    to the nearby roots, ω ← ω − μ. It converges to machine precision for
    simple and for semisimple multiple roots alike (unlike minimising |det|,
    which stalls at √eps for a double root), and a root of multiplicity m
    shows m eigenvalues μ ≈ 0 at convergence.
    """

    #: Offsets |μ|/ω below this are the same root (multiplicity).
    SAME_ROOT = 1e-9
    #: Offsets |μ|/ω below this are polished as members of the same cluster.
    CLUSTER_WINDOW = 2e-3

    def __init__(self, log_det, matrix, xtol: float = 1e-14):
        self.log_det = log_det
        self.matrix = matrix
        self.xtol = xtol

    def rigid_body_modes(self) -> int:
        """Nullity of Ū_all at ω = 0: zero-frequency (rigid-body) modes."""
        return nullity(self.matrix(np.array([0.0]))[0])

    def _offsets(self, omega: float) -> np.ndarray:
        """Real generalized eigenvalues μ of (Ū(ω), dŪ/dω), sorted by |μ|."""
        step = 1e-6 * omega
        A, plus, minus = self.matrix(np.array([omega, omega + step, omega - step]))
        rows, cols = equilibration(A)
        scale = rows[:, None] * cols[None, :]
        mu = scipy.linalg.eigvals(A * scale, (plus - minus) / (2 * step) * scale)
        mu = mu[np.isfinite(mu)]
        real = mu[np.abs(mu.imag) <= 1e-6 * np.abs(mu) + 1e-300].real
        return real[np.argsort(np.abs(real))]

    def polish(self, omega: float, iterations: int = 40):
        """Converge on the root nearest ``omega``. Returns (root, offsets there)."""
        for _ in range(iterations):
            mu = self._offsets(omega)
            if mu.size == 0:
                break
            omega -= mu[0]
            if abs(mu[0]) <= self.xtol * omega:
                break
        return omega, self._offsets(omega)

    def cluster(self, omega: float) -> list[float]:
        """Every root in the cluster around the root nearest ``omega``, ascending."""
        centre, mu = self.polish(omega)
        near = mu[np.abs(mu) < self.CLUSTER_WINDOW * centre]
        roots = [centre] * int(np.sum(np.abs(near) < self.SAME_ROOT * centre))
        for offset in near[np.abs(near) >= self.SAME_ROOT * centre]:
            member = self.polish(centre - offset)[0]
            if all(abs(member - r) > self.SAME_ROOT * r for r in roots):
                roots.append(member)
        return sorted(roots)

    def _refine_sign_change(self, lo, hi, log_lo, log_hi) -> float:
        reference = max(log_lo, log_hi)

        def scaled_det(omega):
            sign, log_abs = self.log_det(np.array([omega]))
            return sign[0] * np.exp(min(log_abs[0] - reference, 700.0))

        return brentq(scaled_det, lo, hi, xtol=1e-12 * hi)

    def _candidates(self, grid) -> list[float]:
        """Starting points: brackets of sign changes and sharp minima of log|det|."""
        sign, log_abs = self.log_det(grid)
        starts = [self._refine_sign_change(grid[i], grid[i + 1], log_abs[i], log_abs[i + 1])
                  for i in range(len(grid) - 1) if sign[i] * sign[i + 1] < 0]
        for i in range(1, len(grid) - 1):
            is_minimum = log_abs[i] < log_abs[i - 1] and log_abs[i] < log_abs[i + 1]
            if is_minimum and sign[i - 1] == sign[i] == sign[i + 1]:
                result = minimize_scalar(lambda w: self.log_det(np.array([w]))[1][0],
                                         bounds=(grid[i - 1], grid[i + 1]), method="bounded")
                if nullity(self.matrix(np.array([result.x]))[0], 1e-5):
                    starts.append(float(result.x))
        return sorted(starts)

    def _roots_in(self, grid, known: list[float]) -> list[float]:
        """Roots found from candidates in the grid, skipping clusters already known."""
        found = list(known)
        for start in self._candidates(grid):
            members = self.cluster(start)
            if members and not any(abs(members[0] - r) <= self.SAME_ROOT * r for r in found):
                found += members
        return sorted(found)

    def find(self, count: int | None, omega_max: float | None,
             omega_start: float = 2 * np.pi) -> list[float]:
        """Elastic roots (rad/s) ascending, each repeated per multiplicity.

        The lowest ``count``, or all up to ``omega_max``. Scans octaves
        upwards from OMEGA_FLOOR; ``omega_start`` is the top of the first scan.
        Fewer than ``count`` come back if there are no more below OMEGA_CEILING.
        """
        roots: list[float] = []
        lo, hi = OMEGA_FLOOR, min(omega_start, omega_max) if omega_max else omega_start
        while True:
            octaves = max(np.log2(hi / lo), 1.0)
            grid = np.geomspace(lo, hi, int(np.ceil(octaves * POINTS_PER_OCTAVE)) + 1)
            roots = self._roots_in(grid, roots)
            done_by_count = count is not None and len(roots) >= count
            done_by_range = omega_max is not None and hi >= omega_max
            if done_by_count or done_by_range:
                break
            if hi >= OMEGA_CEILING:  # a discrete model can have fewer modes than asked for
                break
            lo, hi = hi, hi * 4 if omega_max is None else min(hi * 4, omega_max)
        if omega_max is not None:
            roots = [r for r in roots if r <= omega_max]
        return roots[:count] if count is not None else roots


class DeflatedSystem:
    """Ū_all with its frequency-independent null space removed.

    Redundant rigid constraints (a rigid direction fixed at both ends, ``inf``
    springs closing a loop) leave internal forces statically indeterminate:
    Ū_all is then singular at every ω, with a constant null vector and a
    constant left null vector. Both are found at two generic frequencies and
    projected out: ``Ū' = Wᵀ Ū V`` with V, W orthonormal complements, whose
    determinant vanishes exactly at the natural frequencies.

    matrix : callable omega (n,) -> (n, N, N).
    """

    def __init__(self, matrix, probe=(0.7310, 1.9137, 5.3)):
        self._full = matrix
        samples = matrix(np.asarray(probe, dtype=float))
        self._rows, self._cols = equilibration(samples[0])
        samples = self._rows[:, None] * samples * self._cols
        r = min(nullity(sample) for sample in samples)
        self.indeterminate = r
        self._right = self._left = None
        if r == 0:
            return
        u, _, vt = np.linalg.svd(samples[0])
        right_null, left_null = vt[-r:].T, u[:, -r:]
        for sample in samples[1:]:
            scale = np.abs(sample).max()
            if (np.abs(sample @ right_null).max() > 1e-9 * scale
                    or np.abs(left_null.T @ sample).max() > 1e-9 * scale):
                raise RuntimeError("Ū_all is singular at every frequency with a null space "
                                   "that moves with frequency: the model has a mechanism "
                                   "or a degenerate constraint")
        self._right = np.linalg.svd(right_null)[0][:, r:]
        self._left = np.linalg.svd(left_null)[0][:, r:]

    def matrix(self, omega) -> np.ndarray:
        """(n, N−r, N−r) deflated Ū_all."""
        full = self._full(omega)
        if self._right is None:
            return full
        return self._left.T @ (self._rows[:, None] * full * self._cols) @ self._right

    def log_det(self, omega):
        """(sign, log|det|) of the deflated matrix, each (n,)."""
        return np.linalg.slogdet(self.matrix(omega))
