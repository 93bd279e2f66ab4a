"""Balancing Ū_all and reading its null space: multiplicities and indeterminate unknowns.

Ū_all mixes metres, radians, newtons and newton-metres, so its singular values
mean something only after exact power-of-two row and column scaling
(:func:`equilibration`). The null-space dimension at a root is the root's
(semisimple) multiplicity (:func:`nullity`); a null space present at every
frequency is a set of statically indeterminate unknowns, released before any
root is sought (:func:`release_indeterminate`).
"""
from __future__ import annotations

import functools
import math

import numpy as np
import scipy.linalg  # scipy.linalg.blas and scipy.linalg.lapack with it

from linmstmm.numeric import power_of_two_scale, scale_into_half_one
from linmstmm.own_units import extent, unit_sizes

#: A singular value below this fraction of the largest counts as zero.
NULL_TOLERANCE = 1e-8


#: Sweeps of :func:`equilibration` unless told.
EQUILIBRATION_SWEEPS = 4


def equilibration(matrix: np.ndarray, sweeps: int = EQUILIBRATION_SWEEPS, start=None):
    """Row and column scales (powers of two) giving every row and column max |a| ~ 1.

    matrix : (N, M) or a stack (n, N, M). Returns (rows (…, N), cols (…, M))
    with ``rows[..., :, None] * matrix * cols[..., None, :]`` balanced.
    Keeps the null space (up to column scaling) and makes singular values
    comparable across the mixed units of Ū_all (m, rad, N, N m).
    start : (rows (N,), cols (M,)) to balance from, positive, default ones (then
    the scales are powers of two, exact). The balance reached depends on where it
    starts: from Ū_all in the model's own units (:func:`own_units_start`) it is
    the same whatever units the model is written in.
    """
    size = np.abs(matrix)
    rows = np.ones(matrix.shape[:-1])
    cols = np.ones(matrix.shape[:-2] + matrix.shape[-1:])
    if start is not None:
        rows, cols = rows * start[0], cols * start[1]
    weighted = rows[..., :, None] * size  # the rows' part of the scaled |a|, formed once per change of rows
    scaled = np.empty_like(weighted)
    peaks = None  # each column's largest weighted |a|, found once per change of rows
    for _ in range(sweeps):
        row_factors = power_of_two_scale(np.multiply(weighted, cols[..., None, :], out=scaled).max(axis=-1))
        rows_kept = bool((row_factors == 1.0).all())
        if not rows_kept:
            rows *= row_factors
            np.multiply(rows[..., :, None], size, out=weighted)
        if peaks is None or not rows_kept:
            peaks = weighted.max(axis=-2)
        # a column's largest scaled |a| is its largest weighted |a| times its scale: rounding a
        # product with the same positive factor keeps the order, so the same number, bit for bit
        column_factors = power_of_two_scale(peaks * cols)
        cols *= column_factors
        if rows_kept and (column_factors == 1.0).all():
            break  # a sweep that changed nothing: so would every one after it (Ū_all of a launcher's probe: the second)
    return rows, cols


def own_units_start(deduction, frequency: float | None = None):
    """The scales that write Ū_all in the model's own units, to start :func:`equilibration` from.

    Each row and unknown of the plain Ū_all is divided, or multiplied, by the
    size of its kind (:meth:`~linmstmm.deduction.Deduction.kinds`) in the
    model's own units (:func:`linmstmm.own_units.unit_sizes` at its lowest
    :func:`characteristic_frequencies`): so scaled, Ū_all is the same matrix
    whatever units the model is written in, and so is its balance. Balanced
    from unit scales, the launcher written in µm, pg and µs kept singular
    values of 1e-13 of the largest at every probe (1e-3 to 1e-6 in SI) and was
    taken for a mechanism: max-balancing stops at a balance that depends on
    where it starts.

    Parameters
    ----------
    deduction : linmstmm.deduction.Deduction
        The deduced system, as it stands (less released unknowns).
    frequency : float, optional
        rad/s, the lowest of its :func:`characteristic_frequencies` where the
        caller has them already (found here otherwise).

    Returns
    -------
    rows : numpy.ndarray, shape (N,)
        1 / size of each row's kind.
    cols : numpy.ndarray, shape (N,)
        Size of each unknown's kind (m, rad, N m or N in the model's units).
    """
    if frequency is None:
        frequency = min(characteristic_frequencies(deduction.topology))
    sizes = unit_sizes(deduction.topology, frequency)
    row_kinds, column_kinds = deduction.kinds()
    return 1 / sizes[row_kinds], sizes[column_kinds]


