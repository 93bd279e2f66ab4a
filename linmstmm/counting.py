"""Counting the roots of det Ū_all(ω) by the argument principle.

det Ū_all is an entire function of ω (no inverse is ever taken, so it has no
poles), real on the real axis and even in ω, whose zeros are exactly the
natural frequencies ±ω_k with their multiplicities. The change of its phase
along a closed contour is therefore 2π × the number of natural frequencies
inside; by conjugate symmetry the upper half of the contour carries half of
it, so every count here is Δarg det / π along a half-ellipse or half-circle
(:func:`count_zeros`, :func:`count_in_disc`). The contour is refined until
no phase step exceeds π/4, and the total must come out an integer, or the
count fails with a RuntimeError instead of guessing.

:func:`deflated` divides known roots out of det, so that a count asks only
whether any *other* zero is inside.
"""
from __future__ import annotations

import numpy as np

#: A counting contour's phase step still above π/4 over a θ interval this short
#: (radians) is a jump, not a turn: the count fails.
PHASE_JUMP = 1e-12


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
    ``omega`` (n,): values already computed need no new evaluation of det."""
    factors = np.asarray(omega)[:, None] ** 2 - np.asarray(roots, dtype=float)[None, :] ** 2
    return (sign * np.exp(-1j * np.angle(factors).sum(axis=1)),
            log_abs - np.log(np.abs(factors)).sum(axis=1))


def count_zeros(log_det, a: float, b: float, max_points: int = 20000, initial_points: int = 65) -> int:
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


def count_zeros_many(log_det, intervals, max_points: int = 20000, initial_points: int = 65) -> list:
    """:func:`count_zeros` for several intervals (a, b) with one evaluation of det
    per refinement round for all of them; each entry is an int or the
    RuntimeError that interval's count raised. ``initial_points`` per half-ellipse
    before refinement."""
    def ellipse(a, b):
        centre, radius = (a + b) / 2, (b - a) / 2
        return lambda theta: centre + radius * np.cos(theta) + 0.5j * radius * np.sin(theta)
    return _half_windings(log_det, [ellipse(a, b) for a, b in intervals],
                          [f"({a:.6g}, {b:.6g}) rad/s" for a, b in intervals], max_points, initial_points)


def count_in_disc(log_det, radius: float, max_points: int = 20000) -> int:
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


def _half_windings(log_det, paths, wheres, max_points: int, initial_points: int = 65) -> list:
    """Δarg det / π along each ``path(θ)``, θ from 0 to π, refined until no phase
    step exceeds π/4; each total must come out an integer. All paths' points go
    to ``log_det`` together. Returns an int or a RuntimeError per path: also
    where a phase step stays coarse over a θ interval below PHASE_JUMP (a jump,
    not a turn: det is rounding noise there, as far above a discrete model's
    last root; halving towards it took thousands of one-point rounds)."""
    def phases(pieces):
        """Angles of det at path_i(θ_i) for the (i, θ_i) pieces, one evaluation."""
        sign, log_abs = log_det(np.concatenate([paths[i](theta) for i, theta in pieces]))
        edges = np.cumsum([theta.size for _, theta in pieces])[:-1]
        return np.split(np.angle(sign), edges), [bool(ok.all()) for ok in np.split(np.isfinite(log_abs), edges)]

    thetas = [np.linspace(0.0, np.pi, initial_points) for _ in paths]
    angles, finite = phases(list(enumerate(thetas)))
    results: list = [None] * len(paths)
    while True:
        pieces = []
        for i, theta in enumerate(thetas):
            if results[i] is not None:
                continue
            if not finite[i]:
                results[i] = RuntimeError("det Ū_all vanishes on the counting contour: Ū_all is "
                                          "singular at every frequency (undeflated indeterminate "
                                          "constraint)")
                continue
            steps = np.angle(np.exp(1j * np.diff(angles[i])))  # wrapped into (−π, π]
            coarse = np.abs(steps) > np.pi / 4
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
        new_angles, new_finite = phases(pieces)
        for (i, middles), more, ok in zip(pieces, new_angles, new_finite):
            order = np.argsort(np.r_[thetas[i], middles])
            thetas[i], angles[i] = np.r_[thetas[i], middles][order], np.r_[angles[i], more][order]
            finite[i] = finite[i] and ok
