"""Modal response to point loads, and frequency response functions (docs/method.md).

With the augmented eigenvectors V^k of :mod:`linmstmm.modes` and proportional
damping C = αM + βK (the model's ``[damping]``) or modal damping ratios ζ_k,
each modal coordinate obeys

    q̈_k + c_k q̇_k + ω_k² q_k = p_k(t),   c_k = α + β ω_k²  or  2 ζ_k ω_k,
    p_k(t) = Σ_loads (F · u^k(P) + T · θ^k(P)) g(t) / M_k,

for a force F and moment T at point P with time function g(t): a force at a
point works on the mode's displacement there. The displacement of any point
is x(t) = Σ_k φ^k q_k(t) (velocity and acceleration alike).

Every mode is solved exactly, not by a step-by-step ODE scheme
(:mod:`linmstmm.duhamel`); the loads, their time functions and the load
file are :mod:`linmstmm.loads`.

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

A spring's dashpot ``c`` couples the modes: its damping in modal coordinates
(:func:`linmstmm.modal_dashpots.modal_dashpots`) joins the modal equations,
which are then solved together, still exactly
(:func:`linmstmm.modal_dashpots.coupled_unit_response`). The FRF of such a
model is solved directly (:func:`linmstmm.forced.direct_frf`).
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from linmstmm.duhamel import unit_response
from linmstmm.loads import (
    LoadCase,
    PointLoad,
    TimeFunction,
    half_sine,
    harmonic,
    impulse,
    load_loads,
    step,
    table,
)
from linmstmm.modal_dashpots import coupled_unit_response, modal_dashpots
from linmstmm.model import Model
from linmstmm.modes import ModalResult, mode_shapes
from linmstmm.results import Result, decode_array, decode_arrays, encode_array
from linmstmm.roots import CERTIFIED_STEP

#: The public names, with those of the loads and the exact modal solution
#: (:mod:`linmstmm.loads`, :mod:`linmstmm.duhamel`) this module has always offered.
__all__ = ["DampingRatioError", "FRFResult", "LoadCase", "PointLoad", "QUANTITY_UNITS", "ResonanceError",
           "ResponseResult", "TimeFunction", "frf", "half_sine", "harmonic", "impulse", "load_loads",
           "modal_damping", "modal_response", "participation", "quantity_units", "respond",
           "step", "table", "undamped_resonances", "unit_response"]


@dataclass(frozen=True, eq=False)
class ResponseResult(Result):
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

    kind = "response"

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

    def _restoring_dict(self) -> dict:
        """The modal coordinates :meth:`to_dict` leaves out."""
        return {"modal": encode_array(self.modal)}

    @classmethod
    def _from_data(cls, data: dict) -> ResponseResult:
        """The result :meth:`~linmstmm.results.Result.to_record` describes."""
        points, times = tuple(data["points"]), decode_array(data["times"])

        def histories(name):  # point -> (n_t, 6) back to (n_t, n_points, 6)
            by_point = decode_arrays(data[name], ndim=2)
            return np.stack([by_point[p] for p in points], axis=1) if points else np.empty((times.size, 0, 6))

        return cls(times, points, histories("displacement"), histories("velocity"), histories("acceleration"),
                   decode_array(data["modal"], ndim=2), data["elastic_modes"], data["static_correction"],
                   data.get("note", ""), decode_array(data["frequencies_hz"]), data["rigid_body_modes"])

    def plot(self, quantity: str = "displacement", title: str = ""):
        """The histories at every point (:func:`linmstmm.plot.response_figure`): a row per
        point, translations on the left, rotations on the right.

        Parameters
        ----------
        quantity : str
            "displacement", "velocity" or "acceleration".
        title : str
            The figure's title (default: "modal response, " and the quantity).

        Returns
        -------
        matplotlib.figure.Figure
            Not saved; matplotlib is imported on this call.
        """
        from linmstmm.plot import response_figure

        return response_figure(self, quantity, title)


#: SI units of each response quantity: (translations, rotations).
QUANTITY_UNITS = {"displacement": ("m", "rad"), "velocity": ("m/s", "rad/s"),
                  "acceleration": ("m/s^2", "rad/s^2")}


def quantity_units(quantity: str) -> list[str]:
    """The six component units (x, y, z, rx, ry, rz) of ``quantity``, e.g. "velocity"."""
    translation, rotation = QUANTITY_UNITS[quantity]
    return [translation] * 3 + [rotation] * 3


@dataclass(frozen=True, eq=False)
class FRFResult(Result):
    """Receptance between one load direction and the points.

    excitation_hz : (n_f,) excitation frequencies, Hz. points : names. receptance : (n_f, n_points, 6)
    complex, m/N (or rad/N, m/(N m), rad/(N m)) per unit of the load vector.
    """

    excitation_hz: np.ndarray
    points: tuple[str, ...]
    receptance: np.ndarray

    kind = "frf"

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

    @classmethod
    def _from_data(cls, data: dict) -> FRFResult:
        """The result :meth:`to_dict` describes (which holds all of it)."""
        points, excitation = tuple(data["points"]), decode_array(data["excitation_hz"])
        by_point = decode_arrays(data["receptance"], ndim=2)
        receptance = (np.stack([by_point[p] for p in points], axis=1) if points
                      else np.empty((excitation.size, 0, 6), dtype=complex))
        return cls(excitation, points, receptance)

    def plot(self, natural_hz=(), load_unit: str = "N", title: str = ""):
        """Magnitude and phase of the receptance (:func:`linmstmm.plot.frf_figure`):
        translations and rotations on separate magnitude axes, the phases below.

        Parameters
        ----------
        natural_hz : sequence of float
            Natural frequencies to mark, Hz.
        load_unit : str
            Unit of the load, "N" (a force) or "N m" (a moment).
        title : str
            The figure's title (default: "frequency response (receptance)").

        Returns
        -------
        matplotlib.figure.Figure
            Not saved; matplotlib is imported on this call.
        """
        from linmstmm.plot import frf_figure

        return frf_figure(self, natural_hz, load_unit, title)


class DampingRatioError(ValueError):
    """Modal damping ratios that do not fit the modes (count, sign) or come with Rayleigh damping."""


class ResonanceError(ValueError):
    """An excitation frequency at an undamped natural frequency, where the receptance is unbounded."""


#: An excitation within this relative distance of an undamped natural frequency is
#: at it: the accuracy natural frequencies are certified to, closer than which the
#: receptance's size and sign are not known.
RESONANCE_RTOL = CERTIFIED_STEP


def undamped_resonances(omega, rates, excitation_hz) -> np.ndarray:
    """Which excitation frequencies are at a natural frequency of an undamped mode.

    Parameters
    ----------
    omega : array_like, shape (n,)
        ω_k, rad/s (rigid-body modes at 0).
    rates : array_like, shape (n,)
        Modal damping rates c_k, 1/s (:func:`modal_damping`); an undamped mode has 0.
    excitation_hz : array_like, shape (n_f,)
        Excitation frequencies, Hz.

    Returns
    -------
    numpy.ndarray, shape (n_f,), bool
        True where |Ω − ω_k| <= RESONANCE_RTOL ω_k for an undamped mode k
        (Ω = 0 for a rigid-body mode).
    """
    omega = np.asarray(omega, dtype=float)
    undamped = omega[np.asarray(rates) == 0]
    excitation = 2 * np.pi * np.asarray(excitation_hz, dtype=float)
    return np.any(np.abs(excitation[:, None] - undamped) <= RESONANCE_RTOL * undamped, axis=1)


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


def modal_response(modes: ModalResult, loads, times, points=None, damping=None, *,
                   damping_ratio=None, static=None, dashpots=None) -> ResponseResult:
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
    dashpots : (n, n) the springs' dashpots in the modal coordinates, M⁻¹C,
        1/s (:func:`~linmstmm.modal_dashpots.modal_dashpots`), or None. Given,
        the modal equations they couple are solved together
        (:func:`~linmstmm.modal_dashpots.coupled_unit_response`).

    Returns
    -------
    :class:`ResponseResult`.
    """
    times = np.asarray(times, dtype=float)
    points = tuple(modes.point_displacements) if points is None else tuple(points)
    rate = modal_damping(modes.omega, damping, damping_ratio)
    histories = np.zeros((3, times.size, modes.omega.size))
    for load in loads:
        p = participation(modes, load.point, load.vector)
        if dashpots is None:
            histories += p * np.stack(unit_response(modes.omega, rate, load.time, times))
        else:
            histories += np.stack(coupled_unit_response(modes.omega, rate, dashpots, p, load.time, times))
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
        damping=None, *, damping_ratio=None, static=None) -> FRFResult:
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
    static : array_like, shape (n_points, 6), optional
        K⁺f of the load ``vector`` at the response points (m, rad;
        :func:`linmstmm.fe.static_displacements`). Given, the residual
        flexibility of the modes left out of the sum, K⁺f − Σ φ_k p_k / ω_k²,
        is added at every frequency: the modes above respond to a load below
        them quasi-statically, so the receptance is exact at Ω = 0 and errs by
        about (Ω/ω)² of the first mode left out above (and a massless point's
        flexibility, which no mode holds, is exact). Without it those modes are
        missing altogether (a cantilever's axial receptance below its first
        axial mode is then almost zero).

    Returns
    -------
    FRFResult

    Raises
    ------
    ResonanceError
        For an excitation frequency at the natural frequency of an undamped
        mode (:func:`undamped_resonances`), where the receptance is unbounded.
    DampingRatioError
        For damping ratios that do not fit the modes.
    """
    excitation_hz = np.asarray(excitation_hz, dtype=float)
    points = tuple(modes.point_displacements) if points is None else tuple(points)
    Omega = 2 * np.pi * excitation_hz[:, None]
    rate = modal_damping(modes.omega, damping, damping_ratio)
    resonant = excitation_hz[undamped_resonances(modes.omega, rate, excitation_hz)]
    if resonant.size:
        raise ResonanceError(f"the undamped receptance is unbounded at {', '.join(f'{f:.10g}' for f in resonant)} "
                             f"Hz, a natural frequency: leave it out of excitation_hz, or give damping")
    loading = participation(modes, point, vector)
    modal = loading / (modes.omega**2 - Omega**2 + 1j * Omega * rate)
    shapes = np.stack([modes.point_displacements[p] for p in points], axis=1)
    receptance = np.einsum("fk,kpc->fpc", modal, shapes)
    if static is not None:
        elastic = modes.omega > 0
        modal_static = np.einsum("k,kpc->pc", loading[elastic] / modes.omega[elastic] ** 2, shapes[elastic])
        receptance += np.asarray(static, dtype=float) - modal_static
    return FRFResult(excitation_hz, points, receptance)


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
    DampingRatioError
        For damping ratios that do not fit the modes.
    DefectiveDampingError
        Where the springs' dashpots make two damped modes coincide
        (:func:`~linmstmm.modal_dashpots.coupled_unit_response`).
    """
    from linmstmm.fe.flexibility import static_displacements

    modes = mode_shapes(model, case.modes)
    points = tuple(modes.point_displacements) if case.points is None else case.points
    held = modes.rigid_body_modes == 0
    static = (static_displacements(model, [(load.point, load.vector) for load in case.loads], points)
              if static_correction and held else None)
    damping = model.damping if damping_ratio is None else None
    result = modal_response(modes, case.loads, case.times, points, damping, damping_ratio=damping_ratio,
                            static=static,
                            dashpots=modal_dashpots(model, modes.point_displacements, modes.modal_mass))
    if static_correction and not held:
        return replace(result, note=f"no static correction: the model has {modes.rigid_body_modes} "
                                    f"rigid-body modes (free-floating, or a joint's mechanism); the "
                                    f"modal sum alone")
    return result