def nullity(matrix: np.ndarray, tolerance: float = NULL_TOLERANCE, scales=None) -> int:
    """Number of singular values of the equilibrated matrix below ``tolerance`` × the largest.

    scales : (rows, cols) to balance with; default from ``matrix`` itself. At
    a root, take them from a nearby frequency: balancing exactly there would
    blow up a row whose only entry vanishes at the root (cos kL of a rod)
    and hide the singularity.
    """
    rows, cols = equilibration(matrix) if scales is None else scales
    return _small_singular_values(rows[:, None] * matrix * cols, tolerance)


def _small_singular_values(balanced: np.ndarray, tolerance: float) -> int:
    """Number of singular values of ``balanced`` (N, M) below ``tolerance`` × the largest."""
    sigma = np.linalg.svd(balanced, compute_uv=False)
    return int(np.sum(sigma < tolerance * sigma[0]))


#: A null space present at every probe is released only where its singular values are
#: below this fraction of the largest: redundant rigid constraints make it exact
#: (at most 1.4e-16 over the test suite's models), while a loop of two beams between
#: the same two points, stiff axially, with a joint beside it showed 8e-10 at every
#: probe, was released under NULL_TOLERANCE, and lost 2.7e-4 of its frequencies.
INDETERMINATE_TOLERANCE = 1e-11
#: Generic frequencies (multiples of the model's :func:`characteristic_frequencies`)
#: at which the constant null space of Ū_all is sought.
PROBES = (0.07310, 0.19137, 0.53)


def characteristic_frequencies(topology) -> list[float]:
    """Frequencies of the model's own scale, rad/s, from its elements alone, to probe at.

    First the lowest of each beam's bending scale √(E I_min / ρA) / L², its
    torsion scale √(G J / ρ I_p) / L (a section whose I_p dwarfs J twists far
    below its bending: a strip with Iy/Iz = 1e11 at 0.017 rad/s, 300 times below
    its bending scale, where a count from the search's floor could not resolve
    the phase), and √(k / m) for each spring's softest finite, unreleased
    translation k against the model's whole mass m; then the same with the beams' length L taken as all
    beams together (a chain of 1000 short beams bends as one long one: its
    pieces' own scale puts the probes where Ū_all overflows); where there are
    neither, the springs' rotations (:func:`_torsion_scales`). They move with
    the model's units and size, so probes at multiples of them sit at the same
    place among the model's own frequencies whatever the units (fixed probes
    at 0.7–5 rad/s sat 40 times above the first mode of a star scaled ×1000,
    where Ū_all's conditioning hid its null space).
    """
    records = [element.record for element in topology.elements if element.record is not None]
    mass = sum(record.mass for record in records if record.kind in ("rigid", "beam"))
    beams = [record for record in records if record.kind == "beam" and record.rho > 0]
    springs = [math.sqrt(k / mass) for k in _softest_finite([record.k[:3] for record in records
                                                           if record.kind == "spring"]) if mass > 0]
    span = sum(beam.length for beam in beams)
    candidates = []
    for length in ([beam.length for beam in beams], [span] * len(beams)):
        scales = springs + [math.sqrt(beam.E * min(beam.Iy, beam.Iz) / (beam.rho * beam.A)) / L ** 2
                            for beam, L in zip(beams, length)]
        scales += [math.sqrt(beam.G * beam.J / (beam.rho * beam.Ip)) / L
                   for beam, L in zip(beams, length) if beam.torsion and beam.Ip > 0]
        candidates.append(float(min(scales or _torsion_scales(topology, records, mass) or [1.0])))
    return list(dict.fromkeys(candidates))


