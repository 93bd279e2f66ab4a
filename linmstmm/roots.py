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
POINTS_PER_OCTAVE = 32
#: Lowest scanned circular frequency, rad/s.
OMEGA_FLOOR = 1e-3
#: The scan for ``count`` roots gives up above this circular frequency, rad/s.
OMEGA_CEILING = 1e9
#: A singular value below this fraction of the largest counts as zero.
NULL_TOLERANCE = 1e-8
#: The same, at a root polished to machine precision (multiplicity).
MULTIPLICITY_TOLERANCE = 1e-9


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


def count_zeros(log_det, a: float, b: float, max_points: int = 20000) -> int:
    """Number of natural frequencies in (a, b), rad/s, with multiplicity.

    Argument principle: det Ū_all(ω) is an entire function of ω, real on the
    real axis, whose zeros are exactly the natural frequencies ±ω_k with
    their multiplicities (a null vector of Ū_all is a mode and vice versa;
    no inverse is ever taken, so there are no poles). The winding number of
    det along an ellipse through a and b counts them; by conjugate symmetry
    the upper half-arc suffices: count = Δarg(b → a over the arc) / π. The
    arc is refined until no phase step exceeds π/4, and the total must come
    out an integer multiple of π.

    log_det : callable complex omega (n,) -> (phase factor (n,), log|det| (n,)).
    """
    def phase(theta):
        centre, radius = (a + b) / 2, (b - a) / 2
        omega = centre + radius * np.cos(theta) + 0.5j * radius * np.sin(theta)
        sign, log_abs = log_det(omega)
        if not np.all(np.isfinite(log_abs)):
            raise RuntimeError("det Ū_all vanishes on the counting contour: Ū_all is singular "
                               "at every frequency (undeflated indeterminate constraint)")
        return np.angle(sign)

    theta = np.linspace(0.0, np.pi, 65)
    angles = phase(theta)
    while True:
        steps = np.angle(np.exp(1j * np.diff(angles)))  # wrapped into (−π, π]
        coarse = np.abs(steps) > np.pi / 4
        if not coarse.any():
            break
        if theta.size > max_points:
            raise RuntimeError(f"cannot count the roots in ({a:.6g}, {b:.6g}) rad/s: the phase of "
                               "det Ū_all varies too fast along the counting contour")
        middles = (theta[:-1][coarse] + theta[1:][coarse]) / 2
        order = np.argsort(np.r_[theta, middles])
        theta, angles = np.r_[theta, middles][order], np.r_[angles, phase(middles)][order]
    winding = steps.sum() / np.pi
    if abs(winding - round(winding)) > 0.05:
        raise RuntimeError(f"the root count in ({a:.6g}, {b:.6g}) rad/s is not an integer "
                           f"({winding:.3f}): det Ū_all is not accurate enough there")
    return int(round(abs(winding)))


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
    #: Newton steps |μ|/ω that stop shrinking below this have reached the rounding floor.
    STAGNATION = 1e-11
    #: Offsets |μ|/ω below this are polished as members of the same cluster.
    CLUSTER_WINDOW = 2e-3

    def __init__(self, log_det, matrix, xtol: float = 1e-14,
                 points_per_octave: int = POINTS_PER_OCTAVE, points_per_root: int = 6):
        self.log_det = log_det
        self.matrix = matrix
        self.xtol = xtol
        self.points_per_octave = points_per_octave
        self.points_per_root = points_per_root
        #: root -> relative size of the last Newton step that reached it
        self.last_step: dict[float, float] = {}

    def rigid_body_modes(self) -> int:
        """Nullity of Ū_all at ω = 0: zero-frequency (rigid-body) modes."""
        return nullity(self.matrix(np.array([0.0]))[0])

    def _offsets(self, omega: float) -> np.ndarray:
        """Real generalized eigenvalues μ of (Ū(ω), dŪ/dω), sorted by |μ|."""
        if not (np.isfinite(omega) and omega > 0):
            return np.zeros(0)
        step = 1e-6 * omega
        A, plus, minus = self.matrix(np.array([omega, omega + step, omega - step]))
        if not (np.all(np.isfinite(A)) and np.all(np.isfinite(plus)) and np.all(np.isfinite(minus))):
            return np.zeros(0)
        rows, cols = equilibration(A)
        scale = rows[:, None] * cols[None, :]
        mu = scipy.linalg.eigvals(A * scale, (plus - minus) / (2 * step) * scale)
        mu = mu[np.isfinite(mu)]
        real = mu[np.abs(mu.imag) <= 1e-6 * np.abs(mu) + 1e-300].real
        return real[np.argsort(np.abs(real))]

    def polish(self, omega: float, iterations: int = 40):
        """Converge on the root nearest ``omega``.

        Stops at |μ| <= xtol·ω, or when the steps stop shrinking below
        STAGNATION·ω (the rounding floor of Ū_all). Returns (root, offsets
        there), or (None, offsets) if it did not converge.
        """
        previous = np.inf
        for _ in range(iterations):
            mu = self._offsets(omega)
            if mu.size == 0:
                return None, mu
            step = abs(mu[0])
            omega -= mu[0]
            if step <= self.xtol * omega or (step <= self.STAGNATION * omega and step > previous / 2):
                self.last_step[omega] = step / omega
                return omega, self._offsets(omega)
            previous = step
        return None, mu

    def cluster(self, omega: float) -> list[float]:
        """Every root in the cluster around the root nearest ``omega``, ascending.

        The multiplicity of the polished root is the numerical null-space
        dimension of the balanced Ū_all there; the other small offsets μ are
        polished in turn and kept when they reach a different root.
        """
        centre, mu = self.polish(omega)
        if centre is None:
            return []
        multiplicity = max(nullity(self.matrix(np.array([centre]))[0], MULTIPLICITY_TOLERANCE), 1)
        roots = [centre] * multiplicity
        for offset in mu[np.abs(mu) < self.CLUSTER_WINDOW * centre]:
            if abs(offset) < self.SAME_ROOT * centre:
                continue
            member = self.polish(centre - offset)[0]
            if member is not None and all(abs(member - r) > self.SAME_ROOT * r for r in roots):
                roots.append(member)
        return sorted(roots)

    def _refine_sign_change(self, lo, hi, log_lo, log_hi) -> float:
        reference = max(log_lo, log_hi)

        def scaled_det(omega):
            sign, log_abs = self.log_det(np.array([omega]))
            return sign[0] * np.exp(min(log_abs[0] - reference, 700.0))

        # Only a starting point for polish(): a loose tolerance is enough, and
        # a root of odd multiplicity > 1 is too flat for a tight one.
        return brentq(scaled_det, lo, hi, xtol=1e-6 * hi, maxiter=200)

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

    def _roots_in(self, grid) -> list[float]:
        """Roots inside (grid[0], grid[-1]) reached from the scan's candidates."""
        found: list[float] = []
        for start in self._candidates(grid):
            self._merge(found, self.cluster(start), grid[0], grid[-1])
        return sorted(found)

    def _merge(self, found: list[float], members, lo, hi) -> None:
        """Add the cluster ``members`` inside (lo, hi] to ``found`` unless already there."""
        members = [m for m in members if lo < m <= hi]
        if members and not any(abs(members[0] - r) <= self.SAME_ROOT * r for r in found):
            found += members

    def _split_point(self, lo, hi) -> float:
        """A point in the middle half of (lo, hi) where |det| is largest: far from any root."""
        trial = lo + (hi - lo) * np.linspace(0.3, 0.7, 9)
        return float(trial[np.argmax(self.log_det(trial)[1])])

    def _isolate(self, lo, hi, expected, found, depth=0) -> list[float]:
        """Bisect (lo, hi] on the root count until every root is found.

        found : roots already found (anywhere). Returns the roots in (lo, hi].
        Raises RuntimeError if the count cannot be met.
        """
        inside = sorted(r for r in found if lo < r <= hi)
        if len(inside) == expected:
            return inside
        if len(inside) < expected and (hi - lo) < 1e-7 * hi and found:
            # The interval has shrunk onto a root: the missing ones coincide with it.
            nearest = min(found, key=lambda r: abs(r - (lo + hi) / 2))
            return sorted(inside + [nearest] * (expected - len(inside)))
        if depth > 60 or len(inside) > expected:
            raise RuntimeError(f"cannot separate the {expected} roots in ({lo:.12g}, {hi:.12g}) "
                               f"rad/s in float64 (found {len(inside)}): ask for more digits")
        found = list(found)
        self._merge(found, self.cluster((lo + hi) / 2), lo, hi)
        inside = sorted(r for r in found if lo < r <= hi)
        if len(inside) == expected:
            return inside
        middle = self._split_point(lo, hi)
        roots = []
        for a, b in ((lo, middle), (middle, hi)):
            roots += self._isolate(a, b, count_zeros(self.log_det, a, b), found, depth + 1)
        return sorted(roots)

    def segment(self, lo: float, hi: float) -> list[float]:
        """Every root in (lo, hi], rad/s, ascending, repeated per multiplicity.

        The argument-principle count says how many there are; a scan with at
        least ``points_per_root`` points per counted root finds them; bisection
        on the count finds any the scan missed.
        """
        expected = count_zeros(self.log_det, lo, hi)
        if expected == 0:
            return []
        octaves = max(np.log2(hi / lo), 1.0)
        points = max(octaves * self.points_per_octave, self.points_per_root * expected)
        grid = np.geomspace(lo, hi, int(np.ceil(points)) + 1)
        return self._isolate(lo, hi, expected, self._roots_in(grid))

    def find(self, count: int | None, omega_max: float | None,
             omega_start: float = 2 * np.pi) -> list[float]:
        """Elastic roots (rad/s) ascending, each repeated per multiplicity.

        The lowest ``count``, or all up to ``omega_max``, with none missed:
        each scanned segment is checked against the root count. Scans
        upwards from OMEGA_FLOOR; ``omega_start`` is the top of the first
        segment. Fewer than ``count`` come back if there are no more below
        OMEGA_CEILING.
        """
        roots: list[float] = []
        lo, hi = OMEGA_FLOOR, min(omega_start, omega_max) if omega_max else omega_start
        while True:
            roots += self.segment(lo, hi)
            done_by_count = count is not None and len(roots) >= count
            done_by_range = omega_max is not None and hi >= omega_max
            if done_by_count or done_by_range or hi >= OMEGA_CEILING:
                break
            lo, hi = hi, hi * 4 if omega_max is None else min(hi * 4, omega_max)
        return roots[:count] if count is not None else roots


