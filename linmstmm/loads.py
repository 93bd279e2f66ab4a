"""Loads: time functions g(t), point loads, load cases and the load file.

A time function is a sequence of segments; on segment j (from ``start_j``
to the next start) g obeys g'' = −ν_j g, i.e. it is linear (ν = 0) or
sinusoidal (ν = Ω²), from given g and g' at its start; a segment may also
open with a Dirac impulse. Step, impulse, harmonic and half-sine loads are
one or two segments; tabulated samples are linear between samples.

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
    step = 1e-3                      # s, default duration / 1000; at most duration, and
                                     # at most MAX_RESPONSE_VALUES values in the response
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

from linmstmm.model import Model
from linmstmm.model_file import _did_you_mean, _read_toml, _Table

#: Default [output] values of a load file.
DEFAULT_DURATION = 1.0
DEFAULT_STEPS = 1000
DEFAULT_MODES = 20
#: The most values a response may hold: its output times × (18 per response
#: point: displacement, velocity, acceleration × 6 components, and 3 per mode
#: in the sum), 80 MB in float64; a load file asking for more is refused.
MAX_RESPONSE_VALUES = 10_000_000


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
    times = _output_times(output, duration, dt, len(points) if names is None else len(names), modes)
    return LoadCase(loads, times, names, modes)


def _output_times(output: _Table, duration: float, dt: float, n_points: int, modes: int) -> np.ndarray:
    """(n_t,) s: 0, dt, 2 dt, ... up to ``duration``, after checking that ``dt`` fits in
    ``duration`` and that the response of ``n_points`` points and ``modes`` elastic modes
    at those times holds no more than MAX_RESPONSE_VALUES values (ModelError on key ``step``)."""
    if dt > duration:
        raise output.error("step", f"{dt:g} s is longer than the duration {duration:g} s: "
                                   f"the response would have the single time 0")
    count = np.floor(duration / dt + 1e-9) + 1  # float: a huge count is not built
    values = count * (18 * n_points + 3 * modes)
    if values > MAX_RESPONSE_VALUES:
        raise output.error("step", f"{count:,.0f} output times ({duration:g} s in steps of {dt:g} s) for "
                                   f"{n_points} points and {modes} modes make {values:.3g} values, more than "
                                   f"the {MAX_RESPONSE_VALUES:,} a response may hold: give a longer step, a "
                                   f"shorter duration or fewer points")
    return np.arange(int(count)) * dt


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