def _torsion_scales(topology, records, mass) -> list[float]:
    """√(k / (m d²)) for each spring's softest finite, unreleased rotation k against the
    model's whole mass m at its extent d (the largest distance between ports), rad/s:
    the scale of a model whose only compliance is rotational (rods on pins with
    torsion springs); empty where there is none."""
    size = extent(topology)
    if not (mass > 0 and size > 0):
        return []
    return [math.sqrt(k / (mass * size ** 2))
            for k in _softest_finite([record.k[3:] for record in records if record.kind == "spring"])]


def _softest_finite(stiffnesses: list) -> list[float]:
    """For each of the springs' (3,) stiffnesses that has a finite, unreleased one (k > 0),
    the least of those, in the springs' order (all at once: a chain has thousands)."""
    if not stiffnesses:
        return []
    k = np.array(stiffnesses, dtype=float)
    usable = np.isfinite(k) & (k > 0)
    softest = np.where(usable, k, np.inf).min(axis=1)
    return softest[usable.any(axis=1)].tolist()


#: A null space that moves with ω at INDETERMINATE_TOLERANCE is looked for again at
#: this one: a stiff member in a loop (a random loop with Iy/Iz = 6e6) leaves Ū_all
#: singular to 5e-9 at every low frequency, nearly indeterminate but not, and it is
#: not a mechanism.
ROUNDING_TOLERANCE = 1e-12


#: A probe read by a faster carry (``screen`` of :func:`release_indeterminate`) lets it
#: release nothing only where the probe's smallest singular value (balanced) is at least
#: this many times the tolerance: there the numpy carry finds none below the tolerance
#: either. The compiled plain Ū_all and the numpy carry's, balanced, differ by up to
#: 2e-11 of the largest entry at the probes of 200 random models, 9e-8 on a loop with
#: Iy/Iz 2.7e11, where both lose that much to cancellation (each as far from the exact
#: matrix as the other). Closer to singular, the numpy carry reads the probes: 124 of
#: 681 models the tests draw that are not statically determinate (36 of them release
#: something), neither launcher (smallest singular values 2e-3 of the largest).
SCREEN_MARGIN = 1e5


def release_indeterminate(deduction, probe=None, tolerance: float = INDETERMINATE_TOLERANCE,
                          screen=None, scales=None) -> int:
    """Find and release statically indeterminate unknowns of ``deduction``.

    probe : rad/s, the generic frequencies to look at (default :data:`PROBES`
    times each of the model's :func:`characteristic_frequencies` in turn, until
    one can be read: no overflow, no null space that moves).

    Redundant rigid constraints (a rigid direction fixed at both ends, ``inf``
    springs closing a loop) make Ū_all singular at every ω, with constant
    right and left null vectors. They are found at generic frequencies
    (after balancing) and confirmed to be constant; the unknowns and rows
    with the largest weight in them are released (:meth:`Deduction.release`).
    tolerance : relative singular value below which a direction is null
    (:func:`nullity`). Returns the number released. Raises RuntimeError for a
    null space that moves with ω (a mechanism) at ROUNDING_TOLERANCE too.
    screen : None, or a callable giving Ū_all (n, N, N) as the unknowns stand
    (not orthonormalised) at frequencies (n,) rad/s faster than
    ``deduction.matrix``, the same to rounding: a compiled determinant's
    :meth:`~linmstmm.determinant.CompiledDeterminant.plain_matrix`. It is asked for
    the first probe alone: where that is finite and regular by SCREEN_MARGIN times
    the tolerance, nothing is released without the numpy carry; anything else is
    decided on ``deduction.matrix`` at every probe as without it, so that the
    unknowns released (chosen among equal weights by rounding) are the same
    (:func:`_screened_probe` says why the later probes need not be looked at).
    scales : the :func:`characteristic_frequencies` of ``deduction.topology`` (rad/s)
    where the caller has them already; found here otherwise.
    """
    if probe is None and _statically_determinate(deduction.topology):
        return 0
    scales = characteristic_frequencies(deduction.topology) if scales is None else scales
    # the same for every probe: made once, when first needed, which for the numpy carry is after
    # its first probes, whose carry gives the rows' kinds (Deduction.matrix): 1.5 ms less on the launcher
    start = functools.cache(functools.partial(own_units_start, deduction, min(scales)))
    if probe is not None:
        return _released_at(deduction, np.asarray(probe, dtype=float), tolerance, screen, start)
    for scale in scales[:-1]:  # the first scale whose probes can be read
        try:
            with np.errstate(over="ignore", invalid="ignore"):  # an overflowing scale is the next one's turn
                return _released_at(deduction, np.asarray(PROBES) * scale, tolerance, screen, start)
        except (RuntimeError, np.linalg.LinAlgError):
            continue
    return _released_at(deduction, np.asarray(PROBES) * scales[-1], tolerance, screen, start)


