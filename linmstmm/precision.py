"""Roots to any number of digits: refinement of float64 roots in mpmath.

The float64 search (:mod:`linmstmm.roots`) finds every root and its
multiplicity; this module refines them with det Ū_all evaluated in mpmath
(the same element and deduction code on object arrays; the determinant of the
resulting matrix by an LU in python-flint's Arb, :func:`arb_determinant`), at
the requested number of digits plus guard digits that cover the growth of the beam
functions (e^{βL} along a path). A simple root is refined by the secant
method from the float64 root and a point 2⁻⁴⁰ away (three evaluations of
det: errors 1e-16 and 1e-12 give 1e-28, then 1e-40); a root of
multiplicity m by Newton with the step multiplied by m, which converges
quadratically on an m-fold zero, det and its derivative both taken from one
evaluation at ω + ih (complex step: det is real on the real axis, so
Im det(ω + ih) / h = det'(ω) with no cancellation); where the model's data split
it into simple roots farther apart than the digits asked for, each of them
(:func:`_cluster_members`). Either stops once its
step is below 10^−(digits+2) of the root, or raises a RuntimeError after
MAX_STEPS.

The digits are those of the model records as given: every number the
solver derives from them (compliances 1/k, lever arms, m·r, EI, ρA) is formed
in mpmath from the exact binary values. A beam's ``length`` and ``axes`` are
record fields, float64 values computed from its end points when a file is
read, and are taken as they are.
"""
from __future__ import annotations

import inspect
import math

import mpmath
import numpy as np

from linmstmm.elements.beam import bending_wavenumber
from linmstmm.stages import report

#: Guard digits on top of the growth estimate.
GUARD_DIGITS = 12
#: Iterations of either refinement before it gives up.
MAX_STEPS = 30
#: Points of det in mpmath across a cluster float64 could not separate (:func:`separated_cluster`).
CLUSTER_POINTS = 65
#: A refinement that does not settle is tried again at twice the working precision,
#: up to this many times: the growth estimate misses cancellations such as a
#: ring's T_loop − I (random ring 23 at 2692 Hz: det right to 3 digits at 43).
PRECISION_DOUBLINGS = 2


def growth_digits(model, omega: float) -> int:
    """Decimal digits the beam functions grow by at ``omega`` (rad/s): Σ βL / ln 10."""
    total = sum(bending_wavenumber(beam, omega) * beam.length for beam in model.beams)
    return int(math.ceil(total / math.log(10)))


def working_digits(model, omega: float, digits: int) -> int:
    """mpmath precision for ``digits`` digits of a root near ``omega`` (rad/s): guard digits
    and the beams' growth on top."""
    return digits + GUARD_DIGITS + growth_digits(model, omega)


def mp_determinant(deduction, omega) -> mpmath.mpf:
    """det Ū_all(ω) in mpmath at the working precision (omega an mpf)."""
    return arb_determinant(deduction.matrix(np.array([omega], dtype=object))[0])


def arb_determinant(matrix: np.ndarray):
    """det of an (N, N) object array of mpmath numbers (mpf or mpc), at mpmath's precision.

    The LU runs in python-flint's ball arithmetic (Arb, in C), 20-30 times faster
    than row operations on object arrays in Python (a launcher's 60 × 60 Ū_all at
    33 digits: 5 ms against 0.1 s), which made it half of every mpmath evaluation.
    The entries go in exactly (binary mantissa and exponent) and the midpoint of the
    result comes back: its error is that of an LU at the working precision.
    Returns mpf (mpc if any entry is complex); exactly 0 for an exactly singular matrix.
    """
    import flint  # only the mpmath path needs it

    flint.ctx.prec = mpmath.mp.prec
    complex_entries = any(isinstance(x, mpmath.mpc) for x in matrix.flat)
    if complex_entries:
        det = flint.acb_mat([[_complex_ball(x) for x in row] for row in matrix]).det()
        return mpmath.mpc(_from_ball(det.real), _from_ball(det.imag))
    return _from_ball(flint.arb_mat([[_real_ball(x) for x in row] for row in matrix]).det())


def _real_ball(x):
    """An mpf (or number) as an exact flint.arb."""
    import flint

    sign, mantissa, exponent, _ = mpmath.mpf(x)._mpf_
    return flint.arb((-mantissa if sign else mantissa, exponent)) if mantissa else flint.arb(0)


def _complex_ball(x):
    import flint

    x = mpmath.mpc(x)
    return flint.acb(_real_ball(x.real), _real_ball(x.imag))


