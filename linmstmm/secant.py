"""The secant method on det Ū_all, for many simple roots at once.

One evaluation per step and per root still moving, all in one call (a batch
the kernels share among the cores), superlinear (order 1.6) near a simple
root; det's ratio at two points is formed from the log magnitudes, so no
value overflows. :mod:`linmstmm.predicted` polishes its predictions so.
"""
from __future__ import annotations

import numpy as np

#: Relative size of the secant's first step (its second point): downward, since the
#: coarse model's frequencies lie above the natural frequencies they predict (a
#: Rayleigh–Ritz model: the launchers' lowest 20 by 5e-9 to 7e-4), so the second
#: point lies nearer the root than the first, and so does the first secant point:
#: a few evaluations fewer (2,664 against 2,678 upward, over twenty solves of the
#: bundled launchers and tip-mass cantilever, 10 to 100 modes).
FIRST_STEP = -1e-7
#: Secant steps before a root that has not settled is handed to the pencil.
SECANT_STEPS = 12
#: A secant from the ends of a bracket whose signs agree that comes back within this many
#: half-widths of its start may have met det's rounding noise, not a root beside the start,
#: and is tested (:func:`_in_noise`): on launcher 2's 67th root det's sign is noise over
#: ±5e-9, 50 half-widths, where the secant stopped 1.1e-10 to 1.5e-10 off its exact start
#: (by the BLAS threads' rounding), claiming a last step of 3.4e-14.
NOISE_SPANS = 100
#: The test's points lie this many times the secant result's distance from the start
#: either side of it: a simple root's det is linear there, ten times the start's.
NOISE_REACH = 10.0


def secant_roots(log_det, starts: np.ndarray, xtol: float | np.ndarray, floor: float, spans: np.ndarray | None = None):
    """Simple real roots of det near ``starts`` (rad/s) by the secant method on det.

    log_det : callable ω (n,) -> (sign (n,), log|det| (n,)). xtol : relative
    step that ends the iteration, one for all or (n,) one per start. floor : a
    step below this (relative) that no longer shrinks has reached the rounding
    floor of det, and is accepted with that step as its uncertainty.
    spans : (n,) relative half-widths, 0 where none (the default): where a start
    is known to lie that close to its root (a prediction refined by
    :mod:`linmstmm.rayleigh`), the first two points are start (1 ± span), and
    where det changes sign between them the secant point between them is the
    root, with no further evaluation and the bracket's width (relative) as its
    last step (the secant's error there is of the order of the width squared
    over the distance to the next root); elsewhere the secant goes on from them,
    and where it comes back into det's rounding noise about the start
    (:func:`_in_noise`), the start is the root, its distance from the secant's
    point (or the last step, the larger) its uncertainty.
    Each step evaluates det once per root still moving, all in one call;
    det's ratio at two points is formed from the log magnitudes, so no value
    overflows. Returns (roots, last relative steps); a root that did not
    settle within SECANT_STEPS is NaN.
    """
    starts = np.asarray(starts, dtype=float)
    if not starts.size:
        return np.zeros(0), np.zeros(0)
    tolerance = np.broadcast_to(np.asarray(xtol, dtype=float), starts.shape).copy()
    spans = np.zeros(starts.size) if spans is None else np.asarray(spans, dtype=float)
    bracketing = spans > 0
    x_old = np.where(bracketing, starts * (1 + spans), starts)
    x = np.where(bracketing, starts * (1 - spans), x_old * (1 + FIRST_STEP))
    # both starting points in one batch (each frequency is evaluated on its own: the same numbers)
    signs, logs = log_det(np.concatenate([x_old, x]))
    (sign_old, sign), (log_old, log_abs) = np.split(signs, 2), np.split(logs, 2)
    roots = np.full(x.size, np.nan)
    steps = np.full(x.size, np.inf)
    active = np.arange(x.size)
    previous = before = np.full(x.size, np.inf)
    oldest = np.full(x.size, np.nan)  # the point evaluated before x_old (none yet)
    bracketed = bracketing & ((sign * sign_old).real < 0)  # a bracket's ends: ended by the first step
    unconfirmed = np.flatnonzero(bracketing & ~bracketed)  # a bracket whose ends' signs agree
    level = np.maximum(log_old, log_abs)  # log|det| at a bracket's ends, the larger
    for _ in range(SECANT_STEPS):
        with np.errstate(divide="ignore", invalid="ignore"):  # sign 0: det exactly 0, x is a root
            ratio = (sign_old / sign).real * np.exp(np.clip(log_old - log_abs, -700, 700))  # det(x_old)/det(x)
            step = -(x - x_old) / (1 - ratio)
        step = np.where(np.isfinite(step), step, 0.0)
        new = x + step
        size = np.abs(step) / np.abs(new)
        # The secant converges superlinearly (order 1.6): the error of a point from
        # x_k and x_(k-1) is C e_k e_(k-1), and that of x_k was C e_(k-1) e_(k-2), so
        # with the step s_k measuring e_k, the error left is about s_k^2 / e_(k-2),
        # e_(k-2) the distance of the new point from the point x_(k-2) (the reach):
        # a step whose square is xtol/10 of that reach needs no evaluation to
        # confirm it. (s_k^2 / s_(k-1), taken before, is larger by e_(k-2)/e_(k-1):
        # the launchers' first 100 took 513 and 492 evaluations so, against 496 and
        # 469 with the reach and FIRST_STEP.)
        # A step measures the error only while the secant converges: the first one
        # (from two points FIRST_STEP apart, a Newton step), or one shorter than the
        # step before, itself at most half of the one before it. From a point far
        # off, with det there much larger, the step is short whatever the error:
        # a step back from an overshoot is as long as the overshoot, and on a
        # cantilever's pair 2.5e-6 apart the step of 1.4e-9 after two of 1.1e-3
        # stopped the secant between the two roots, at det's extremum.
        converging = ~np.isfinite(previous) | ((size < previous) & (previous <= before / 2))
        reach = np.abs(new - oldest) / np.abs(new)
        measured = converging & np.isfinite(previous) & np.isfinite(reach) & (reach > 0)  # none before two steps
        ahead = np.where(measured, size * size / np.where(measured, reach, 1.0), np.inf)
        done = (((size <= tolerance) & converging) | (ahead <= tolerance / 10)
                | ((size >= previous / 2) & (size <= floor)) | (sign == 0) | bracketed)
        roots[active[done]] = np.where(sign[done] == 0, x[done], new[done])
        steps[active[done]] = np.where(bracketed[done], np.abs(x_old - x)[done] / np.abs(new[done]),
                                       np.minimum(size[done], ahead[done]))
        keep = ~done
        if not keep.any():
            break
        active, previous, before, oldest = active[keep], size[keep], previous[keep], x_old[keep]
        bracketed = np.zeros(active.size, dtype=bool)
        tolerance = tolerance[keep]
        x_old, sign_old, log_old = x[keep], sign[keep], log_abs[keep]
        x = new[keep]
        sign, log_abs = log_det(x)
    distance = np.abs(roots - starts) / np.abs(starts)  # NaN where the secant did not settle
    noise = _in_noise(log_det, roots, steps, starts, distance, unconfirmed, spans, level)
    steps[noise] = np.maximum(steps[noise], distance[noise])
    roots[noise] = starts[noise]
    return roots, steps