def _released_at(deduction, probe: np.ndarray, tolerance: float, screen, start) -> int:
    """:func:`release_indeterminate` at the frequencies ``probe`` (rad/s), balancing from
    ``start()`` (:func:`own_units_start`)."""
    if screen is not None and _clearly_regular(_screened_probe(screen, probe), SCREEN_MARGIN * tolerance, start()):
        return 0
    samples = deduction.matrix(probe)
    rows, cols = equilibration(samples[0], start=start())
    samples = rows[:, None] * samples * cols
    r = _common_nullity(samples, tolerance)
    if r == 0:
        return 0
    u, _, vt = np.linalg.svd(samples[0])
    right_null, left_null = vt[-r:].T, u[:, -r:]
    for sample in samples[1:]:
        scale = np.abs(sample).max()
        if (np.abs(sample @ right_null).max() > 1e-9 * scale
                or np.abs(left_null.T @ sample).max() > 1e-9 * scale):
            if tolerance > ROUNDING_TOLERANCE:
                return _released_at(deduction, probe, ROUNDING_TOLERANCE, None, start)
            raise RuntimeError("Ū_all is singular at every frequency with a null space that "
                               "moves with frequency: the model has a mechanism")
    released_columns = scipy.linalg.qr(right_null.T, pivoting=True)[2][:r]
    released_rows = scipy.linalg.qr(left_null.T, pivoting=True)[2][:r]
    deduction.release(released_columns, released_rows)
    return r


def _screened_probe(screen, probe: np.ndarray) -> np.ndarray:
    """Ū_all (N, N) by ``screen`` at the first of ``probe`` (rad/s), the one probe the screen
    decides on.

    The numpy carry reads its probes first to last and stops at the first with no null
    space (:func:`_common_nullity`); so where the first is clearly regular
    (:func:`_clearly_regular`) the later ones can change nothing, as long as they are
    finite. They entered the screen only so: a later probe that overflows (a non-finite
    Ū_all) sent the probes to the numpy carry, which took the scale for unreadable and
    went on to the next. From the first probe to the last (7.25 times its frequency) a
    beam's waves grow by e^(1.7 βL) and a rigid body's inertia by 53: Ū_all overflows at
    the last but not at the first only after a run of hundreds of beams (e^260 at the
    first already), whose growing and decaying waves leave the first probe far from
    clearly regular, or with entries within a factor 1e4 of overflow at the first
    (tests: no random model has a clearly regular first probe and a later one that
    overflows). The first alone costs a third of the three (the launchers: 40 µs a probe).
    """
    return screen(probe[:1])[0]


def _clearly_regular(sample: np.ndarray, threshold: float, start) -> bool:
    """True where ``sample`` (N, N) is finite and, balanced from ``start``
    (:func:`equilibration`), has no singular value below ``threshold`` times its largest
    (:func:`nullity`; decided by :func:`_well_above` where that can, on the one balanced
    matrix both read). The balance and its bound are compiled
    (:func:`linmstmm._balance_kernels.balanced`: the launcher's 65 µs in numpy, 17 µs so)."""
    if not np.isfinite(sample).all():
        return False
    from linmstmm._balance_kernels import balanced  # numba loads here: a screen is a compiled determinant's

    matrix, bound = balanced(np.ascontiguousarray(sample), start[0], start[1], EQUILIBRATION_SWEEPS)
    return _well_above(matrix, threshold, bound) or _small_singular_values(matrix, threshold) == 0