def _from_ball(ball) -> mpmath.mpf:
    """The midpoint of a flint.arb as an mpf."""
    mantissa, exponent = ball.mid().man_exp()
    return mpmath.mpf((int(mantissa), int(exponent)))


def refine_roots(deduction, model, omegas, digits: int, multiplicities=None, log_det=None) -> list:
    """The roots ``omegas`` (rad/s, ascending, repeated per multiplicity) to ``digits`` digits.

    multiplicities : {root: multiplicity} where it differs from the number of
    repeats in ``omegas`` (the highest root of a list cut at a count may be
    double with one entry). log_det : callable ω (n,) -> (sign (n,), log|det Ū_all|
    (n,)) in float64, or None; where given, a simple root's slope comes from it
    (:func:`float64_slopes`), and the secant's second point is the Newton step
    from the float64 root: two evaluations in mpmath per root, not three.
    Returns mpf values, one per entry of ``omegas``.
    Raises RuntimeError for a root the refinement does not settle on, even at
    2**PRECISION_DOUBLINGS times the working precision.
    """
    refined = []
    slopes = float64_slopes(log_det, omegas) if log_det is not None else {}
    i = 0
    while i < len(omegas):
        repeats = 1
        while i + repeats < len(omegas) and omegas[i + repeats] == omegas[i]:
            repeats += 1
        m = (multiplicities or {}).get(omegas[i], repeats)
        which = f"root {i + 1}" if repeats == 1 else f"roots {i + 1}-{i + repeats}"
        report(f"mpmath: {which} of {len(omegas)} ({omegas[i] / (2 * math.pi):.6g} Hz)")
        dps = working_digits(model, omegas[i], digits)
        for attempt in range(PRECISION_DOUBLINGS + 1):
            with mpmath.workdps(dps << attempt):
                start, tolerance = mpmath.mpf(omegas[i]), mpmath.mpf(10) ** -(digits + 2)
                try:
                    members = ([_secant(deduction, start, tolerance, slopes.get(omegas[i]))] * repeats if m == 1
                               else _cluster_members(deduction, start, m, tolerance)[:repeats])
                except RuntimeError:
                    if attempt == PRECISION_DOUBLINGS:
                        raise
                    continue
                refined += [+root for root in members]
                break
        i += repeats
    return refined


#: Relative step of the float64 central difference that gives det's slope at a root.
SLOPE_STEP = 1e-6


def float64_slopes(log_det, omegas) -> dict:
    """{ω: d det Ū_all / dω} at each of ``omegas`` (rad/s), from float64 values of det at
    ω (1 ± SLOPE_STEP) (``log_det``: ω (n,) -> (sign, log|det|)), as mpf: accurate to
    about 1e-10 relative at a simple root, enough for the mpmath secant's first step
    to land within that fraction of the float64 root's error."""
    omegas = np.unique(np.asarray(omegas, dtype=float))
    if not omegas.size:
        return {}
    points = np.concatenate([omegas * (1 + SLOPE_STEP), omegas * (1 - SLOPE_STEP)])
    sign, log_abs = log_det(points)
    values = [mpmath.mpf(float(np.real(s))) * mpmath.exp(mpmath.mpf(float(v))) for s, v in zip(sign, log_abs)]
    n = omegas.size
    return {float(w): (values[i] - values[n + i]) / (2 * SLOPE_STEP * mpmath.mpf(float(w)))
            for i, w in enumerate(omegas)}


def _secant(deduction, start, tolerance, slope=None):
    """The simple root of det Ū_all next to ``start`` (mpf, rad/s), to ``tolerance`` relative.

    slope : det's derivative there (mpf, from :func:`float64_slopes`) or None: the
    second point is then the Newton step from ``start`` (where that step is below
    SLOPE_STEP relative), else ``start`` (1 + 2⁻⁴⁰)."""
    x0 = start
    f0 = mp_determinant(deduction, x0)
    x1 = start * (1 + mpmath.mpf(2) ** -40)
    if slope:
        newton = x0 - f0 / slope
        if abs(newton - x0) <= SLOPE_STEP * abs(x0) and newton != x0:
            x1 = newton
    f1 = mp_determinant(deduction, x1)
    for _ in range(MAX_STEPS):
        if f1 == 0:
            return x1
        if f1 == f0:
            break
        x0, x1, f0 = x1, x1 - f1 * (x1 - x0) / (f1 - f0), f1
        if abs(x1 - x0) <= tolerance * abs(x1):
            return x1
        f1 = mp_determinant(deduction, x1)
    raise RuntimeError(f"the root near {float(start):.12g} rad/s does not settle in mpmath "
                       f"at {mpmath.mp.dps} digits")


