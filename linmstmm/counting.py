"""Counting the roots of det Ū_all(ω) by the argument principle.

det Ū_all is an entire function of ω (no inverse is ever taken, so it has no
poles), real on the real axis and even in ω, whose zeros are exactly the
natural frequencies ±ω_k with their multiplicities. The change of its phase
along a closed contour is therefore 2π × the number of natural frequencies
inside; by conjugate symmetry the upper half of the contour carries half of
it, so every count here is Δarg det / π along a half-ellipse or half-circle
(:func:`count_zeros`, :func:`count_in_disc`). The contour is refined until
the phase turns by at most π/4 between neighbouring points, as sampled and as
the derivative of log det at either point predicts (the samples alone can
miss a whole turn), and the total must come out an integer, or the count
fails with a RuntimeError instead of guessing.

:func:`deflated` divides known roots out of det, so that a count asks only
whether any *other* zero is inside.
"""
from __future__ import annotations

import numpy as np

#: A counting contour's phase step still above π/4 over a θ interval this short
#: (radians) is a jump, not a turn: the count fails.
PHASE_JUMP = 1e-12
#: Largest turn of the phase of det between neighbouring contour points, sampled or
#: predicted from the derivative of log det at either end; also the largest change of
#: that derivative across a step, times the step (:func:`_half_windings`).
LOG_STEP = np.pi / 4
#: Contour points a count starts from (each with log det and its derivative), before
#: refinement where LOG_STEP is exceeded.
INITIAL_POINTS = 33
#: Contour points a count may take before it fails (each costs two evaluations of
#: det: its value and its derivative). Successful counts of the test suite took at
#: most 1262; one where det is rounding noise (far above a discrete model's last
#: root) refines until it reaches this.
MAX_POINTS = 10000
#: Contour points evaluated in one call of ``log_det``: the stacks of one round of
#: many counts at once stay a few hundred MB.
EVALUATION_CHUNK = 2048
#: θ step (radians) of the difference that gives d log det / dθ at each contour point:
#: the same fraction of a small circle (a multiplicity count) as of a wide ellipse.
#: It is no smaller because the difference amplifies the rounding noise of log det by
#: its inverse: far above a discrete model's last root, where det is rounding noise,
#: counts refine on that noise before they fail. Figure 11.7's ring of three masses
#: asked for 4 modes (tests/test_book_topologies.py) took 1.6 s before derivatives,
#: and with steps of 1e-3, 4e-3 (this) and 1e-2: 3.3, 1.8 and 2.5 s (1e-7 relative to
#: ω, with twice the point limits: 14 s). Features narrower than this are the sampled
#: steps' to see.
DERIVATIVE_STEP = 4e-3


def deflated(log_det, roots):
    """``log_det`` of det Ū_all / ∏_r (ω² − r²) over ``roots`` (rad/s, repeated per
    multiplicity): the same zeros less those at ±r (r = 0: a factor ω²).

    Counting the deflated determinant over a contour around known roots asks
    only whether any *other* zero is inside: its phase no longer turns by π per
    known root, so far fewer contour points resolve it.
    """
    roots = np.asarray(roots, dtype=float)

    def reduced(omega):
        return divided_out(omega, *log_det(omega), roots)

    return reduced


def divided_out(omega, sign, log_abs, roots):
    """(phase, log|·|) of det / ∏_r (ω² − r²), given det's (``sign``, ``log_abs``) at
    ``omega`` (n,): values already computed need no new evaluation of det. At a
    known root itself the value is not finite (the callers test for that), without
    a warning (they reached the command line's error output)."""
    factors = np.asarray(omega)[:, None] ** 2 - np.asarray(roots, dtype=float)[None, :] ** 2
    with np.errstate(divide="ignore", invalid="ignore"):  # log|det| -inf at the root: inf - inf
        return (sign * np.exp(-1j * np.angle(factors).sum(axis=1)),
                log_abs - np.log(np.abs(factors)).sum(axis=1))


def count_zeros(log_det, a: float, b: float, max_points: int = MAX_POINTS, initial_points: int = INITIAL_POINTS) -> int:
    """Number of natural frequencies in (a, b), rad/s, with multiplicity.

    Argument principle: det Ū_all(ω) is an entire function of ω, real on the
    real axis, whose zeros are exactly the natural frequencies ±ω_k with
    their multiplicities (a null vector of Ū_all is a mode and vice versa;
    no inverse is ever taken, so there are no poles). The winding number of
    det along an ellipse through a and b counts them; by conjugate symmetry
    the upper half-arc suffices: count = Δarg(b → a over the arc) / π.

    log_det : callable complex omega (n,) -> (phase factor (n,), log|det| (n,)).
    Raises RuntimeError if the count cannot be made.
    """
    return _raised(count_zeros_many(log_det, [(a, b)], max_points, initial_points)[0])


