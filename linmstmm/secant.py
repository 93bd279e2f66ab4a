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
    and where it comes back within its last step of the start, det cannot tell
    them apart and the start is the root (the step stays its uncertainty).
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
    unconfirmed = bracketing & ~bracketed  # a bracket whose ends det does not tell apart
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
    # Where det does not change sign across a bracket and the secant from its ends comes
    # back within its own last step of the start, det cannot tell the two apart at its
    # rounding floor, and the start (a Rayleigh value: 1e-16 to 1e-13 off on the
    # launchers) is the nearer: launcher 2's 67th root, 1.1e-10 off by the secant, is the
    # start to the bit. The step stays what det can confirm.
    with np.errstate(invalid="ignore"):
        indistinct = unconfirmed & (np.abs(roots - starts) <= steps * np.abs(roots))
    roots[indistinct] = starts[indistinct]
    return roots, steps