def _multiple_newton(deduction, start, multiplicity: int, tolerance):
    """The root of det Ū_all of ``multiplicity`` next to ``start`` (mpf, rad/s), to
    ``tolerance`` relative: ω ← ω − m det/det', both from det(ω + ih).

    The complex step h must stay far below the distance to the root (on an
    m-fold zero, Re det(ω + ih) = det(ω) − O(h² det'')), and det is rounding
    noise within about tolerance² of the root; so the iteration also stops
    once quadratic convergence predicts an error below tolerance / 1000 (the
    next error ≈ s³/p² for relative steps p, then s), and a step that does not
    shrink is an error, not a result.
    """
    x, previous, step = start, None, 0
    for _ in range(MAX_STEPS):
        h = abs(x) * mpmath.mpf(10) ** -mpmath.mp.dps
        value = mpmath.mpc(mp_determinant(deduction, mpmath.mpc(x, h)))
        if value.real == 0:
            return x
        if value.imag == 0:
            break
        step = multiplicity * value.real * h / value.imag / abs(x)  # relative
        if previous is not None and abs(step) >= previous:
            break
        x -= step * abs(x)
        if abs(step) <= tolerance or (previous is not None and abs(step) ** 3 <= tolerance / 1000 * previous ** 2):
            return x
        previous = abs(step)
    raise UnsettledRoot(f"the {multiplicity}-fold root near {float(start):.12g} rad/s does not "
                        f"settle in mpmath at {mpmath.mp.dps} digits", x, max(abs(step), previous or 0, tolerance))


class UnsettledRoot(RuntimeError):
    """A multiple root's Newton iteration (:func:`_multiple_newton`) that stopped converging:
    ``at`` (mpf, rad/s) where it stopped, ``step`` (relative) the larger of its last two
    steps, the scale of how far apart the roots it circles are."""

    def __init__(self, message: str, at, step):
        super().__init__(message)
        self.at, self.step = at, step


#: The first circle of :func:`_split_cluster` has this many times the stalled Newton step
#: as radius; where it does not hold the cluster, the next has CLUSTER_REACH² times the radius.
CLUSTER_REACH = 10
#: Relative radius the circles of :func:`_split_cluster` stop at: the circle about a root
#: within which float64's tighter count (:func:`linmstmm.roots.clusters.separated`) found
#: the whole cluster.
CLUSTER_LIMIT = 1e-6


def _cluster_members(deduction, start, multiplicity: int, tolerance) -> list:
    """The ``multiplicity`` roots of det Ū_all counted at ``start`` (mpf, rad/s), ascending, to
    ``tolerance`` relative: one root repeated where they coincide at that tolerance
    (:func:`_multiple_newton`), else each one (:func:`_split_cluster`).

    A root float64 counts as multiple may be a cluster of simple roots closer than
    float64 resolves but farther apart than ``tolerance``: Iy and Iz one ulp apart
    (bending pairs 1.1e-16 apart), or a symmetric model turned in space, whose
    frames and spring axes rounded to float64 split its double roots by 1e-17.
    Raises RuntimeError (the Newton iteration's) where neither settles.
    """
    try:
        return [_multiple_newton(deduction, start, multiplicity, tolerance)] * multiplicity
    except UnsettledRoot as stall:
        radius = CLUSTER_REACH * stall.step * abs(stall.at)  # a stall next to one member is a short step
        while radius <= CLUSTER_LIMIT * abs(stall.at):
            try:
                return _split_cluster(deduction, stall.at, multiplicity, radius, tolerance)
            except RuntimeError:
                radius *= CLUSTER_REACH ** 2
        raise stall from None


