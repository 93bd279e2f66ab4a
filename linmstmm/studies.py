"""Studies built on the solvers: the receptance sweep, response peaks, the determinant scan.

* :func:`frf_study` — the receptance of a unit load at one point along one
  direction, over an equally spaced sweep, with a JSON-ready summary of what
  went in (route, modes, damping, units); :func:`frf_text` prints it. A
  model with spring dashpots takes the direct route
  (:func:`linmstmm.forced.direct_frf`), every other one the modal sum.
* :func:`peak_responses` — the largest |value| of every component of a
  :class:`~linmstmm.response.ResponseResult` and when; :func:`peaks_text`.
* :func:`determinant_scan` — log|det Ū_all| over a frequency grid and the
  natural frequencies found there (:class:`ScanResult`).

Errors name the parameter at fault (``point``, ``response_points``,
``direction``, ``fmax``, ``modes``, ``damping_ratio``) in a
:class:`~linmstmm.model.ModelError`; damping
ratios that do not fit the modes raise
:class:`~linmstmm.response.DampingRatioError`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from linmstmm.forced import direct_frf, has_dashpots
from linmstmm.mode_bound import check_range_request
from linmstmm.model import COMPONENTS, Model, ModelError
from linmstmm.model_file import _did_you_mean
from linmstmm.modes import ModalResult, mode_shapes
from linmstmm.response import (
    RESONANCE_RTOL,
    FRFResult,
    ResponseResult,
    frf,
    modal_damping,
    quantity_units,
    undamped_resonances,
)
from linmstmm.results import Result, decode_array, encode_array
from linmstmm.solve import natural_frequencies
from linmstmm.stages import report
from linmstmm.wording import counted

#: Frequencies in a scan and in a receptance sweep, by default.
DEFAULT_SCAN_POINTS = 2000
DEFAULT_FRF_FREQUENCIES = 2000
#: Without ``modes``, the FRF modal sum takes every mode up to this factor × fmax.
FRF_MODE_REACH = 2.0
#: Frequencies per chunk of the determinant scan (bounds the memory of Ū_all stacks).
SCAN_CHUNK = 256


# --- receptance ---------------------------------------------------------------------

def frf_study(model: Model, point: str, direction: str, fmax: float, *,
              frequencies: int = DEFAULT_FRF_FREQUENCIES, response_points=None,
              modes: int | None = None, damping_ratio=None) -> tuple[FRFResult, dict]:
    """Receptance to a unit load at ``point`` along ``direction``, with its summary.

    A model without spring dashpots takes the modal route (the modal sum,
    :func:`linmstmm.response.frf`); a model with a spring dashpot ``c`` takes
    the direct route (:func:`linmstmm.forced.direct_frf`: the transfer
    equations solved at each frequency in complex arithmetic, dashpots and
    the model's Rayleigh damping exact, no modes), which neither ``modes``
    nor ``damping_ratio`` fits.

    Parameters
    ----------
    model : Model
        The model.
    point : str
        The load point.
    direction : str
        One of COMPONENTS: a unit force along x, y, z (N) or a unit moment about them (N m).
    fmax : float
        Top of the sweep, Hz; the sweep has ``frequencies`` equal steps from fmax / frequencies.
    frequencies : int
        Excitation frequencies in the sweep.
    response_points : sequence of str, optional
        Response points (default: the load point).
    modes : int, optional
        Elastic modes in the sum (default: every mode up to FRF_MODE_REACH × fmax);
        modal route only.
    damping_ratio : sequence of float, optional
        Modal damping ratios (one, or one per elastic mode in the sum); given,
        they replace the model's damping; without them the model's Rayleigh
        damping is used (undamped without it). Modal route only.

    Returns
    -------
    result : FRFResult
        The receptance on the sweep (``excitation_hz``).
    summary : dict
        JSON-ready: ``model``, ``load`` {point, direction}, ``fmax_hz``, the damping
        used (:func:`damping_in_use`), ``route`` ("modal" or "direct"),
        ``modes_in_sum`` (0 on the direct route), ``static_correction`` (the
        modal sum's residual flexibility added: a held model on the modal
        route, :func:`linmstmm.response.frf`), ``rigid_body_modes``,
        ``frequencies_hz`` (modal route: the elastic natural frequencies in the
        sum; direct route: the undamped model's elastic natural frequencies up
        to fmax; Hz), ``load_unit`` and ``receptance_units`` (per component);
        where the undamped modal sum is unbounded at frequencies of the sweep
        (at an undamped natural frequency), they are left out of the result,
        listed in ``unbounded_hz`` (Hz) and named in ``note``.

    Raises
    ------
    ModelError
        For an unknown point (key ``point`` or ``response_points``) or
        direction (key ``direction``), a range holding too many modes or none
        (key ``fmax``), or ``modes`` or ``damping_ratio`` given for a model
        with dashpots (key ``modes`` or ``damping_ratio``).
    DampingRatioError
        For damping ratios that do not fit the modes.
    """
    direct = has_dashpots(model)
    if direct:
        _refuse_modal_options(model, modes, damping_ratio)
    targets = [point] if response_points is None else list(response_points)
    _check_points(model, "point", [point])
    _check_points(model, "response_points", targets)
    if direction not in COMPONENTS:
        raise ModelError(model.source or model.name, f"direction must be one of {', '.join(COMPONENTS)}, "
                         f"got {direction!r}", key="direction")
    sweep = fmax * np.arange(1, frequencies + 1) / frequencies
    damping = damping_in_use(model, damping_ratio)
    unit = np.eye(6)[COMPONENTS.index(direction)]
    unbounded = []
    if direct:
        result, in_sum, rigid, natural = _direct_sweep(model, point, unit, sweep, targets, fmax)
    else:
        result, in_sum, rigid, natural, unbounded = _modal_sweep(model, point, unit, sweep, targets, fmax, modes,
                                                                 damping_ratio, damping)
    load_unit = "N m" if direction.startswith("r") else "N"
    summary = {"model": model.name, "load": {"point": point, "direction": direction}, "fmax_hz": fmax,
               **damping, "route": "direct" if direct else "modal", "modes_in_sum": in_sum,
               "static_correction": not direct and rigid == 0,
               "rigid_body_modes": rigid, "frequencies_hz": natural,
               "load_unit": load_unit, "receptance_units": receptance_units(load_unit),
               **({"unbounded_hz": unbounded, "note": _unbounded_note(unbounded)} if unbounded else {})}
    return result, summary


def _unbounded_note(unbounded: list) -> str:
    """The note of a sweep that left out the excitation frequencies ``unbounded`` (Hz)."""
    return f"the sweep leaves out {_unbounded(unbounded)}; give damping for a finite peak"


def _unbounded(hz) -> str:
    """Why the excitation frequencies ``hz`` (Hz) are left out."""
    return (f"{', '.join(f'{f:.10g}' for f in hz)} Hz: at an undamped natural frequency (to 1 part in "
            f"{1 / RESONANCE_RTOL:.0e}) the receptance is unbounded")


def _modal_sweep(model: Model, point: str, unit, sweep, targets, fmax: float, modes, damping_ratio,
                 damping: dict):
    """(FRFResult, elastic modes in the sum, rigid-body modes, the elastic natural frequencies
    in the sum, Hz, and the frequencies of ``sweep`` left out, Hz) of the modal sum: those at
    an undamped mode's natural frequency (:func:`~linmstmm.response.undamped_resonances`)."""
    reach = None if modes else FRF_MODE_REACH * fmax
    if reach:
        check_range_request(model, reach, f"fmax = {fmax:g} Hz (the modal sum takes every mode "
                            f"up to {FRF_MODE_REACH:g} x fmax)", "ask for a lower fmax, or for N modes")
    from linmstmm.fe.flexibility import static_displacements  # the command line starts without the FE route

    shapes = mode_shapes(model, modes, fmax=reach)
    report("receptance")
    static = (static_displacements(model, [(point, unit)], targets)[0] if shapes.rigid_body_modes == 0
              else None)  # a free model's K⁺f depends on the mesh (see respond)
    rates = modal_damping(shapes.omega, damping["damping"], damping_ratio)
    unbounded = undamped_resonances(shapes.omega, rates, sweep)
    if unbounded.all():
        raise ModelError(model.source or model.name, f"every frequency of the sweep is left out, "
                         f"{_unbounded(sweep)}: give damping, or another fmax or number of frequencies",
                         key="fmax")
    result = frf(shapes, point, unit, sweep[~unbounded], targets, damping["damping"], damping_ratio=damping_ratio,
                 static=static)
    return (result, int(np.count_nonzero(shapes.omega > 0)), shapes.rigid_body_modes, _elastic_hz(shapes),
            sweep[unbounded].tolist())


def _direct_sweep(model: Model, point: str, unit, sweep, targets, fmax: float):
    """(FRFResult, 0, rigid-body modes, the undamped elastic natural frequencies up to fmax, Hz)
    of the direct route, the model's Rayleigh damping added."""
    natural = natural_frequencies(model, count=None, fmax=fmax)
    report("receptance")
    result = direct_frf(model, point, unit, sweep, targets, damping=model.damping)
    return result, 0, natural.rigid_body_modes, natural.frequencies_hz.tolist()


#: What each modal-route parameter is, for the direct route's refusal.
_MODAL_PARAMETERS = {"modes": "a number of modes in the sum", "damping_ratio": "modal damping ratios"}


def _refuse_modal_options(model: Model, modes, damping_ratio) -> None:
    """ModelError (key ``modes`` or ``damping_ratio``) for either given to a model whose
    dashpots take the direct route."""
    for key, value in (("modes", modes), ("damping_ratio", damping_ratio)):
        if value is not None:
            raise ModelError(model.source or model.name,
                             f"the model's spring dashpots 'c' take the direct route, which sums no modes: "
                             f"{_MODAL_PARAMETERS[key]} belong to the modal route; give [damping] for "
                             f"more damping", key=key)


def _elastic_hz(shapes: ModalResult) -> list[float]:
    """The elastic natural frequencies of ``shapes``, Hz, as a list."""
    return shapes.frequencies_hz[shapes.rigid_body_modes:].tolist()


def receptance_units(load_unit: str) -> list[str]:
    """The units of a receptance's six components.

    Parameters
    ----------
    load_unit : str
        "N" (a unit force) or "N m" (a unit moment).

    Returns
    -------
    list of str
        Six units, of x, y, z, rx, ry, rz, e.g. ``["m/N", ..., "rad/N"]``.
    """
    per = load_unit if load_unit == "N" else f"({load_unit})"
    return [f"m/{per}"] * 3 + [f"rad/{per}"] * 3


def _check_points(model: Model, key: str, names) -> None:
    for name in names:
        if name not in model.points:
            raise ModelError(model.source or model.name,
                             f"unknown point {name!r}{_did_you_mean(name, model.points)}", key=key)


def damping_in_use(model: Model, damping_ratio) -> dict:
    """The damping a run uses: modal ratios when given, else the model's Rayleigh damping.

    Parameters
    ----------
    model : Model
        The model (its ``damping``: Rayleigh α, β or None).
    damping_ratio : sequence of float or None
        Modal damping ratios given for the run.

    Returns
    -------
    dict
        ``{"damping": (α, β) or None, "damping_ratio": list or None}``.
    """
    return {"damping": model.damping if damping_ratio is None else None, "damping_ratio": damping_ratio}


def damping_text(damping: dict) -> str:
    """One phrase for the damping of :func:`damping_in_use`.

    Parameters
    ----------
    damping : dict
        As returned by :func:`damping_in_use`.

    Returns
    -------
    str
        E.g. "modal damping ratio 0.02", "Rayleigh damping alpha, beta = ...", "undamped".
    """
    if damping["damping_ratio"] is not None:
        ratios = damping["damping_ratio"]
        return f"modal damping ratio{'s' if len(ratios) > 1 else ''} {', '.join(f'{r:g}' for r in ratios)}"
    if damping["damping"] is not None:
        return "Rayleigh damping alpha, beta = {:g} 1/s, {:g} s".format(*damping["damping"])
    return "undamped"


def frf_text(result: FRFResult, summary: dict) -> str:
    """The summary of :func:`frf_study` and the largest |H| of every significant component.

    Parameters
    ----------
    result : FRFResult
        The receptance.
    summary : dict
        Its summary from :func:`frf_study`.

    Returns
    -------
    str
        Lines of text (no trailing newline).
    """
    from linmstmm.plot import significant_components

    load = summary["load"]
    direct = summary.get("route") == "direct"
    damping = damping_text(summary)
    if damping == "undamped":
        damping = "no Rayleigh damping" if direct else "undamped (unbounded at the natural frequencies)"
    route = ("direct transfer-matrix solve, spring dashpots acting" if direct
             else f"{counted(summary['modes_in_sum'], 'elastic mode')} in the sum")
    natural = ", ".join(f"{f:.6g}" for f in summary["frequencies_hz"]) or "none"
    lines = [(f"{summary['model']}: receptance to a unit load {load['direction']} at {load['point']} "
              f"[per {summary['load_unit']}], 0-{summary['fmax_hz']:g} Hz, {route}, {damping}"),
             f"  natural frequencies{' (undamped)' if direct else ''} [Hz]: {natural}",
             f"  {'point':<20}{'component':>10}{'largest |H|':>14}{'unit':>12}{'at [Hz]':>12}"]
    magnitude = np.abs(result.receptance)
    for p, c in significant_components(result.receptance):
        peak = magnitude[:, p, c].argmax()
        lines.append(f"  {result.points[p]:<20}{COMPONENTS[c]:>10}{magnitude[peak, p, c]:>14.4g}"
                     f"{summary['receptance_units'][c]:>12}{result.excitation_hz[peak]:>12.5g}")
    if summary.get("note"):
        lines.append(f"  note: {summary['note']}")
    return "\n".join(lines)


# --- response peaks -----------------------------------------------------------------

def peak_responses(result: ResponseResult, quantity: str = "displacement") -> tuple[np.ndarray, np.ndarray]:
    """The largest |value| of every component of a response, and when it occurs.

    Parameters
    ----------
    result : ResponseResult
        The response histories.
    quantity : str
        "displacement", "velocity" or "acceleration".

    Returns
    -------
    peaks : numpy.ndarray, shape (n_points, 6)
        Largest |value| of each component (units of ``quantity``).
    times : numpy.ndarray, shape (n_points, 6)
        The times of those peaks, s.
    """
    values = np.abs(getattr(result, quantity))
    return values.max(axis=0), result.times[values.argmax(axis=0)]


def peaks_text(points, peaks, times, quantity: str = "displacement") -> str:
    """The peak table of :func:`peak_responses`: each column's SI unit in its header.

    Parameters
    ----------
    points : sequence of str
        The response points, in the order of ``peaks``.
    peaks, times : numpy.ndarray, shape (n_points, 6)
        As returned by :func:`peak_responses`.
    quantity : str
        "displacement", "velocity" or "acceleration".

    Returns
    -------
    str
        Lines of text (no trailing newline), the time of each peak (s) in brackets.
    """
    lines = [f"  peak |{quantity}| (at time [s]):",
             f"  {'point':<20}" + "".join(f"{f'{name} [{unit}]':>22}"
                                          for name, unit in zip(COMPONENTS, quantity_units(quantity)))]
    for point, row, at in zip(points, peaks, times):
        lines.append(f"  {point:<20}" + "".join(f"{value:>12.4g} ({t:6.3f})" for value, t in zip(row, at)))
    return "\n".join(lines)


# --- determinant scan ---------------------------------------------------------------

@dataclass(frozen=True, eq=False)
class ScanResult(Result):
    """log|det Ū_all| over a frequency grid, and the natural frequencies below its top.

    Attributes
    ----------
    model : str
        The model's name.
    omega : numpy.ndarray, shape (n,)
        The grid, rad/s.
    sign, log_abs : numpy.ndarray, shape (n,)
        Sign and natural logarithm of |det Ū_all| on the grid.
    roots : numpy.ndarray, shape (r,)
        Every elastic natural frequency up to the top of the grid, rad/s.
    ubar_order : int
        Order of Ū_all.
    rigid_body_modes : int
        Zero-frequency modes.
    note : str
        What the search must say ("" if nothing).
    """

    model: str
    omega: np.ndarray
    sign: np.ndarray
    log_abs: np.ndarray
    roots: np.ndarray
    ubar_order: int
    rigid_body_modes: int
    note: str = ""

    kind = "scan"

    @property
    def frequencies_hz(self) -> np.ndarray:
        """(r,) the elastic natural frequencies found, Hz."""
        return self.roots / (2 * np.pi)

    def count(self) -> np.ndarray:
        """Natural frequencies at or below each grid frequency, N(ω).

        Returns
        -------
        numpy.ndarray of int, shape (n,)
        """
        return np.searchsorted(self.roots, self.omega, side="right")

    def to_dict(self) -> dict:
        """The JSON-ready summary (the grid itself left out).

        Returns
        -------
        dict
            ``model``, ``fmax_hz``, ``points``, ``ubar_order``, ``rigid_body_modes``,
            ``frequencies_hz`` and, when set, ``note``.
        """
        return {"model": self.model, "fmax_hz": float(self.omega[-1] / (2 * np.pi)), "points": self.omega.size,
                "ubar_order": self.ubar_order, "rigid_body_modes": self.rigid_body_modes,
                "frequencies_hz": self.frequencies_hz.tolist(), **({"note": self.note} if self.note else {})}

    def _restoring_dict(self) -> dict:
        """The grid and the roots in rad/s, which :meth:`to_dict` leaves out."""
        return {"omega": encode_array(self.omega), "sign": encode_array(self.sign),
                "log_abs": encode_array(self.log_abs), "roots": encode_array(self.roots)}

    @classmethod
    def _from_data(cls, data: dict) -> ScanResult:
        """The result :meth:`~linmstmm.results.Result.to_record` describes."""
        return cls(data["model"], decode_array(data["omega"]), decode_array(data["sign"]),
                   decode_array(data["log_abs"]), decode_array(data["roots"]), data["ubar_order"],
                   data["rigid_body_modes"], data.get("note", ""))

    def plot(self):
        """Draw log₁₀|det Ū_all| over the grid, coloured by its sign, and the root count N(f) under it.

        Returns
        -------
        matplotlib.figure.Figure
            Two axes sharing the frequency (:func:`linmstmm.plot.scan_figure`), unsaved.
        """
        from linmstmm.plot import scan_figure

        return scan_figure(self.omega, self.sign, self.log_abs, self.roots, self.count(),
                           title=f"{self.model}: determinant scan")


def determinant_scan(model: Model, fmax: float, points: int = DEFAULT_SCAN_POINTS) -> ScanResult:
    """log|det Ū_all| at ``points`` equally spaced frequencies up to ``fmax``, and the roots there.

    Parameters
    ----------
    model : Model
        The model.
    fmax : float
        Top of the scan, Hz.
    points : int
        Frequencies in the scan: fmax / points, 2 fmax / points, ..., fmax.

    Returns
    -------
    ScanResult

    Raises
    ------
    ModelError
        If ``fmax`` holds too many modes to search for (key-less, naming fmax).
    """
    from linmstmm.solve import frequency_finder, search_note, search_up_to

    check_range_request(model, fmax)
    report("deducing Ubar_all")
    deduction, finder, _ = frequency_finder(model)
    omega_max = 2 * np.pi * fmax
    grid = omega_max * np.arange(1, points + 1) / points
    report("scanning det Ubar_all")
    parts = [deduction.log_det(grid[start:start + SCAN_CHUNK]) for start in range(0, grid.size, SCAN_CHUNK)]
    report("finding roots")
    search = search_up_to(finder, None, fmax)
    note = search_note(search, search.roots.size, search.unseparated, None, fmax)
    return ScanResult(model.name, grid, np.concatenate([p[0] for p in parts]),
                      np.concatenate([p[1] for p in parts]), search.roots, deduction.full_order,
                      search.rigid_body_modes, note)
