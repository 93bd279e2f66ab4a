"""Exact modal time response: Duhamel's integral in closed form.

Every mode is solved exactly, not by a step-by-step ODE scheme. Each load's
time function is a sequence of segments on which g'' = −ν g
(:class:`linmstmm.loads.TimeFunction`). The modal oscillator and the load
generator together form a linear system y' = G y, y = (q, q̇, g, g'), so the
state is carried by the exact propagator exp(G τ): Duhamel's integral in
closed form, exact to rounding for every damping (under-, over-, critically
damped, zero-frequency rigid-body modes). The output times are equally
spaced, so a segment needs two propagators per mode (to its first output
time, to its end) and each distinct ν one over an output step, all computed
in one call; the states at all output times of the segment follow by
doubling (the first m states times P^m give the next m), log2(n_t) products
over all modes and times at once. Step, impulse, harmonic and half-sine
loads are one or two segments; tabulated samples are linear between samples
(the exact piecewise-linear-load recurrence).
"""
from __future__ import annotations

import numpy as np

from linmstmm.loads import TimeFunction

#: Output times count as equally spaced when every step is within this
#: fraction of their mean step (rounding of ``start + i * step``).
SPACING_TOLERANCE = 1e-9
#: Exponentials by scaling and squaring: a Taylor series of this many terms
#: on matrices scaled to a 1-norm of at most TAYLOR_RADIUS (error below
#: RADIUS^(TERMS+1) / (TERMS+1)! = 1.6e-23 relative).
TAYLOR_TERMS = 18
TAYLOR_RADIUS = 0.5


def unit_response(omega, damping_rate, function: TimeFunction, times):
    """Exact response of q̈ + c q̇ + ω² q = g(t) from rest, for each mode.

    Parameters
    ----------
    omega, damping_rate : (n,) ω_k, rad/s, and c_k, 1/s.
    function : the load's time function g.
    times : (n_t,) s, increasing and equally spaced.

    Returns
    -------
    (q, q̇, q̈), each (n_t, n), in s², s and 1 per unit of g.
    """
    omega, rate = np.asarray(omega, float), np.asarray(damping_rate, float)
    times = np.asarray(times, dtype=float)
    starts, segments = function.starts, function.starts.size
    bounds = np.searchsorted(times, np.r_[starts, np.inf], side="left")  # output times [bounds[j], bounds[j+1])
    reached = bounds[:-1] < times.size
    leads = np.zeros(segments)  # from each start to its first output time
    leads[reached] = times[bounds[:-1][reached]] - starts[reached]
    nus, kind = np.unique(function.nu, return_inverse=True)
    generators = _generators(omega, rate, nus)  # (U, n, 4, 4), one per distinct ν
    lead, carry, stride = np.split(_propagators(
        np.concatenate([generators[kind], generators[kind], generators]),
        np.r_[leads, np.diff(starts), 0.0, np.full(nus.size, _spacing(times))]), [segments, 2 * segments])
    out = np.zeros((times.size, omega.size, 4))
    state = np.zeros((omega.size, 4))
    for j in range(segments):
        state[:, 1] += function.kicks[j]
        state[:, 2], state[:, 3] = function.values[j], function.slopes[j]
        first, stop = bounds[j], bounds[j + 1]
        if stop > first:
            out[first:stop] = _march(stride[kind[j]], _apply(lead[j], state), stop - first)
        state = _apply(carry[j], state)
    q, velocity, load = out[..., 0], out[..., 1], out[..., 2]
    return q, velocity, load - rate * velocity - omega**2 * q


def _spacing(times: np.ndarray) -> float:
    """The step (s) of equally spaced ``times`` (0 for a single time); ValueError otherwise."""
    if times.size < 2:
        return 0.0
    steps = np.diff(times)
    spacing = (times[-1] - times[0]) / (times.size - 1)
    if not spacing > 0 or np.abs(steps - spacing).max() > SPACING_TOLERANCE * spacing:
        raise ValueError("times must increase in equal steps")
    return spacing


def _generators(omega, rate, nus) -> np.ndarray:
    """(U, n, 4, 4) G of y' = G y, y = (q, q̇, g, g'), per mode, for each g'' = −ν g of ``nus`` (U,)."""
    G = np.zeros((nus.size, omega.size, 4, 4))
    G[..., 0, 1] = 1.0
    G[..., 1, 0] = -omega**2
    G[..., 1, 1] = -rate
    G[..., 1, 2] = 1.0
    G[..., 2, 3] = 1.0
    G[..., 3, 2] = -nus[:, None]
    return G


def _propagators(generators: np.ndarray, durations: np.ndarray) -> np.ndarray:
    """(m, n, 4, 4) exp(G_i τ_i), the exact Duhamel integral over each duration.

    generators : (m, n, 4, 4) from :func:`_generators`. durations : (m,) s.
    All at once by scaling and squaring: the state is first balanced to
    (ω q, q̇, √ν g, g') (1 in place of a zero ω or ν), so each oscillator
    block has entries ω, c and √ν rather than ω² and ν; each Gτ is scaled by
    2^-s to a 1-norm of at most TAYLOR_RADIUS, its exponential summed to
    TAYLOR_TERMS terms, then squared s times. Vectorised over every matrix
    (scipy.linalg.expm takes a stack one matrix at a time).
    """
    rates = np.sqrt(-generators[..., [1, 3], [0, 2]])  # (m, n, 2): ω and √ν
    scale = np.ones(generators.shape[:-1])
    scale[..., [0, 2]] = np.where(rates > 0, rates, 1.0)
    X = generators * (scale[..., :, None] / scale[..., None, :]) * durations[:, None, None, None]
    norms = np.abs(X).sum(axis=-2).max(axis=-1)
    squarings = np.ceil(np.log2(np.maximum(norms, TAYLOR_RADIUS) / TAYLOR_RADIUS)).astype(int)
    X = X / (2.0 ** squarings)[..., None, None]
    identity = np.eye(4)
    power = identity + X / TAYLOR_TERMS
    for k in range(TAYLOR_TERMS - 1, 0, -1):  # Horner: I + X (I + X/2 (I + X/3 (...)))
        power = identity + np.einsum("...ij,...jk->...ik", X, power) / k
    for round_ in range(int(squarings.max(initial=0))):
        square = squarings > round_
        power[square] = np.einsum("mij,mjk->mik", power[square], power[square])
    return power * scale[..., None, :] / scale[..., :, None]


def _apply(propagator: np.ndarray, state: np.ndarray) -> np.ndarray:
    """(n, 4) propagator (n, 4, 4) times state (n, 4), mode by mode."""
    return np.einsum("nij,nj->ni", propagator, state)


def _march(propagator: np.ndarray, first: np.ndarray, count: int) -> np.ndarray:
    """(count, n, 4) states P^i first, i = 0 … count − 1, by doubling.

    Each pass applies P^m to the m states known so far, then squares P^m:
    log2(count) products, each over all of those states and modes at once.
    """
    states = np.empty((count,) + first.shape)
    states[0] = first
    power, known = propagator, 1
    while known < count:
        new = min(known, count - known)
        states[known:known + new] = np.einsum("nij,knj->kni", power, states[:new])
        power, known = power @ power, known + new
    return states