#: :func:`_well_above` answers True only where its bound clears the threshold this many
#: times over: the computed inverse is off by at most κ n eps (κ ≤ 1 / threshold, under
#: 1e-8 relative for the probes' 1e-6 and order 60), and the singular values an SVD
#: computes by n eps of the largest, both far inside a factor 2.
BOUND_MARGIN = 2.0
#: The Gram matrix's test (:func:`_gram_clears`) is taken only where its shift
#: (BOUND_MARGIN threshold s)² is at least this many times the rounding of forming AᵀA
#: and factorising it, at most (n + 1)² eps s² for order n: what it clears then has
#: σ_min ≥ √2 threshold s, above the threshold with room for the SVD's n eps (the
#: probes' threshold 1e-6 up to order 93; the launchers are 60 and 72).
GRAM_ROUNDING = 2.0
_EPS = float(np.finfo(float).eps)


def _well_above(matrix: np.ndarray, threshold: float, bound: float | None = None) -> bool:
    """True where the real square ``matrix``'s smallest singular value is surely at least
    ``threshold`` times its largest, decided against BOUND_MARGIN times the threshold
    and σ_max ≤ s = √(‖A‖₁ ‖A‖∞): by the Gram matrix where that is exact enough
    (:func:`_gram_clears`), else by one inverse (a third of an SVD's cost):
    1 / σ_min = ‖A⁻¹‖₂ ≤ √(‖A⁻¹‖₁ ‖A⁻¹‖∞). False says nothing (a matrix that is nearly
    singular, or whose bounds are loose). ``bound``: s where the caller has it already
    (:func:`linmstmm._balance_kernels.balanced`), found here otherwise."""
    if bound is None:
        size = np.abs(matrix)
        bound = math.sqrt(size.sum(axis=0).max()) * math.sqrt(size.sum(axis=1).max())  # the product may underflow
    if not 0 < bound < math.inf:
        return False
    margin = BOUND_MARGIN * threshold
    n = matrix.shape[0]
    if margin ** 2 >= GRAM_ROUNDING * (n + 1) ** 2 * _EPS:
        unit = scale_into_half_one(bound)  # exact: s of ``matrix * unit`` is about 1
        return _gram_clears(matrix * unit, margin * bound * unit)
    try:
        inverse = np.linalg.inv(matrix)
    except np.linalg.LinAlgError:
        return False
    inverse = np.abs(inverse)
    return bool(1.0 >= margin * bound * np.sqrt(inverse.sum(axis=0).max()) * np.sqrt(inverse.sum(axis=1).max()))


def _gram_clears(matrix: np.ndarray, floor: float) -> bool:
    """True where AᵀA − floor² I of the real square ``matrix`` A has a Cholesky factor, that
    is where σ_min(A) ≥ ``floor`` (to the rounding GRAM_ROUNDING leaves out): a product
    and a Cholesky factorisation, a quarter of an inverse's cost (on the launcher 20 µs
    against 85), by scipy's BLAS syrk and LAPACK potrf (a model's first potrf: 22 µs,
    numpy's cholesky 42)."""
    gram = scipy.linalg.blas.dsyrk(1.0, matrix, trans=1)  # the upper triangle, which the factorisation reads
    np.einsum("ii->i", gram)[:] -= floor ** 2
    return scipy.linalg.lapack.dpotrf(gram, clean=0, overwrite_a=1)[1] == 0


def _common_nullity(samples: np.ndarray, tolerance: float) -> int:
    """The least :func:`nullity` of the (n, N, N) ``samples``, their first ones first: once
    one has none the rest are not decomposed. Unless one is not finite (an overflowing
    probe), where each is, so that one the SVD cannot read raises as it would."""
    if not np.all(np.isfinite(samples)):
        return min(nullity(sample, tolerance) for sample in samples)
    least = nullity(samples[0], tolerance)
    for sample in samples[1:]:
        if least == 0:
            break
        least = min(least, nullity(sample, tolerance))
    return least


def _statically_determinate(topology) -> bool:
    """True for a tree (no loop cut) held at one boundary end at most, with no released
    spring direction (no k = 0): statics fixes every reaction, so Ū_all has no null
    space at every frequency and there is nothing to release (a 10,000-body chain
    spent three quarters of its solve carrying the probes that would find none)."""
    if topology.cuts or sum(bool(np.any(end.fixed)) for end in topology.boundaries) > 1:
        return False
    stiffness = [np.ravel(element.record.k) for element in topology.elements if element.kind == "spring"]
    return not stiffness or bool(np.all(np.concatenate(stiffness) > 0))
