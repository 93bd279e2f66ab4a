"""Modal response to point loads, and frequency response functions (docs/method.md).

With the augmented eigenvectors V^k of :mod:`linmstmm.modes` and proportional
damping C = αM + βK (the model's ``[damping]``), each modal coordinate obeys

    q̈_k + c_k q̇_k + ω_k² q_k = p_k(t),   c_k = α + β ω_k²,
    p_k(t) = Σ_loads (F · u^k(P) + T · θ^k(P)) g(t) / M_k,

for a force F and moment T at point P with time function g(t): a force at a
point works on the mode's displacement there. The displacement of any point
is x(t) = Σ_k φ^k q_k(t) (velocity and acceleration alike).

Every mode is solved exactly, not by a step-by-step ODE scheme. A time
function is a sequence of segments; on segment j (from ``start_j`` to the
next start) g obeys g'' = −ν_j g, i.e. it is linear (ν = 0) or sinusoidal
(ν = Ω²), from given g and g' at its start; a segment may also open with a
Dirac impulse. The modal oscillator and the load generator together form a
linear system y' = G y, y = (q, q̇, g, g'), so the state is carried across a
segment by the matrix exponential expm(G τ): Duhamel's integral in closed
form, exact to rounding for every damping (under-, over-, critically damped,
zero-frequency rigid-body modes). Step, impulse, harmonic and half-sine loads
are one or two segments; tabulated samples are linear between samples (the
exact piecewise-linear-load recurrence).

The frequency response (receptance) between a load and the points is the
modal sum H(Ω) = Σ_k φ^k (d · φ^k_load) / (M_k (ω_k² − Ω² + i Ω c_k)).

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

from dataclasses import dataclass

import numpy as np
import scipy.linalg

from linmstmm.model import Model, _did_you_mean, _read_toml, _Table
from linmstmm.modes import ModalResult, mode_shapes

#: Default [output] values of a load file.
DEFAULT_DURATION = 1.0
DEFAULT_STEPS = 1000
DEFAULT_MODES = 20


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
        t = np.asarray(t, dtype=float)
        j = np.searchsorted(self.starts, t, side="right") - 1
        segment = np.maximum(j, 0)
        tau = t - self.starts[segment]
        rate = np.sqrt(self.nu[segment])
        oscillating = self.values[segment] * np.cos(rate * tau) + self.slopes[segment] * tau * np.sinc(
            rate * tau / np.pi)
        return np.where(j >= 0, oscillating, 0.0)


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
    (translations) and rad, rad/s, rad/s² (rotations), inertial axes.
    modal : (n_t, n_modes) modal coordinates q_k.
    """

    times: np.ndarray
    points: tuple[str, ...]
    displacement: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    modal: np.ndarray

    def to_dict(self) -> dict:
        """Plain JSON-ready dictionary: point -> lists (n_t, 6)."""
        return {"times": self.times.tolist(), "points": list(self.points),
                **{name: {p: values[:, i].tolist() for i, p in enumerate(self.points)}
                   for name, values in (("displacement", self.displacement),
                                        ("velocity", self.velocity),
                                        ("acceleration", self.acceleration))}}


@dataclass(frozen=True, eq=False)
class FRFResult:
    """Receptance between one load direction and the points.

    frequencies_hz : (n_f,). points : names. receptance : (n_f, n_points, 6)
    complex, m/N (or rad/N, m/(N m), rad/(N m)) per unit of the load vector.
    """

    frequencies_hz: np.ndarray
    points: tuple[str, ...]
    receptance: np.ndarray

    @property
    def mobility(self) -> np.ndarray:
        """Velocity per load, iΩ H."""
        return 2j * np.pi * self.frequencies_hz[:, None, None] * self.receptance

    @property
    def accelerance(self) -> np.ndarray:
        """Acceleration per load, −Ω² H."""
        return -(2 * np.pi * self.frequencies_hz[:, None, None]) ** 2 * self.receptance

    def to_dict(self) -> dict:
        """Plain JSON-ready dictionary: point -> real and imaginary parts (n_f, 6)."""
        return {"frequencies_hz": self.frequencies_hz.tolist(), "points": list(self.points),
                "receptance": {p: {"real": self.receptance[:, i].real.tolist(),
                                   "imag": self.receptance[:, i].imag.tolist()}
                               for i, p in enumerate(self.points)}}


# --- the solution ---------------------------------------------------------------

def modal_damping(omega, damping) -> np.ndarray:
    """(n,) c_k = α + β ω_k², 1/s, for ``damping`` = (α, β) or None (undamped)."""
    alpha, beta = damping if damping is not None else (0.0, 0.0)
    return alpha + beta * np.asarray(omega) ** 2


