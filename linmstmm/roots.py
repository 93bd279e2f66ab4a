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

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq, minimize_scalar

#: Grid points per octave of the scan.
POINTS_PER_OCTAVE = 256
#: Lowest scanned circular frequency, rad/s.
OMEGA_FLOOR = 1e-3
#: A singular value below this fraction of the largest counts as zero.
NULL_TOLERANCE = 1e-8


@dataclass(frozen=True)
class Root:
    """A natural circular frequency ``omega`` (rad/s) of multiplicity ``multiplicity``."""

    omega: float
    multiplicity: int


def equilibrate(matrix: np.ndarray, sweeps: int = 4) -> np.ndarray:
    """Row and column scaling by powers of two so every row and column has max |a| ~ 1.

    Keeps the null space (up to column scaling) and makes singular values
    comparable across the mixed units of Ū_all (m, rad, N, N m).
    """
    scaled = np.array(matrix, dtype=float)
    for _ in range(sweeps):
        rows = np.max(np.abs(scaled), axis=1, keepdims=True)
        scaled /= np.exp2(np.round(np.log2(np.where(rows > 0, rows, 1.0))))
        cols = np.max(np.abs(scaled), axis=0, keepdims=True)
        scaled /= np.exp2(np.round(np.log2(np.where(cols > 0, cols, 1.0))))
    return scaled


def nullity(matrix: np.ndarray, tolerance: float = NULL_TOLERANCE) -> int:
    """Number of singular values of the equilibrated matrix below ``tolerance`` × the largest."""
    sigma = np.linalg.svd(equilibrate(matrix), compute_uv=False)
    return int(np.sum(sigma < tolerance * sigma[0]))


class RootFinder:
    """Finds the natural frequencies of a deduced model.

    log_det : callable omega (n,) -> (sign (n,), log|det| (n,)).
    matrix : callable omega (n,) -> Ū_all stack (n, N, N).
    """

    def __init__(self, log_det, matrix, xtol: float = 1e-13):
        self.log_det = log_det
        self.matrix = matrix
        self.xtol = xtol

    def rigid_body_modes(self) -> int:
        """Nullity of Ū_all at ω = 0: zero-frequency (rigid-body) modes."""
        return nullity(self.matrix(np.array([0.0]))[0])

    def _refine_sign_change(self, lo, hi, log_lo, log_hi) -> float:
        reference = max(log_lo, log_hi)

        def scaled_det(omega):
            sign, log_abs = self.log_det(np.array([omega]))
            return sign[0] * np.exp(min(log_abs[0] - reference, 700.0))

        return brentq(scaled_det, lo, hi, xtol=self.xtol * hi, rtol=4 * np.finfo(float).eps)

    def _refine_minimum(self, lo, hi) -> float:
        result = minimize_scalar(lambda w: self.log_det(np.array([w]))[1][0], bounds=(lo, hi),
                                 method="bounded", options={"xatol": self.xtol * hi})
        return float(result.x)

    def _roots_in(self, grid) -> list[Root]:
        """Roots inside the scanned grid (ascending, distinct)."""
        sign, log_abs = self.log_det(grid)
        found = []
        for i in range(len(grid) - 1):
            if sign[i] * sign[i + 1] < 0:
                omega = self._refine_sign_change(grid[i], grid[i + 1], log_abs[i], log_abs[i + 1])
                found.append(Root(omega, max(nullity(self.matrix(np.array([omega]))[0]), 1)))
        for i in range(1, len(grid) - 1):
            is_minimum = log_abs[i] < log_abs[i - 1] and log_abs[i] < log_abs[i + 1]
            no_sign_change = sign[i - 1] == sign[i] == sign[i + 1]
            if is_minimum and no_sign_change:
                omega = self._refine_minimum(grid[i - 1], grid[i + 1])
                multiplicity = nullity(self.matrix(np.array([omega]))[0])
                if multiplicity:
                    found.append(Root(omega, multiplicity))
        return sorted(found, key=lambda root: root.omega)

    def find(self, count: int | None, omega_max: float | None,
             omega_start: float = 2 * np.pi) -> list[Root]:
        """Elastic roots in ascending order: the lowest ``count``, or all up to ``omega_max``.

        Scans octaves upwards from OMEGA_FLOOR; ``omega_start`` is the top of
        the first octave group (rad/s).
        """
        roots: list[Root] = []
        lo, hi = OMEGA_FLOOR, min(omega_start, omega_max) if omega_max else omega_start
        while True:
            octaves = max(np.log2(hi / lo), 1.0)
            grid = np.geomspace(lo, hi, int(np.ceil(octaves * POINTS_PER_OCTAVE)) + 1)
            roots += [r for r in self._roots_in(grid) if not roots or r.omega > roots[-1].omega]
            total = sum(r.multiplicity for r in roots)
            done_by_count = count is not None and total >= count
            done_by_range = omega_max is not None and hi >= omega_max
            if done_by_count or done_by_range:
                break
            if hi > 1e9:
                raise RuntimeError("no further natural frequency below 1e9 rad/s")
            lo, hi = hi, hi * 4 if omega_max is None else min(hi * 4, omega_max)
        if omega_max is not None:
            roots = [r for r in roots if r.omega <= omega_max]
        return roots