def _split_cluster(deduction, centre, multiplicity: int, radius, tolerance) -> list:
    """The ``multiplicity`` simple roots of det Ū_all within ``radius`` (rad/s) of ``centre``
    (mpf, rad/s), ascending, each to ``tolerance`` relative.

    det is entire: its Taylor polynomial about ``centre``, to degree multiplicity + 2,
    from its values on a circle of that radius (a discrete Fourier transform), has the
    cluster's roots as its smallest; each is then polished by the secant method on
    det, its second point the Newton step with the polynomial's slope. Raises
    RuntimeError where the polynomial's roots are not real and inside the circle, or
    two of them polish onto one root.
    """
    degree, points = multiplicity + 2, 4 * (multiplicity + 2)
    turns = [mpmath.expjpi(mpmath.mpf(2 * j + 1) / points) for j in range(points)]
    values = [mp_determinant(deduction, centre + radius * turn) for turn in turns]
    taylor = [sum(v / turn ** k for v, turn in zip(values, turns)) / points / radius ** k
              for k in range(degree + 1)]
    try:
        offsets = _polynomial_roots(taylor)
    except mpmath.libmp.NoConvergence as error:
        raise RuntimeError(str(error)) from None
    offsets = sorted(offsets, key=abs)[:multiplicity]
    if any(abs(t) >= radius or abs(mpmath.im(t)) > tolerance * abs(centre) for t in offsets):
        raise RuntimeError("the cluster's roots are not real and inside the circle")
    slopes = [k * taylor[k] for k in range(degree, 0, -1)]  # det' about centre, highest power first
    members = sorted(_secant(deduction, centre + mpmath.re(t), tolerance,
                             mpmath.re(_horner(slopes, mpmath.re(t)))) for t in offsets)
    if (any(abs(a - centre) >= radius for a in members)
            or any(b - a <= tolerance * abs(a) for a, b in zip(members, members[1:]))):
        raise RuntimeError("the cluster's members polish onto one root, or out of the circle")
    return members


#: Whether this mpmath's polyroots takes its coefficients lowest power first (``asc``, from
#: mpmath 1.4, which deprecates the highest-first order that 1.3 alone knows).
_ASCENDING = "asc" in inspect.signature(mpmath.polyroots).parameters


def _polynomial_roots(ascending: list) -> list:
    """The roots of the polynomial with coefficients ``ascending`` (lowest power first),
    at twice the working precision, by mpmath.polyroots in the order this mpmath takes."""
    options = {"maxsteps": 200, "extraprec": 2 * mpmath.mp.prec}
    if _ASCENDING:
        return mpmath.polyroots(ascending, asc=True, **options)
    return mpmath.polyroots(ascending[::-1], **options)


def _horner(descending: list, x):
    """The polynomial with coefficients ``descending`` (highest power first) at ``x``, by
    Horner's rule as mpmath.polyval forms it (whose default order mpmath 1.4 deprecates)."""
    value = descending[0]
    for coefficient in descending[1:]:
        value = value * x + coefficient
    return value


def separated_cluster(deduction, model, omega: float, multiplicity: int, radius: float, digits: int):
    """The ``multiplicity`` roots within ``radius`` of ``omega`` (rad/s) that float64 could
    not tell apart (:attr:`RootSearchResult.unseparated`), to ``digits`` digits; None if they
    are not found in full.

    det Ū_all in mpmath on CLUSTER_POINTS points across the interval: each sign
    change holds a simple root (bracketed refinement, Anderson–Björck), each local
    minimum of |det| between points of one sign a double root (:func:`_multiple_newton`).
    They must make up ``multiplicity`` (the float64 count over the circle), else None.
    """
    with mpmath.workdps(working_digits(model, omega, digits)):
        tolerance = mpmath.mpf(10) ** -(digits + 2)
        lo, width = mpmath.mpf(omega) - mpmath.mpf(radius), 2 * mpmath.mpf(radius)
        grid = [lo + width * k / (CLUSTER_POINTS - 1) for k in range(CLUSTER_POINTS)]
        values = [mp_determinant(deduction, x) for x in grid]
        roots = []
        try:
            for k in range(CLUSTER_POINTS - 1):
                if values[k] * values[k + 1] < 0:
                    # (verify=False: findroot would check det(root)² against tol, det being ~1e100)
                    root = mpmath.findroot(lambda x: mp_determinant(deduction, x), (grid[k], grid[k + 1]),
                                           solver="anderson", tol=(tolerance * abs(grid[k])) ** 2, verify=False)
                    if not grid[k] <= root <= grid[k + 1]:
                        return None
                    roots.append(root)
            for k in range(1, CLUSTER_POINTS - 1):
                if (values[k - 1] * values[k] > 0 and values[k] * values[k + 1] > 0
                        and abs(values[k]) < abs(values[k - 1]) and abs(values[k]) < abs(values[k + 1])):
                    roots += [_multiple_newton(deduction, grid[k], 2, tolerance)] * 2
        except (RuntimeError, ValueError, ZeroDivisionError):
            return None
        return sorted(+root for root in roots) if len(roots) == multiplicity else None
