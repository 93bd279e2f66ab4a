"""Modal response to point loads, and frequency response functions (docs/method.md).

With the augmented eigenvectors V^k of :mod:`linmstmm.modes` and proportional
damping C = αM + βK (the model's ``[damping]``) or modal damping ratios ζ_k,
each modal coordinate obeys

    q̈_k + c_k q̇_k + ω_k² q_k = p_k(t),   c_k = α + β ω_k²  or  2 ζ_k ω_k,
    p_k(t) = Σ_loads (F · u^k(P) + T · θ^k(P)) g(t) / M_k,

for a force F and moment T at point P with time function g(t): a force at a
point works on the mode's displacement there. The displacement of any point
is x(t) = Σ_k φ^k q_k(t) (velocity and acceleration alike).

Every mode is solved exactly, not by a step-by-step ODE scheme. A time
function is a sequence of segments; on segment j (from ``start_j`` to the
next start) g obeys g'' = −ν_j g, i.e. it is linear (ν = 0) or sinusoidal
(ν = Ω²), from given g and g' at its start; a segment may also open with a
Dirac impulse. The modal oscillator and the load generator together form a
linear system y' = G y, y = (q, q̇, g, g'), so the state is carried by the
exact propagator exp(G τ): Duhamel's integral in closed form, exact to
rounding for every damping (under-, over-, critically damped,
zero-frequency rigid-body modes). The output times are equally spaced, so
a segment needs two propagators per mode (to its first output time, to its
end) and each distinct ν one over an output step, all computed in one
call; the states at all output times
of the segment follow by doubling (the first m states times P^m give the
next m), log2(n_t) products over all modes and times at once. Step,
impulse, harmonic and half-sine loads are one or two segments; tabulated
samples are linear between samples (the exact piecewise-linear-load
recurrence).

A truncated modal sum misses part of the static deflection. The static
correction (mode acceleration) adds, for each load f g(t),

    (K⁻¹f − Σ_k φ^k p_k / ω_k²) g(t)

(and g', g'' to velocity and acceleration), with K⁻¹f from the FE route's
static solve (:func:`linmstmm.fe.static_displacements`), so a slowly applied
or lasting load gives the static solution exactly. :func:`respond` adds it
for held models; a free-floating model, or one with a mechanism (a joint
free to move), gets the modal sum alone and a note.

The frequency response (receptance) between a load and the points is the
modal sum H(Ω) = Σ_k φ^k (d · φ^k_load) / (M_k (ω_k² − Ω² + i Ω c_k)).

A spring's dashpot ``c`` couples the modes; this modal route cannot honour
it and the time response refuses such a model (:func:`refuse_dashpots`)
instead of dropping it. The FRF of such a model is solved directly
(:func:`linmstmm.forced.direct_frf`).

Load file (TOML)
----------------
::

    # one [[load]] per point load; all act together (superposition)
    [[load]]
    point = "tip"                    # a point of the model
    force = [0.0, 0.0, -1000.0]      # N, inertial axes (optional, default 0)
    moment = [0.0, 0.0, 0.0]         # N m (optional, default 0)
    time = { kind = "half_sine", duration = 0.01, start = 0.0 }

    [[load]]
    point = "muzzle"
    force = [-50.0, 0.0, 0.0]        # for kind = "impulse": N s (and moment N m s)
    time = { kind = "impulse", start = 0.2 }

    [output]                         # optional
    points = ["tip", "root"]         # response points (default: every point)
    duration = 1.0                   # s, default 1
    step = 1e-3                      # s, default duration / 1000
    modes = 20                       # elastic modes in the sum, default 20

Time kinds, g(t) with τ = t − start (g = 0 before ``start``, default 0 s):

=============  ==============================================================
``step``       g = 1
``impulse``    g = δ(τ): force and moment are impulses, N s and N m s
``half_sine``  g = sin(π τ / duration) for τ < duration, then 0
``harmonic``   g = sin(2π frequency τ + phase); frequency Hz, phase rad (0)
``table``      ``time = [...]`` (s, increasing), ``value = [...]`` (same
               length): linear between samples, 0 before the first; after
               the last 0, or the last value if ``hold = true``. No
               ``start``: the sample times are absolute.
=============  ==============================================================

Errors in the file are :class:`linmstmm.model.ModelError` naming the file,
the load and the key.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from linmstmm.model import Model, ModelError
from linmstmm.model_file import _did_you_mean, _read_toml, _Table
from linmstmm.modes import ModalResult, mode_shapes

#: Default [output] values of a load file.
DEFAULT_DURATION = 1.0
DEFAULT_STEPS = 1000
DEFAULT_MODES = 20
#: Output times count as equally spaced when every step is within this
#: fraction of their mean step (rounding of ``start + i * step``).
SPACING_TOLERANCE = 1e-9
#: Exponentials by scaling and squaring: a Taylor series of this many terms
#: on matrices scaled to a 1-norm of at most TAYLOR_RADIUS (error below
#: RADIUS^(TERMS+1) / (TERMS+1)! = 1.6e-23 relative).
TAYLOR_TERMS = 18
TAYLOR_RADIUS = 0.5


# --- time functions -----------------------------------------------------------

@dataclass(frozen=True, eq=False)
class TimeFunction:
    """g(t) as segments (see the module docstring); arrays of shape (E,).

    starts : s, non-decreasing. nu : ν of g'' = −ν g, rad²/s². values, slopes :
    g and g' just after each start. kicks : weight of a Dirac at each start, s.
    """

    kind: str
    starts: np.ndarray
    nu: np.ndarray
    values: np.ndarray
    slopes: np.ndarray
    kicks: np.ndarray

    def __call__(self, t) -> np.ndarray:
        """g at the times ``t`` (s), shape of ``t``; Dirac impulses are not shown."""
        return self.derivatives(t)[0]

    def derivatives(self, t):
        """(g, g', g'') at the times ``t`` (s), each of the shape of ``t``.

        Units 1, 1/s, 1/s²; Dirac impulses (and those of g' and g'' at a kink
        or jump) are not shown.
        """
        t = np.asarray(t, dtype=float)
        j = np.searchsorted(self.starts, t, side="right") - 1
        segment = np.maximum(j, 0)
        tau = t - self.starts[segment]
        nu, value, slope = self.nu[segment], self.values[segment], self.slopes[segment]
        rate = np.sqrt(nu)
        g = value * np.cos(rate * tau) + slope * tau * np.sinc(rate * tau / np.pi)
        rate_of_g = slope * np.cos(rate * tau) - value * rate * np.sin(rate * tau)
        active = j >= 0
        return tuple(np.where(active, x, 0.0) for x in (g, rate_of_g, -nu * g))


def _segments(kind, starts, nu, values, slopes, kicks=0.0) -> TimeFunction:
    """A TimeFunction from per-segment values (scalars broadcast)."""
    arrays = np.broadcast_arrays(*(np.atleast_1d(np.asarray(a, dtype=float))
                                   for a in (starts, nu, values, slopes, kicks)))
    return TimeFunction(kind, *(a.copy() for a in arrays))


def step(start: float = 0.0) -> TimeFunction:
    """g = 1 from ``start`` (s) on."""
    return _segments("step", start, 0.0, 1.0, 0.0)


def impulse(start: float = 0.0) -> TimeFunction:
    """g = δ(t − start): the load's force and moment are impulses (N s, N m s)."""
    return _segments("impulse", start, 0.0, 0.0, 0.0, kicks=1.0)


def half_sine(duration: float, start: float = 0.0) -> TimeFunction:
    """g = sin(π (t − start) / duration) for ``duration`` seconds, 0 otherwise."""
    rate = np.pi / duration
    return _segments("half_sine", [start, start + duration], [rate**2, 0.0], 0.0, [rate, 0.0])


def harmonic(frequency: float, phase: float = 0.0, start: float = 0.0) -> TimeFunction:
    """g = sin(2π frequency (t − start) + phase) from ``start`` on (frequency in Hz)."""
    rate = 2 * np.pi * frequency
    return _segments("harmonic", start, rate**2, np.sin(phase), rate * np.cos(phase))


def table(times, values, hold: bool = False) -> TimeFunction:
    """Samples (s, increasing; values) joined linearly; 0 after the last unless ``hold``."""
    times, values = np.asarray(times, dtype=float), np.asarray(values, dtype=float)
    slopes = np.r_[np.diff(values) / np.diff(times), 0.0]
    if not hold:
        times, values, slopes = np.r_[times, times[-1]], np.r_[values, 0.0], np.r_[slopes, 0.0]
    return _segments("table", times, np.zeros(times.size), values, slopes)


# --- loads and results ----------------------------------------------------------

@dataclass(frozen=True, eq=False)
class PointLoad:
    """Force (3,) N and moment (3,) N m at ``point``, inertial axes, times g(t)."""

    point: str
    force: np.ndarray
    moment: np.ndarray
    time: TimeFunction

    @property
    def vector(self) -> np.ndarray:
        """(6,) [force, moment], paired with the displacement [u, θ]."""
        return np.r_[self.force, self.moment]


@dataclass(frozen=True, eq=False)
class LoadCase:
    """A load file: loads, output times (s), response points, number of modes."""

    loads: tuple[PointLoad, ...]
    times: np.ndarray
    points: tuple[str, ...] | None
    modes: int


@dataclass(frozen=True, eq=False)
class ResponseResult:
    """Response histories.

    times : (n_t,) s. points : names, in order.
    displacement, velocity, acceleration : (n_t, n_points, 6) m, m/s, m/s²
    (translations) and rad, rad/s, rad/s² (rotations), inertial axes
    (:data:`QUANTITY_UNITS`).
    modal : (n_t, n_modes) modal coordinates q_k.
    elastic_modes : elastic modes in the modal sum.
    static_correction : whether the static correction (mode acceleration) is in.
    note : why it is not, when it was asked for ("" otherwise).
    frequencies_hz : (elastic_modes,) natural frequencies of the elastic modes in the sum, Hz.
    rigid_body_modes : zero-frequency modes in the sum.
    """

    times: np.ndarray
    points: tuple[str, ...]
    displacement: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    modal: np.ndarray
    elastic_modes: int
    static_correction: bool = False
    note: str = ""
    frequencies_hz: np.ndarray = field(default_factory=lambda: np.empty(0))
    rigid_body_modes: int = 0

    def to_dict(self) -> dict:
        """Plain JSON-ready dictionary: point -> lists (n_t, 6); ``units`` per quantity and component.

        Returns
        -------
        dict
            ``times``, ``points``, ``elastic_modes``, ``rigid_body_modes``, ``frequencies_hz``,
            ``static_correction``, ``note`` when set, ``units``, ``displacement``,
            ``velocity``, ``acceleration``.
        """
        return {"times": self.times.tolist(), "points": list(self.points),
                "elastic_modes": self.elastic_modes, "rigid_body_modes": self.rigid_body_modes,
                "frequencies_hz": self.frequencies_hz.tolist(), "static_correction": self.static_correction,
                **({"note": self.note} if self.note else {}),
                "units": {"times": "s", **{name: quantity_units(name) for name in QUANTITY_UNITS}},
                **{name: {p: values[:, i].tolist() for i, p in enumerate(self.points)}
                   for name, values in (("displacement", self.displacement),
                                        ("velocity", self.velocity),
                                        ("acceleration", self.acceleration))}}


#: SI units of each response quantity: (translations, rotations).
QUANTITY_UNITS = {"displacement": ("m", "rad"), "velocity": ("m/s", "rad/s"),
                  "acceleration": ("m/s^2", "rad/s^2")}


def quantity_units(quantity: str) -> list[str]:
    """The six component units (x, y, z, rx, ry, rz) of ``quantity``, e.g. "velocity"."""
    translation, rotation = QUANTITY_UNITS[quantity]
    return [translation] * 3 + [rotation] * 3


@dataclass(frozen=True, eq=False)
class FRFResult:
    """Receptance between one load direction and the points.

    excitation_hz : (n_f,) excitation frequencies, Hz. points : names. receptance : (n_f, n_points, 6)
    complex, m/N (or rad/N, m/(N m), rad/(N m)) per unit of the load vector.
    """

    excitation_hz: np.ndarray
    points: tuple[str, ...]
    receptance: np.ndarray

    @property
    def mobility(self) -> np.ndarray:
        """Velocity per load, iΩ H."""
        return 2j * np.pi * self.excitation_hz[:, None, None] * self.receptance

    @property
    def accelerance(self) -> np.ndarray:
        """Acceleration per load, −Ω² H."""
        return -(2 * np.pi * self.excitation_hz[:, None, None]) ** 2 * self.receptance

    def to_dict(self) -> dict:
        """Plain JSON-ready dictionary: point -> real and imaginary parts (n_f, 6).

        Returns
        -------
        dict
            ``excitation_hz``, ``points`` and ``receptance`` (point -> ``{real, imag}``).
        """
        return {"excitation_hz": self.excitation_hz.tolist(), "points": list(self.points),
                "receptance": {p: {"real": self.receptance[:, i].real.tolist(),
                                   "imag": self.receptance[:, i].imag.tolist()}
                               for i, p in enumerate(self.points)}}


# --- the solution ---------------------------------------------------------------

class DampingRatioError(ValueError):
    """Modal damping ratios that do not fit the modes (count, sign) or come with Rayleigh damping."""


def modal_damping(omega, damping=None, damping_ratio=None) -> np.ndarray:
    """Modal damping rates c_k of q̈_k + c_k q̇_k + ω_k² q_k = p_k, 1/s.

    Parameters
    ----------
    omega : (n,) ω_k, rad/s; zero-frequency rigid-body modes first.
    damping : (α, β) of C = αM + βK (c_k = α + β ω_k²), or None.
    damping_ratio : ζ for every elastic mode, or (n_elastic,) one per elastic
        mode in order (c_k = 2 ζ_k ω_k; rigid-body modes undamped), or None.
        Not together with ``damping``: the caller picks one.

    Raises :class:`DampingRatioError` for ratios that do not fit.

    Returns
    -------
    (n,) c_k, 1/s (zeros when both are None: undamped).
    """
    omega = np.asarray(omega, dtype=float)
    if damping_ratio is None:
        alpha, beta = damping if damping is not None else (0.0, 0.0)
        return alpha + beta * omega**2
    if damping is not None:
        raise DampingRatioError("give Rayleigh damping (alpha, beta) or modal damping ratios, not both")
    ratio = np.asarray(damping_ratio, dtype=float)
    elastic = omega > 0
    if ratio.ndim > 1 or ratio.size not in (1, int(elastic.sum())) or np.any(ratio < 0):
        raise DampingRatioError(f"give one damping ratio >= 0 for all elastic modes or one for each of "
                                f"the {int(elastic.sum())} in the sum, got {ratio.tolist()}")
    rates = np.zeros(omega.size)
    rates[elastic] = 2 * ratio * omega[elastic]
    return rates


def participation(modes: ModalResult, point: str, vector) -> np.ndarray:
    """(n,) ⟨f, V^k⟩ / M_k for the (6,) load ``vector`` [force, moment] at ``point``."""
    return modes.point_displacements[point] @ np.asarray(vector, dtype=float) / modes.modal_mass


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


def modal_response(modes: ModalResult, loads, times, points=None, damping=None, *,
                   damping_ratio=None, static=None) -> ResponseResult:
    """Response of the points to ``loads`` by modal superposition.

    Parameters
    ----------
    modes : the modes in the sum (rigid-body modes included).
    loads : sequence of :class:`PointLoad`.
    times : (n_t,) s, increasing in equal steps.
    points : names (default: every point of the modes).
    damping, damping_ratio : Rayleigh (α, β) or modal ratios ζ, see
        :func:`modal_damping` (one of them, or neither: undamped).
    static : (n_loads, n_points, 6) elastic static displacements K⁺f of each
        load at the points (m, rad; :func:`linmstmm.fe.static_displacements`),
        or None. Given, the static correction (mode acceleration) is added:
        each load's part of K⁺f that the modal sum leaves out, times g(t)
        (and g', g'' for velocity and acceleration), so that a slowly
        applied or lasting load gives the static solution exactly.

    Returns
    -------
    :class:`ResponseResult`.
    """
    times = np.asarray(times, dtype=float)
    points = tuple(modes.point_displacements) if points is None else tuple(points)
    rate = modal_damping(modes.omega, damping, damping_ratio)
    histories = np.zeros((3, times.size, modes.omega.size))
    for load in loads:
        response = unit_response(modes.omega, rate, load.time, times)
        histories += participation(modes, load.point, load.vector) * np.stack(response)
    shapes = np.stack([modes.point_displacements[p] for p in points], axis=1)  # (n, p, 6)
    physical = np.einsum("htk,kpc->htpc", histories, shapes)
    if static is not None:
        physical += _static_correction(modes, loads, times, shapes, np.asarray(static, dtype=float))
    elastic = modes.omega > 0
    return ResponseResult(times, points, *physical, histories[0], int(np.count_nonzero(elastic)),
                          static is not None, frequencies_hz=modes.frequencies_hz[elastic],
                          rigid_body_modes=modes.rigid_body_modes)


def _static_correction(modes: ModalResult, loads, times, shapes, static) -> np.ndarray:
    """(3, n_t, n_points, 6): Σ_loads (K⁺f − Σ_elastic φ_k p_k / ω_k²) (g, g', g'')."""
    elastic = modes.omega > 0
    correction = np.zeros((3, times.size) + shapes.shape[1:])
    for load, solution in zip(loads, static):
        modal_part = participation(modes, load.point, load.vector)[elastic] / modes.omega[elastic] ** 2
        residual = solution - np.einsum("k,kpc->pc", modal_part, shapes[elastic])
        correction += np.stack(load.time.derivatives(times))[:, :, None, None] * residual
    return correction


def frf(modes: ModalResult, point: str, vector, excitation_hz, points=None,
        damping=None, *, damping_ratio=None) -> FRFResult:
    """Receptance between a load ``vector`` at ``point`` and the response ``points``.

    Parameters
    ----------
    modes : ModalResult
        The modes in the sum (rigid-body modes included).
    point : str
        The load point.
    vector : array_like, shape (6,)
        The load [force (N), moment (N m)], inertial axes.
    excitation_hz : array_like, shape (n_f,)
        Excitation frequencies, Hz.
    points : sequence of str, optional
        Response points (default: every point of the modes).
    damping : tuple of float, optional
        Rayleigh (α 1/s, β s), see :func:`modal_damping`.
    damping_ratio : float or sequence of float, optional
        Modal damping ratios ζ instead (neither: undamped, infinite at the
        natural frequencies).

    Returns
    -------
    FRFResult
    """
    excitation_hz = np.asarray(excitation_hz, dtype=float)
    points = tuple(modes.point_displacements) if points is None else tuple(points)
    Omega = 2 * np.pi * excitation_hz[:, None]
    rate = modal_damping(modes.omega, damping, damping_ratio)
    modal = participation(modes, point, vector) / (modes.omega**2 - Omega**2 + 1j * Omega * rate)
    shapes = np.stack([modes.point_displacements[p] for p in points], axis=1)
    return FRFResult(excitation_hz, points, np.einsum("fk,kpc->fpc", modal, shapes))


def respond(model: Model, case: LoadCase, damping_ratio=None,
            static_correction: bool = True) -> ResponseResult:
    """The response of ``model`` to a load case.

    Parameters
    ----------
    model, case : the model and its load file.
    damping_ratio : modal damping ratios ζ (see :func:`modal_damping`); given,
        they replace the model's ``[damping]``; None: the model's damping.
    static_correction : add the static correction (mode acceleration), the
        static solution from :func:`linmstmm.fe.static_displacements`. Not
        for a model with rigid-body or mechanism modes (the result's ``note`` says so):
        there the elastic part of a beam's static solution depends on the
        mesh (its rigid-body motion is removed with the mesh's mass), so
        it would not be exact.

    Returns
    -------
    ResponseResult

    Raises
    ------
    ModelError
        For a spring with a dashpot (:func:`refuse_dashpots`).
    DampingRatioError
        For damping ratios that do not fit the modes.
    """
    from linmstmm.fe.flexibility import static_displacements

    refuse_dashpots(model, "time response")
    modes = mode_shapes(model, case.modes)
    points = tuple(modes.point_displacements) if case.points is None else case.points
    held = modes.rigid_body_modes == 0
    static = (static_displacements(model, [(load.point, load.vector) for load in case.loads], points)
              if static_correction and held else None)
    damping = model.damping if damping_ratio is None else None
    result = modal_response(modes, case.loads, case.times, points, damping,
                            damping_ratio=damping_ratio, static=static)
    if static_correction and not held:
        return replace(result, note=f"no static correction: the model has {modes.rigid_body_modes} "
                                    f"rigid-body modes (free-floating, or a joint's mechanism); the "
                                    f"modal sum alone")
    return result


def refuse_dashpots(model: Model, what: str) -> None:
    """Raise ModelError on the first spring with a nonzero dashpot ``c``.

    The modal route's modes are undamped and their damping is proportional
    (``[damping]``) or modal (ratios); a discrete dashpot couples the modes,
    so the modal ``what`` (e.g. "time response") cannot honour it.
    """
    for spring in model.springs:
        if spring.c is not None and np.any(spring.c > 0):
            raise ModelError(model.source or model.name,
                             f"the modal {what} cannot honour a spring's dashpot (its modes are "
                             f"undamped); remove 'c' and give [damping] or modal damping ratios",
                             element=f"spring '{spring.name}'", key="c")


# --- the load file --------------------------------------------------------------

_TIME_KEYS = {
    "step": ((), ("start",)),
    "impulse": ((), ("start",)),
    "half_sine": (("duration",), ("start",)),
    "harmonic": (("frequency",), ("phase", "start")),
    "table": (("time", "value"), ("hold",)),
}


def load_loads(path, model: Model) -> LoadCase:
    """Read and validate the load file ``path`` (format: module docstring) for ``model``.

    Parameters
    ----------
    path : str or os.PathLike
        The load file (format: ``docs/cli.md``, load files).
    model : Model
        The model whose points the loads name.

    Returns
    -------
    LoadCase

    Raises
    ------
    ModelError
        One line naming the file, the load and the key at fault.
    """
    file = str(path)
    top = _Table(file, _read_toml(path, file))
    top.check_keys(("load",), ("output",))
    points = model.points
    tables = top.array_of_tables("load")
    if not tables:
        raise top.error("load", "no [[load]] given")
    loads = tuple(_check_load(_Table(file, table, f"load #{i + 1}"), points)
                  for i, table in enumerate(tables))
    output = top.section("output")
    output.check_keys((), ("points", "duration", "step", "modes"))
    duration = output.number("duration", "> 0", default=DEFAULT_DURATION)
    dt = output.number("step", "> 0", default=duration / DEFAULT_STEPS)
    modes = output.table.get("modes", DEFAULT_MODES)
    if isinstance(modes, bool) or not isinstance(modes, int) or modes < 1:
        raise output.error("modes", f"must be a positive integer, got {modes!r}")
    names = output.point_names("points", points) if "points" in output else None
    return LoadCase(loads, np.arange(int(np.floor(duration / dt + 1e-9)) + 1) * dt, names, modes)


def _check_load(t: _Table, points) -> PointLoad:
    t.check_keys(("point", "time"), ("force", "moment"))
    point = t.string("point", nonempty=True)
    if point not in points:
        raise t.error("point", f"unknown point {point!r}{_did_you_mean(point, points)}")
    force = t.vector("force", 3) if "force" in t else np.zeros(3)
    moment = t.vector("moment", 3) if "moment" in t else np.zeros(3)
    if not isinstance(t.table["time"], dict):
        raise t.error("time", "must be a table, e.g. { kind = \"step\" }")
    return PointLoad(point, force, moment, _check_time(_Table(t.file, t.table["time"], t.element)))


def _check_time(t: _Table) -> TimeFunction:
    kind = t.string("kind") if "kind" in t else None
    if kind not in _TIME_KEYS:
        raise t.error("time", f"kind must be one of {', '.join(_TIME_KEYS)}, got {kind!r}")
    required, optional = _TIME_KEYS[kind]
    t.check_keys(("kind", *required), optional)
    start = t.number("start", default=0.0)
    if kind == "step":
        return step(start)
    if kind == "impulse":
        return impulse(start)
    if kind == "half_sine":
        return half_sine(t.number("duration", "> 0"), start)
    if kind == "harmonic":
        return harmonic(t.number("frequency", "> 0"), t.number("phase", default=0.0), start)
    samples = t.table["time"]
    if not isinstance(samples, list) or not samples:
        raise t.error("time", "must be a non-empty array of times")
    times, values = t.vector("time", len(samples)), t.vector("value", len(samples))
    if np.any(np.diff(times) <= 0):
        raise t.error("time", "sample times must increase strictly")
    return table(times, values, t.boolean("hold", False))