def count_zeros_many(log_det, intervals, max_points: int = MAX_POINTS, initial_points: int = INITIAL_POINTS) -> list:
    """:func:`count_zeros` for several intervals (a, b) with one evaluation of det
    per refinement round for all of them; each entry is an int or the
    RuntimeError that interval's count raised. ``initial_points`` per half-ellipse
    before refinement."""
    return _half_windings(log_det, [_ellipse(a, b) for a, b in intervals],
                          [f"({a:.6g}, {b:.6g}) rad/s" for a, b in intervals], max_points, initial_points)


def zero_free(log_det, a: float, b: float, initial_points: int = INITIAL_POINTS) -> bool:
    """Whether (a, b), rad/s, holds no natural frequency, by :func:`count_zeros`.

    det Ū_all is real on the real axis, so where it has opposite signs at a and b
    an odd number of roots lies between: the answer is False from the count's
    first round, whose contour starts at b and ends at a, without refining it (a
    10,000-body chain's first scan chunk holds 75 roots; counting them took 812
    evaluations of det, its first round 18).

    Parameters
    ----------
    log_det : callable
        complex omega (n,) -> (phase factor (n,), log|det| (n,)).
    a, b : float
        The interval, rad/s, 0 < a < b.
    initial_points : int
        Contour points before refinement.

    Returns
    -------
    bool
        True if the count comes out 0; False if it finds roots or cannot be made.
    """
    odd = RuntimeError(f"det Ū_all changes sign between {a:.6g} and {b:.6g} rad/s: not counted")
    return _half_windings(log_det, [_ellipse(a, b)], [f"({a:.6g}, {b:.6g}) rad/s"], MAX_POINTS, initial_points,
                          opposite_ends=odd)[0] == 0


def _ellipse(a: float, b: float):
    """The upper half of the ellipse through a and b (rad/s) as a function of θ in
    [0, π]: from b (θ = 0) to a (θ = π), half as high as wide."""
    centre, radius = (a + b) / 2, (b - a) / 2
    return lambda theta: centre + radius * np.cos(theta) + 0.5j * radius * np.sin(theta)


def count_in_disc(log_det, radius: float, max_points: int = MAX_POINTS) -> int:
    """Zeros of det Ū_all with |ω| < ``radius`` (rigid-body modes count twice: det ∝ ω^2r).

    det is even in ω and real on the real axis, so the upper half circle,
    from +radius to −radius, carries half the winding: count = Δarg / π.
    """
    return _raised(_half_windings(log_det, [lambda theta: radius * np.exp(1j * theta)],
                                  [f"|ω| < {radius:.6g} rad/s"], max_points)[0])


def _raised(count):
    """``count``, or raise it if it is the RuntimeError a count came back with."""
    if isinstance(count, RuntimeError):
        raise count
    return count