def release_indeterminate(deduction, probe=(0.7310, 1.9137, 5.3)) -> int:
    """Find and release statically indeterminate unknowns of ``deduction``.

    Redundant rigid constraints (a rigid direction fixed at both ends, ``inf``
    springs closing a loop) make Ū_all singular at every ω, with constant
    right and left null vectors. They are found at generic frequencies
    (after balancing) and confirmed to be constant; the unknowns and rows
    with the largest weight in them are released (:meth:`Deduction.release`).
    Returns the number released. Raises RuntimeError for a null space that
    moves with ω (a mechanism).
    """
    samples = deduction.matrix(np.asarray(probe, dtype=float))
    rows, cols = equilibration(samples[0])
    samples = rows[:, None] * samples * cols
    r = min(nullity(sample) for sample in samples)
    if r == 0:
        return 0
    u, _, vt = np.linalg.svd(samples[0])
    right_null, left_null = vt[-r:].T, u[:, -r:]
    for sample in samples[1:]:
        scale = np.abs(sample).max()
        if (np.abs(sample @ right_null).max() > 1e-9 * scale
                or np.abs(left_null.T @ sample).max() > 1e-9 * scale):
            raise RuntimeError("Ū_all is singular at every frequency with a null space that "
                               "moves with frequency: the model has a mechanism")
    released_columns = scipy.linalg.qr(right_null.T, pivoting=True)[2][:r]
    released_rows = scipy.linalg.qr(left_null.T, pivoting=True)[2][:r]
    deduction.release(released_columns, released_rows)
    return r