def participation(modes: ModalResult, point: str, vector) -> np.ndarray:
    """(n,) ⟨f, V^k⟩ / M_k for the (6,) load ``vector`` [force, moment] at ``point``."""
    return modes.point_displacements[point] @ np.asarray(vector, dtype=float) / modes.modal_mass


def unit_response(omega, damping_rate, function: TimeFunction, times):
    """Exact response of q̈ + c q̇ + ω² q = g(t) from rest, for each mode.

    omega, damping_rate : (n,) rad/s and 1/s. times : (n_t,) s.
    Returns (q, q̇, q̈), each (n_t, n).
    """
    omega, rate = np.asarray(omega, float), np.asarray(damping_rate, float)
    times = np.asarray(times, dtype=float)
    generators = _generators(omega, rate, function.nu)  # (E, n, 4, 4)
    states = np.zeros((function.starts.size, omega.size, 4))
    state = np.zeros((omega.size, 4))
    for j, start in enumerate(function.starts):
        if j:
            carry = scipy.linalg.expm(generators[j - 1] * (start - function.starts[j - 1]))
            state = np.einsum("nij,nj->ni", carry, state)
        state[:, 1] += function.kicks[j]
        state[:, 2], state[:, 3] = function.values[j], function.slopes[j]
        states[j] = state
    segment = np.searchsorted(function.starts, times, side="right") - 1
    active = segment >= 0
    out = np.zeros((times.size, omega.size, 4))
    tau = (times[active] - function.starts[segment[active]])[:, None, None, None]
    carry = scipy.linalg.expm(generators[segment[active]] * tau)
    out[active] = np.einsum("tnij,tnj->tni", carry, states[segment[active]])
    q, velocity, load = out[..., 0], out[..., 1], out[..., 2]
    return q, velocity, load - rate * velocity - omega**2 * q


def _generators(omega, rate, nu) -> np.ndarray:
    """(E, n, 4, 4) G of y' = G y, y = (q, q̇, g, g'), per segment and mode."""
    G = np.zeros((nu.size, omega.size, 4, 4))
    G[:, :, 0, 1] = 1.0
    G[:, :, 1, 0] = -omega**2
    G[:, :, 1, 1] = -rate
    G[:, :, 1, 2] = 1.0
    G[:, :, 2, 3] = 1.0
    G[:, :, 3, 2] = -nu[:, None]
    return G


def modal_response(modes: ModalResult, loads, times, points=None, damping=None) -> ResponseResult:
    """Response of the points to ``loads`` (PointLoad) at ``times`` (s) by modal superposition.

    points : names (default: every point of the modes). damping : (α, β) or None.
    """
    times = np.asarray(times, dtype=float)
    points = tuple(modes.point_displacements) if points is None else tuple(points)
    rate = modal_damping(modes.omega, damping)
    histories = np.zeros((3, times.size, modes.omega.size))
    for load in loads:
        response = unit_response(modes.omega, rate, load.time, times)
        histories += participation(modes, load.point, load.vector) * np.stack(response)
    shapes = np.stack([modes.point_displacements[p] for p in points], axis=1)  # (n, p, 6)
    physical = np.einsum("htk,kpc->htpc", histories, shapes)
    return ResponseResult(times, points, *physical, histories[0])


def frf(modes: ModalResult, point: str, vector, frequencies_hz, points=None,
        damping=None) -> FRFResult:
    """Receptance between the (6,) load ``vector`` [force, moment] at ``point`` and ``points``.

    frequencies_hz : (n_f,) Hz. damping : (α, β) or None (undamped: infinite
    at the natural frequencies).
    """
    frequencies_hz = np.asarray(frequencies_hz, dtype=float)
    points = tuple(modes.point_displacements) if points is None else tuple(points)
    Omega = 2 * np.pi * frequencies_hz[:, None]
    rate = modal_damping(modes.omega, damping)
    modal = participation(modes, point, vector) / (modes.omega**2 - Omega**2 + 1j * Omega * rate)
    shapes = np.stack([modes.point_displacements[p] for p in points], axis=1)
    return FRFResult(frequencies_hz, points, np.einsum("fk,kpc->fpc", modal, shapes))


def respond(model: Model, case: LoadCase) -> ResponseResult:
    """The response of ``model`` to a load case, with the model's damping."""
    modes = mode_shapes(model, case.modes)
    return modal_response(modes, case.loads, case.times, case.points, model.damping)


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

    Raises :class:`linmstmm.model.ModelError`.
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