def _half_windings(log_det, paths, wheres, max_points: int, initial_points: int = INITIAL_POINTS,
                   opposite_ends=None) -> list:
    """Δarg det / π along each ``path(θ)``, θ from 0 to π; each total must come out
    an integer. All paths' points go to ``log_det`` together. Returns an int or a
    RuntimeError per path; ``opposite_ends`` (if given) instead, from the first
    round, for a path whose two ends (on the real axis) have det of opposite signs.

    The contour is refined until, between every two neighbouring points, the phase
    turns by at most LOG_STEP, as sampled and as predicted by the derivative of
    log det (log|det| + i arg det, analytic) along the path at either point (a
    difference, evaluated with the point), and that derivative changes by at most
    LOG_STEP / step (a zero close to the contour makes it swing). The samples alone
    cannot tell a step that turns the phase by a whole turn from none: random
    floating_loops 11 counted 40 roots below 30 kHz where there are 98. Bounding the
    sampled change of log|det| as well still gave 88: along the top of a counting
    ellipse |det| hardly changes while the phase winds at a steady rate (steps of
    5.6–6.2 rad read as −0.65 … −0.10). The count also fails where a step stays
    coarse over a θ interval below PHASE_JUMP (a jump, not a turn: det is rounding
    noise there, as far above a discrete model's last root; halving towards it took
    thousands of one-point rounds).
    """
    def logs(pieces):
        """(log det, d log det / dθ) at path_i(θ_i) for the (i, θ_i) pieces, one evaluation
        (the derivative a difference over DERIVATIVE_STEP, towards the middle of the path)."""
        steps = np.concatenate([np.where(theta < np.pi / 2, DERIVATIVE_STEP, -DERIVATIVE_STEP) for _, theta in pieces])
        edges = np.cumsum([theta.size for _, theta in pieces])[:-1]
        shifted = np.split(np.concatenate([theta for _, theta in pieces]) + steps, edges)
        points = np.concatenate([paths[i](theta) for i, theta in pieces]
                                + [paths[i](theta) for (i, _), theta in zip(pieces, shifted)])
        sign, log_abs = (np.concatenate(parts) for parts in zip(*[
            log_det(points[start:start + EVALUATION_CHUNK]) for start in range(0, points.size, EVALUATION_CHUNK)]))
        here, there = np.split(log_abs + 1j * np.angle(sign), 2)
        with np.errstate(invalid="ignore"):  # a point on a known root: not finite, flagged below
            change = (there.real - here.real) + 1j * np.angle(np.exp(1j * (there.imag - here.imag)))
            slope = change / steps
        lost = ~np.isfinite(log_abs).reshape(2, -1).all(axis=0)
        return (np.split(here, edges), np.split(slope, edges),
                [None if not gone.any() else complex(where[gone][0])
                 for gone, where in zip(np.split(lost, edges), np.split(points[:lost.size], edges))])

    thetas = [np.linspace(0.0, np.pi, initial_points) for _ in paths]
    values, slopes, lost = logs(list(enumerate(thetas)))
    results: list = [opposite_ends if opposite_ends is not None and lost[i] is None
                     and np.cos(value[0].imag - value[-1].imag) < 0 else None for i, value in enumerate(values)]
    while True:
        pieces = []
        for i, theta in enumerate(thetas):
            if results[i] is not None:
                continue
            if lost[i] is not None:
                results[i] = RuntimeError(_lost_message(wheres[i], lost[i], values[i]))
                continue
            steps = np.angle(np.exp(1j * np.diff(values[i].imag)))  # wrapped into (−π, π]
            h = np.diff(theta)
            turning = np.maximum(np.abs(slopes[i][:-1].imag), np.abs(slopes[i][1:].imag)) * h
            bending = np.abs(np.diff(slopes[i])) * h
            coarse = (np.abs(steps) > LOG_STEP) | (turning > LOG_STEP) | (bending > LOG_STEP)
            if not coarse.any():
                winding = steps.sum() / np.pi
                results[i] = (int(round(abs(winding))) if abs(winding - round(winding)) <= 0.05 else
                              RuntimeError(f"the root count in {wheres[i]} is not an integer "
                                           f"({winding:.3f}): det Ū_all is not accurate enough there"))
            elif theta.size > max_points or np.min(np.diff(theta)[coarse]) < PHASE_JUMP:
                results[i] = RuntimeError(f"cannot count the roots in {wheres[i]}: the phase of "
                                          "det Ū_all varies too fast along the counting contour")
            else:
                pieces.append((i, (theta[:-1][coarse] + theta[1:][coarse]) / 2))
        if not pieces:
            return results
        new_values, new_slopes, new_lost = logs(pieces)
        for (i, middles), more, more_slopes, gone in zip(pieces, new_values, new_slopes, new_lost):
            order = np.argsort(np.r_[thetas[i], middles])
            thetas[i] = np.r_[thetas[i], middles][order]
            values[i], slopes[i] = np.r_[values[i], more][order], np.r_[slopes[i], more_slopes][order]
            lost[i] = gone if lost[i] is None else lost[i]


def count_inside(log_det, centre: complex, radius: float, height: float | None = None,
                 max_points: int = MAX_POINTS) -> int:
    """Zeros of an entire function inside an ellipse, with multiplicity, by the whole contour.

    For a determinant without the symmetries of an undamped det Ū_all (a model
    with dashpots: its roots ω and −ω̄ lie off the real axis), so the whole
    ellipse ``centre + radius cos φ + i height sin φ`` (``height`` default
    ``radius``: a circle; all in rad/s) is followed once, φ = 2θ for θ in [0, π].

    log_det : callable complex omega (n,) -> (phase factor (n,), log|det| (n,)).
    Raises RuntimeError if the count cannot be made.
    """
    height = radius if height is None else height
    winding = _raised(_half_windings(
        log_det, [lambda theta: centre + radius * np.cos(2 * theta) + 1j * height * np.sin(2 * theta)],
        [f"the ellipse about {centre:.6g} rad/s"], max_points)[0])
    if winding % 2:
        raise RuntimeError(f"the root count in the ellipse about {centre:.6g} rad/s is not an integer")
    return winding // 2


def _lost_message(where: str, omega: complex, values: np.ndarray) -> str:
    """Why a count in ``where`` cannot be made: det Ū_all came out exactly 0 or not finite
    at ``omega`` (rad/s) on its contour, where ``values`` (log det at the contour's points)
    are known. Where no point of the contour had a finite value, Ū_all is singular at
    every frequency (an indeterminate constraint left in it); where others had, det lost
    its digits at that point (its scales too far apart to be told from 0 there)."""
    if not np.isfinite(values.real).any():
        return (f"det Ū_all vanishes on the whole counting contour in {where}: Ū_all is singular at every "
                "frequency (undeflated indeterminate constraint)")
    return (f"cannot count the roots in {where}: det Ū_all came out exactly 0 or not finite at "
            f"ω = {omega.real:.6g}{omega.imag:+.6g}j rad/s on the counting contour (the largest and smallest "
            "scales of Ū_all there too far apart to be told from 0 in float64)")