def _in_noise(log_det, roots: np.ndarray, steps: np.ndarray, starts: np.ndarray, distance: np.ndarray,
              unconfirmed: np.ndarray, spans: np.ndarray, level: np.ndarray) -> np.ndarray:
    """(n,) bool: which secant results ``roots`` (rad/s) from the ends of a bracket whose
    signs agree (indices ``unconfirmed``) lie in det's rounding noise about their start
    (``distance``: relative, from it).

    Near some roots det's sign is noise (launcher 2 at 780 Hz: over ±5e-9), where the
    secant settles on a sign flip with a last step far shorter than its distance d from
    the start, a Rayleigh value that is 1e-16 to 1e-13 off on the launchers. A result
    within its own last step of the start cannot be told from it; one within
    NOISE_SPANS half-widths is tested: det at NOISE_REACH · d either side of it must
    change sign, and a det linear through those two points must give the bracket's
    farther end (``level``: the larger log|det| at its ends) within a factor of
    √NOISE_REACH, as a simple root's det does (one evaluation each side, all in one
    call); else det there is noise (flat at its rounding floor, or the secant's point is
    not where the sign changes): two evaluations more per tested result, only where a
    bracket failed."""
    noise = np.zeros(roots.size, dtype=bool)
    noise[unconfirmed] = distance[unconfirmed] <= steps[unconfirmed]
    tested = unconfirmed[~noise[unconfirmed] & (distance[unconfirmed] <= NOISE_SPANS * spans[unconfirmed])]
    if not tested.size:
        return noise
    root, start = roots[tested], starts[tested]
    reach = NOISE_REACH * np.abs(root - start)
    signs, logs = log_det(np.concatenate([root - reach, root + reach]))
    (below, above), (log_below, log_above) = np.split(signs, 2), np.split(logs, 2)
    farther = np.maximum(np.abs(root - start * (1 - spans[tested])), np.abs(root - start * (1 + spans[tested])))
    expected = 0.5 * (log_below + log_above) + np.log(farther / reach)  # a linear det's at the farther end
    linear = ((below * above).real < 0) & (np.abs(level[tested] - expected) < 0.5 * np.log(NOISE_REACH))
    noise[tested[~linear]] = True
    return noise
