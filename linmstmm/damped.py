"""Damped natural frequencies: the complex roots of det Ū_all with dashpots acting.

A free motion ``e^{st}`` of a model with spring dashpots (and Rayleigh
damping) has s = −ζω_n ± iω_n√(1 − ζ²). In terms of the complex frequency
ω = −is = ω_n√(1 − ζ²) + iζω_n the element matrices are those of the direct
route (:mod:`linmstmm.forced`: springs k + iωc, Rayleigh damping as the
complex frequency ω̃² = (ω² − iαω)/(1 + iωβ)), and the roots are the zeros
of the entire function det Ū_all(ω) in the upper half plane (its zeros come
in pairs ω, −ω̄; the first is kept).

Each is found by the secant method started from an undamped natural
frequency (on det^{1/m} for an m-fold root, which converges as fast as on a
simple one), its multiplicity counted on a small circle around it, and the
whole set certified by one argument-principle count
(:func:`linmstmm.counting.count_inside`) over an ellipse in the upper half
plane that spans the undamped frequencies used, with the roots found divided
out: no other root may lie inside.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from linmstmm.counting import count_inside
from linmstmm.eigenspaces import SAME_FREQUENCY, _group
from linmstmm.forced import rayleigh_equivalent, refuse_released_dashpots, released_deduction
from linmstmm.model import Model
from linmstmm.results import Result, decode_array
from linmstmm.solve import natural_frequencies
from linmstmm.threads import single_blas_thread
from linmstmm.topology import build_topology

#: The secant stops when its step is below this fraction of |ω|.
STEP_TOLERANCE = 1e-14
#: ... or after this many steps.
MAX_STEPS = 80
#: The second starting point of the secant is ω_k (1 + i START_DAMPING).
START_DAMPING = 1e-2
#: Radius of the circle the multiplicity is counted on, relative to |ω|.
MULTIPLICITY_RADIUS = 1e-4
#: The certifying ellipse spans from this fraction of the lowest undamped
#: frequency used to half-way to the next undamped frequency, and reaches this
#: many times its half-width into the upper half plane (damping ratios up to
#: about 0.8 at its centre).
LOWEST_FRACTION = 0.5
HEIGHT = 1.5


@dataclass(frozen=True)
class DampedResult(Result):
    """Damped natural frequencies, ascending in damped frequency.

    Attributes
    ----------
    model : str
        The model's name.
    roots : numpy.ndarray, shape (n,), complex
        s = −ζω_n + iω_d, 1/s, one per root and multiplicity.
    undamped_frequencies_hz : numpy.ndarray, shape (n_u,)
        The undamped natural frequencies the search started from, Hz.
    rigid_body_modes : int
        Zero-frequency modes (not in the lists).
    seconds : float
        Wall time of the whole solve, s.

    The properties ``damped_frequencies_hz`` (ω_d / 2π), ``damping_ratio``
    (ζ) and ``frequencies_hz`` (ω_n / 2π = |s| / 2π) derive from ``roots``.
    """

    model: str
    roots: np.ndarray
    undamped_frequencies_hz: np.ndarray
    rigid_body_modes: int
    seconds: float

    kind = "damped"

    @property
    def damped_frequencies_hz(self) -> np.ndarray:
        """(n,) ω_d / 2π = Im s / 2π, Hz."""
        return self.roots.imag / (2 * np.pi)

    @property
    def frequencies_hz(self) -> np.ndarray:
        """(n,) ω_n / 2π = |s| / 2π, Hz (the undamped ones where there is no damping)."""
        return np.abs(self.roots) / (2 * np.pi)

    @property
    def damping_ratio(self) -> np.ndarray:
        """(n,) ζ = −Re s / |s|."""
        return -self.roots.real / np.abs(self.roots)

    def to_dict(self) -> dict:
        """The ``linmstmm freqs --damped --json`` object (``docs/cli.md``).

        Returns
        -------
        dict
            JSON-ready: ``model``, ``damped_frequencies_hz``, ``damping_ratio``,
            ``frequencies_hz`` (|s| / 2π), ``roots`` ([re, im] of s, 1/s),
            ``undamped_frequencies_hz``, ``rigid_body_modes``, ``seconds``, ``method``.
        """
        return {"model": self.model, "damped_frequencies_hz": self.damped_frequencies_hz.tolist(),
                "damping_ratio": self.damping_ratio.tolist(), "frequencies_hz": self.frequencies_hz.tolist(),
                "roots": [[float(s.real), float(s.imag)] for s in self.roots],
                "undamped_frequencies_hz": self.undamped_frequencies_hz.tolist(),
                "rigid_body_modes": int(self.rigid_body_modes), "seconds": float(self.seconds),
                "method": "mstmm-damped"}

    @classmethod
    def _from_data(cls, data: dict) -> DampedResult:
        """The result :meth:`to_dict` describes (which holds all of it)."""
        pairs = decode_array(data["roots"], ndim=2).reshape(-1, 2)
        return cls(data["model"], pairs[:, 0] + 1j * pairs[:, 1], decode_array(data["undamped_frequencies_hz"]),
                   data["rigid_body_modes"], data["seconds"])

    def plot(self):
        """Draw ζ against the damped natural frequency, the undamped ones as dotted lines.

        Returns
        -------
        matplotlib.figure.Figure
            One axis (:func:`linmstmm.plot.damped_figure`), unsaved.
        """
        from linmstmm.plot import damped_figure

        return damped_figure(self.damped_frequencies_hz, self.damping_ratio, self.undamped_frequencies_hz,
                             title=f"{self.model}: damped natural frequencies")


def damped_log_det(model: Model, root: str | None = None):
    """(phase, log|det Ū_all|) of ``model`` with its dashpots and Rayleigh damping acting,
    as a callable of complex ω (n,) rad/s (the stable carry of :meth:`Deduction.log_det`)."""
    deduction = released_deduction(build_topology(model, root=root))

    def log_det(omega):
        carried, deduction.rate, _ = rayleigh_equivalent(omega, model.damping)
        return deduction.log_det(carried)

    return log_det


@single_blas_thread
def damped_frequencies(model: Model, count: int | None = 10, fmax: float | None = None,
                       root: str | None = None) -> DampedResult:
    """Damped natural frequencies and damping ratios of ``model`` (dashpots ``c``
    and the model's Rayleigh ``[damping]`` acting), from its lowest undamped ones.

    Parameters
    ----------
    model : Model
        The model.
    count : int or None
        The lowest ``count`` undamped frequencies to start from (as
        :func:`linmstmm.solve.natural_frequencies`; a repeated frequency comes
        with its whole eigenspace); one damped root comes from each.
    fmax : float or None
        Hz: start from every undamped frequency up to fmax (with ``count``:
        whichever stops first).
    root : str or None
        Boundary end to use as the root of the transfer tree.

    Returns
    -------
    DampedResult

    Raises
    ------
    ModelError
        For ``root`` that is no boundary end (key ``root``) or ``fmax`` alone
        that holds too many modes (as :func:`linmstmm.solve.natural_frequencies`).
    RuntimeError
        When a root cannot be found or the certifying count finds roots the
        search did not.
    """
    refuse_released_dashpots(model)
    started = time.perf_counter()
    asked = natural_frequencies(model, count=count, fmax=fmax, root=root)
    if not asked.frequencies_hz.size:
        return DampedResult(model.name, np.zeros(0, complex), asked.frequencies_hz, asked.rigid_body_modes,
                            time.perf_counter() - started)
    undamped = _beyond(model, asked.frequencies_hz, root)
    used = undamped[undamped <= asked.frequencies_hz[-1] * (1 + SAME_FREQUENCY)]
    log_det = damped_log_det(model, root)
    roots: list[complex] = []
    for omega, multiplicity in _group(2 * np.pi * used):
        roots += _roots_near(log_det, omega, multiplicity, roots)
    _certify(log_det, roots, 2 * np.pi * undamped, used.size)
    s = 1j * np.array(roots)
    return DampedResult(model.name, s[np.argsort(s.imag, kind="stable")], used, asked.rigid_body_modes,
                        time.perf_counter() - started)


def _beyond(model: Model, frequencies_hz, root) -> np.ndarray:
    """The undamped frequencies (Hz) from the lowest up to the first one above
    ``frequencies_hz[-1]`` (all of them if the model has no more)."""
    extra = 1
    while True:
        found = natural_frequencies(model, count=frequencies_hz.size + extra, root=root).frequencies_hz
        if found.size < frequencies_hz.size + extra or found[-1] > frequencies_hz[-1] * (1 + SAME_FREQUENCY):
            return found
        extra *= 2


def _log(log_det, omega: complex) -> complex:
    """log det at one complex ω: log|det| + i arg det."""
    phase, log_abs = log_det(np.array([omega]))
    return complex(log_abs[0] + 1j * np.angle(phase[0]))


def _deflated(log_det, known):
    """``log_det`` divided by ∏ (ω − r) over the ``known`` roots."""
    known = np.asarray(known, dtype=complex)

    def reduced(omega):
        phase, log_abs = log_det(omega)
        factors = np.asarray(omega, dtype=complex)[:, None] - known[None, :]
        return phase * np.exp(-1j * np.angle(factors).sum(axis=1)), log_abs - np.log(np.abs(factors)).sum(axis=1)

    return reduced


def _secant(log_det, start: complex, power: int) -> complex:
    """A zero of det^{1/power} by the secant method from ``start`` and ``start``(1 + i START_DAMPING)."""
    x0, x1 = start, start * (1 + 1j * START_DAMPING)
    l0, l1 = _log(log_det, x0), _log(log_det, x1)
    for _ in range(MAX_STEPS):
        change = l0 - l1
        change = change.real + 1j * np.angle(np.exp(1j * change.imag))
        with np.errstate(divide="ignore", invalid="ignore"):  # det equal at both points: no step, stop below
            step = (x1 - x0) / (1 - np.exp(change / power))
        if not np.isfinite(step):
            break
        x0, l0 = x1, l1
        x1 = x1 - step
        l1 = _log(log_det, x1)
        if abs(step) <= STEP_TOLERANCE * abs(x1):
            break
    return x1


def _roots_near(log_det, omega: float, multiplicity: int, known: list) -> list[complex]:
    """The ``multiplicity`` damped roots that come from the undamped ω (rad/s), each
    found with the roots already ``known`` divided out, and counted on a small circle."""
    found: list[complex] = []
    while len(found) < multiplicity:
        reduced = _deflated(log_det, known + found)
        remaining = multiplicity - len(found)
        root = _secant(reduced, omega, remaining)
        inside = count_inside(reduced, root, MULTIPLICITY_RADIUS * abs(root))
        if inside == 0 and remaining > 1:  # the damping split the eigenspace into simple roots
            root = _secant(reduced, omega, 1)  # (a dashpot along one of two equal bending planes)
            inside = count_inside(reduced, root, MULTIPLICITY_RADIUS * abs(root))
        if inside == 0:
            raise RuntimeError(f"no damped root found near the undamped {omega / (2 * np.pi):.6g} Hz")
        if inside < remaining:  # the damping splits the eigenspace: polish the part found
            root = _secant(reduced, root, inside)
        found += [root] * min(inside, remaining)
    return found


def _certify(log_det, roots, undamped, used: int) -> None:
    """RuntimeError unless the ellipse over the undamped frequencies used holds no
    root of det but ``roots`` (rad/s, complex)."""
    low = LOWEST_FRACTION * undamped[0]
    high = (undamped[used - 1] + undamped[used]) / 2 if undamped.size > used else 1.5 * undamped[used - 1]
    centre, half = (low + high) / 2, (high - low) / 2
    inside = [r for r in roots if ((r.real - centre) / half) ** 2 + (r.imag / (HEIGHT * half)) ** 2 < 1]
    others = count_inside(_deflated(log_det, inside), centre, half, HEIGHT * half)
    where = f"the ellipse over {low / (2 * np.pi):.6g} to {high / (2 * np.pi):.6g} Hz"
    if others:
        raise RuntimeError(f"{others} damped roots in {where} were not found from the undamped frequencies")
    if len(inside) != len(roots):
        raise RuntimeError(f"{len(roots) - len(inside)} damped roots found lie outside {where}, "
                           f"which cannot certify them")
