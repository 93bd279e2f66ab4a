"""Commands ``linmstmm modes``, ``scan``, ``response`` and ``frf``: figures and data out.

* ``modes MODEL [--count N] [--fmax HZ] [--json] [--plot DIR] [--animate]
  [--uff FILE] [--mac-fe] [--normalization mass|max]``: frequencies, modal
  masses and orthogonality errors of the modes (shapes mass-normalised by
  default, modal mass 1 kg; ``max``: largest translation 1 m, so the modal
  masses are comparable); one PNG per mode (and a GIF with
  ``--animate``) in DIR; the shapes as a universal file (:mod:`linmstmm.uff`);
  the MAC matrix against the finite-element route's modes.
* ``scan MODEL --fmax HZ [--points N] --plot FILE [--json]``: log|det Ū_all|
  over a frequency grid and the root count N(f) from the natural frequencies found.
* ``response MODEL LOADS [--json] [--plot FILE] [--quantity Q] [--zeta Z]``:
  the modal response to a load file (format: :mod:`linmstmm.response`), with
  the static correction, and its peaks.
* ``frf MODEL --point P --direction D --fmax HZ [--response-points P ...]
  [--frequencies N] [--modes N] [--zeta Z] [--plot FILE] [--json]``:
  receptance between a unit load at P along D and the response points.

``--zeta`` gives modal damping ratios: one for every elastic mode, or a comma
list with one per elastic mode in the sum. They replace the model's
``[damping]`` (Rayleigh α, β) for that run; the output names the damping used.
``response`` refuses a model with a spring dashpot ``c`` (the modal route
cannot honour it); ``frf`` solves such a model directly
(:func:`linmstmm.forced.direct_frf`) and refuses ``--zeta`` and ``--modes``
for it.

Bad input raises :class:`linmstmm.model.ModelError` (exit status 2, one line);
a file that cannot be written is a ModelError on the option that named it.
"""
from __future__ import annotations

import argparse
import json
import math
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from linmstmm.mode_bound import check_range_request
from linmstmm.model import COMPONENTS, Model, ModelError, _did_you_mean, load_model
from linmstmm.modes import DEFAULT_NORMALIZATION, NORMALIZATIONS, ModalResult, mac_matrix, mode_shapes

#: Frequencies in a scan and in an FRF sweep, by default.
DEFAULT_SCAN_POINTS = 2000
DEFAULT_FRF_FREQUENCIES = 2000
#: Without --modes, the FRF modal sum takes every mode up to this factor × fmax.
FRF_MODE_REACH = 2.0
#: Frequencies closer than this (relative) are one repeated frequency when
#: eigenspaces of the FE route are aligned for the MAC.
REPEATED = 1e-6
#: Frequencies per chunk of the determinant scan (bounds the memory of Ū_all stacks).
SCAN_CHUNK = 256


def add_mode_commands(subparsers) -> None:
    """Register ``modes``, ``scan``, ``response`` and ``frf`` on ``subparsers``.

    subparsers : the object returned by ``ArgumentParser.add_subparsers``.
    """
    # Imported here: linmstmm.cli imports this module to wire the commands in.
    from linmstmm.cli import _add_request_options, _positive_float, _positive_int

    modes = subparsers.add_parser("modes", help="mode shapes, modal masses, orthogonality; figures, UFF, MAC")
    _add_request_options(modes)
    modes.add_argument("--plot", metavar="DIR", default=None, help="write one PNG per mode into DIR")
    modes.add_argument("--animate", action="store_true", help="with --plot: also one animated GIF per mode")
    modes.add_argument("--uff", metavar="FILE", default=None,
                       help="write the shapes as a universal file (datasets 15 and 55)")
    modes.add_argument("--mac-fe", action="store_true",
                       help="MAC matrix against the finite-element route's modes")
    modes.add_argument("--normalization", choices=NORMALIZATIONS, default=DEFAULT_NORMALIZATION,
                       help=f"mode scaling: mass = unit modal mass (1 kg), max = largest translation "
                            f"1 m (default {DEFAULT_NORMALIZATION}, as in linmstmm.modes.mode_shapes)")
    modes.set_defaults(run=run_modes)

    scan = subparsers.add_parser("scan", help="plot log|det Ubar_all| and the root count over frequency")
    scan.add_argument("model", help="model file (TOML, see model-format.md)")
    scan.add_argument("--fmax", type=_positive_float, required=True, help="top of the scan, Hz")
    scan.add_argument("--points", type=_positive_int, default=DEFAULT_SCAN_POINTS,
                      help=f"frequencies in the scan (default {DEFAULT_SCAN_POINTS})")
    scan.add_argument("--plot", metavar="FILE", required=True, help="the scan figure (PNG)")
    scan.add_argument("--json", action="store_true", help="one JSON object on stdout")
    scan.set_defaults(run=run_scan)

    response = subparsers.add_parser("response", help="modal response to a load file")
    response.add_argument("model", help="model file (TOML, see model-format.md)")
    response.add_argument("loads", help="load file (TOML, see the README)")
    response.add_argument("--plot", metavar="FILE", default=None, help="the response histories (PNG)")
    response.add_argument("--quantity", choices=("displacement", "velocity", "acceleration"),
                          default="displacement", help="what --plot and the peak table show")
    response.add_argument("--json", action="store_true", help="one JSON object on stdout")
    _add_zeta_option(response)
    response.set_defaults(run=run_response)

    sweep = subparsers.add_parser("frf", help="frequency response between a load point and response points")
    sweep.add_argument("model", help="model file (TOML, see model-format.md)")
    sweep.add_argument("--point", required=True, help="load point")
    sweep.add_argument("--direction", required=True, choices=COMPONENTS,
                       help="unit force (x, y, z) or moment (rx, ry, rz) at the load point")
    sweep.add_argument("--fmax", type=_positive_float, required=True, help="top of the sweep, Hz")
    sweep.add_argument("--frequencies", type=_positive_int, default=DEFAULT_FRF_FREQUENCIES,
                       help=f"frequencies in the sweep (default {DEFAULT_FRF_FREQUENCIES})")
    sweep.add_argument("--response-points", nargs="+", default=None, metavar="P",
                       help="response points (default: the load point)")
    sweep.add_argument("--modes", type=_positive_int, default=None,
                       help=f"elastic modes in the sum (default: all up to {FRF_MODE_REACH:g} x fmax)")
    sweep.add_argument("--plot", metavar="FILE", default=None, help="magnitude and phase (PNG)")
    sweep.add_argument("--json", action="store_true", help="one JSON object on stdout")
    _add_zeta_option(sweep)
    sweep.set_defaults(run=run_frf)


def _add_zeta_option(parser) -> None:
    parser.add_argument("--zeta", type=_damping_ratios, default=None, metavar="Z[,Z...]",
                        help="modal damping ratios: one for all elastic modes or one per elastic mode "
                             "(replaces the model's [damping])")


def _damping_ratios(text: str) -> list[float]:
    """``--zeta`` text "0.02" or "0.01,0.02,..." as a list of finite ratios >= 0."""
    try:
        ratios = [float(part) for part in text.split(",")]
    except ValueError:
        ratios = [math.nan]
    if not all(math.isfinite(r) and r >= 0 for r in ratios):
        raise argparse.ArgumentTypeError(f"must be damping ratios >= 0, one or a comma list, got {text}")
    return ratios


def _damping_in_use(model: Model, zeta) -> dict:
    """{"damping": (α, β) or None, "damping_ratio": list or None}: what a run with ``--zeta`` uses."""
    return {"damping": model.damping if zeta is None else None, "damping_ratio": zeta}


def _damping_text(damping: dict) -> str:
    """One phrase for the output of :func:`_damping_in_use`, e.g. "modal damping ratio 0.02"."""
    if damping["damping_ratio"] is not None:
        ratios = damping["damping_ratio"]
        return f"modal damping ratio{'s' if len(ratios) > 1 else ''} {', '.join(f'{r:g}' for r in ratios)}"
    if damping["damping"] is not None:
        return "Rayleigh damping alpha, beta = {:g} 1/s, {:g} s".format(*damping["damping"])
    return "undamped"


@contextmanager
def _zeta_option(model: Model):
    """Turn a DampingRatioError (ratios that do not fit the modes) into a ModelError on ``--zeta``."""
    from linmstmm.response import DampingRatioError

    try:
        yield
    except DampingRatioError as error:
        raise ModelError(model.source or model.name, str(error), key="--zeta") from error


# --- modes --------------------------------------------------------------------------

def run_modes(args) -> int:
    """Run ``linmstmm modes``; returns the exit status 0."""
    from linmstmm.cli import _request

    model = load_model(args.model)
    if args.animate and args.plot is None:
        raise ModelError(args.model, "--animate needs --plot DIR", key="--animate")
    count, fmax = _request(args)
    result = _mode_shapes(model, count, fmax, normalization=args.normalization)
    files = _mode_figures(result, model, args.plot, args.animate) if args.plot else []
    if args.uff:
        from linmstmm.uff import write_uff

        with _writing(model, "--uff", args.uff):
            write_uff(result, model, args.uff)
        files.append(str(args.uff))
    comparison = fe_mac(result, model) if args.mac_fe else None
    if comparison and args.plot:
        files.append(_mac_figure(result, model, comparison, Path(args.plot)))
    data = modes_summary(result, model)
    if comparison:
        data["mac_fe"] = {"fe_frequencies_hz": comparison[0].tolist(), "matrix": comparison[1].tolist()}
    data["files"] = files
    if args.json:
        print(json.dumps(data))
    else:
        _print_modes(data)
    return 0


def _mode_shapes(model: Model, count: int | None, fmax: float | None, **options) -> ModalResult:
    """:func:`mode_shapes`; a range without any mode is a ModelError on ``--fmax``."""
    if count is None:
        from linmstmm.solve import natural_frequencies

        lowest = natural_frequencies(model, count=1, fmax=fmax)
        if lowest.frequencies_hz.size == 0 and lowest.rigid_body_modes == 0:
            raise ModelError(model.source or model.name, f"no natural frequency up to {fmax:g} Hz",
                             key="--fmax")
    return mode_shapes(model, count, fmax=fmax, **options)


def modes_summary(result: ModalResult, model: Model) -> dict:
    """The ``modes --json`` object: frequencies, modal masses, orthogonality errors, shapes at points."""
    full = result.to_dict()
    keys = ("model", "natural_freq_hz", "rigid_body_modes", "normalization", "modal_mass",
            "modal_stiffness", "mass_orthogonality_error", "stiffness_orthogonality_error",
            "point_displacements")
    return {key: full[key] for key in keys} | {"points": list(model.points)} | (
        {"note": result.note} if result.note else {})


def _print_modes(data: dict) -> None:
    scaling = {"mass": "mass-normalised (modal mass 1 kg)", "max": "scaled to a largest translation of 1 m"}
    print(f"{data['model']}: modes (MSTMM), shapes {scaling[data['normalization']]}")
    print(f"  {'mode':>4}  {'f [Hz]':>16}  {'modal mass [kg]':>16}  {'modal stiffness [N/m]':>22}")
    for n, (f, m, k) in enumerate(zip(data["natural_freq_hz"], data["modal_mass"], data["modal_stiffness"]),
                                  start=1):
        print(f"  {n:>4}  {f:>16.10g}  {m:>16.6g}  {k:>22.6g}")
    print(f"  rigid-body modes: {data['rigid_body_modes']}")
    print(f"  orthogonality error (largest off-diagonal, mass-normalised): "
          f"mass {data['mass_orthogonality_error']:.2e}, stiffness {data['stiffness_orthogonality_error']:.2e}")
    if "mac_fe" in data:
        fe_hz, matrix = data["mac_fe"]["fe_frequencies_hz"], np.array(data["mac_fe"]["matrix"])
        print("  MAC against the FE route (rows: elastic MSTMM modes; columns: FE modes, Hz):")
        print("  " + " " * 16 + "".join(f"{f:>9.4g}" for f in fe_hz))
        elastic = data["natural_freq_hz"][data["rigid_body_modes"]:]
        for f, row in zip(elastic, matrix):
            print(f"  {f:>14.6g}  " + "".join(f"{value:>9.4f}" for value in row))
    if data.get("note"):
        print(f"  note: {data['note']}")
    for file in data["files"]:
        print(f"  wrote {file}")


def _mode_figures(result: ModalResult, model: Model, directory, animate: bool) -> list[str]:
    """mode_NN.png (and mode_NN.gif) for every mode in ``directory``; returns the paths."""
    from linmstmm.plot import animate_mode, plot_mode

    directory = Path(directory)
    width = len(str(result.omega.size))
    files = []
    with _writing(model, "--plot", directory):
        directory.mkdir(parents=True, exist_ok=True)
        for k in range(result.omega.size):
            stem = directory / f"mode_{k + 1:0{width}d}"
            plot_mode(result, model, k, stem.with_suffix(".png"))
            files.append(str(stem.with_suffix(".png")))
            if animate:
                animate_mode(result, model, k, stem.with_suffix(".gif"))
                files.append(str(stem.with_suffix(".gif")))
    return files


def fe_mac(result: ModalResult, model: Model):
    """(FE frequencies (m,) Hz, MAC (n, m)) of the elastic modes of ``result`` against the FE route's.

    The FE modes (:func:`linmstmm.fe.fe_frequencies` with ``mode_shapes``) are
    taken at the same point DOFs; within a repeated frequency their basis is
    aligned to ours first (:func:`align_eigenspaces`).
    """
    from linmstmm.fe import assemble, fe_frequencies

    elastic = result.omega > 0
    if not elastic.any():
        raise ModelError(model.source or model.name, "no elastic mode in the request to compare",
                         key="--mac-fe")
    fe = fe_frequencies(model, count=int(elastic.sum()), mode_shapes=True)
    index = assemble(model, 1).dof_index  # point DOFs come first, whatever the mesh
    dofs = np.concatenate([index.point(point) for point in model.points])
    ours = result.shape_matrix(model.points)[elastic]
    theirs = align_eigenspaces(ours, fe.mode_shapes[dofs].T, fe.frequencies_hz)
    return fe.frequencies_hz, mac_matrix(ours, theirs)


def align_eigenspaces(reference: np.ndarray, shapes: np.ndarray, frequencies_hz) -> np.ndarray:
    """``shapes`` (m, d) with each repeated frequency's basis turned towards ``reference`` (n, d).

    A repeated frequency's modes are any basis of its eigenspace; the MAC of
    two such bases says nothing. Mode i of a group (indices in
    ``frequencies_hz``, equal within REPEATED) is replaced by the projection
    of reference mode i onto the group's span, so its MAC with reference mode
    i measures how far that mode lies outside the eigenspace.
    """
    aligned = np.array(shapes, dtype=float)
    for group in _repeated_groups(np.asarray(frequencies_hz, dtype=float)):
        group = group[group < len(reference)]
        basis = shapes[group].T
        aligned[group] = (basis @ np.linalg.lstsq(basis, reference[group].T, rcond=None)[0]).T
    return aligned


def _repeated_groups(frequencies: np.ndarray) -> list[np.ndarray]:
    """Index arrays of the runs of two or more equal frequencies (ascending input)."""
    starts = np.flatnonzero(np.r_[True, np.diff(frequencies) > REPEATED * frequencies[1:]])
    runs = np.split(np.arange(frequencies.size), starts[1:])
    return [run for run in runs if run.size > 1]


def _mac_figure(result: ModalResult, model: Model, comparison, directory: Path) -> str:
    from linmstmm.plot import plot_mac

    fe_hz, matrix = comparison
    path = directory / "mac_fe.png"
    with _writing(model, "--plot", path):
        plot_mac(matrix, path, result.natural_freq[result.omega > 0], fe_hz,
                 title=f"{model.name}: MAC, MSTMM against FE modes")
    return str(path)


# --- scan ---------------------------------------------------------------------------

def run_scan(args) -> int:
    """Run ``linmstmm scan``; returns the exit status 0."""
    from linmstmm.plot import plot_scan
    from linmstmm.solve import frequency_finder, search_note

    model = load_model(args.model)
    check_range_request(model, args.fmax)
    deduction, finder, _ = frequency_finder(model)
    omega_max = 2 * np.pi * args.fmax
    grid = omega_max * np.arange(1, args.points + 1) / args.points
    sign, log_abs = _log_det(deduction, grid)
    roots = np.array(finder.find(None, omega_max))
    with _writing(model, "--plot", args.plot):
        plot_scan(grid, sign, log_abs, roots, np.searchsorted(roots, grid, side="right"), args.plot,
                  title=f"{model.name}: det Ū_all, {roots.size} natural frequencies up to {args.fmax:g} Hz")
    note = search_note(finder, roots.size, finder.unseparated_among(roots), None, args.fmax)
    data = {"model": model.name, "fmax_hz": args.fmax, "points": args.points,
            "ubar_order": deduction.full_order, "rigid_body_modes": finder.rigid_body_modes(),
            "frequencies_hz": (roots / (2 * np.pi)).tolist(), "plot": str(args.plot),
            **({"note": note} if note else {})}
    if args.json:
        print(json.dumps(data))
    else:
        print(f"{model.name}: det Ubar_all (order {data['ubar_order']}) scanned at {args.points} "
              f"frequencies up to {args.fmax:g} Hz")
        print(f"  natural frequencies [Hz]: {', '.join(f'{f:.8g}' for f in data['frequencies_hz']) or 'none'}")
        if note:
            print(f"  note: {note}")
        print(f"  wrote {args.plot}")
    return 0


def _log_det(deduction, grid):
    """(sign, log|det Ū_all|) on ``grid`` (rad/s), evaluated SCAN_CHUNK frequencies at a time."""
    parts = [deduction.log_det(grid[start:start + SCAN_CHUNK]) for start in range(0, grid.size, SCAN_CHUNK)]
    return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])


# --- response -----------------------------------------------------------------------

def run_response(args) -> int:
    """Run ``linmstmm response``; returns the exit status 0."""
    from linmstmm.response import load_loads, respond

    model = load_model(args.model)
    case = load_loads(args.loads, model)
    with _zeta_option(model):
        result = respond(model, case, damping_ratio=args.zeta)
    damping = _damping_in_use(model, args.zeta)
    peaks, times = peak_responses(result, args.quantity)
    if args.plot:
        from linmstmm.plot import plot_response

        with _writing(model, "--plot", args.plot):
            plot_response(result, args.plot, args.quantity, title=f"{model.name}: {Path(args.loads).name}")
    if args.json:
        print(json.dumps({"model": model.name, "modes": result.elastic_modes, "modes_asked": case.modes,
                          **damping, **result.to_dict(), "quantity": args.quantity,
                          "peaks": {p: peaks[i].tolist() for i, p in enumerate(result.points)},
                          "peak_times": {p: times[i].tolist() for i, p in enumerate(result.points)}}))
    else:
        print(f"{model.name}: response to {args.loads} ({_modes_used_text(result.elastic_modes, case.modes)}, "
              f"{_damping_text(damping)}, {'with' if result.static_correction else 'no'} static correction)")
        if result.note:
            print(f"  note: {result.note}")
        print_peaks(result.points, peaks, times, args.quantity)
        if args.plot:
            print(f"  wrote {args.plot}")
    return 0


def _modes_used_text(used: int, asked: int) -> str:
    """"6 elastic modes" and, when fewer than asked exist, "(20 asked: the model has no more)"."""
    return f"{used} elastic modes" + (f" ({asked} asked: the model has no more)" if used < asked else "")


def peak_responses(result, quantity: str = "displacement"):
    """(peaks, times), each (n_points, 6): the largest |value| of every component and when.

    result : :class:`linmstmm.response.ResponseResult`; quantity :
    "displacement", "velocity" or "acceleration".
    """
    values = np.abs(getattr(result, quantity))
    return values.max(axis=0), result.times[values.argmax(axis=0)]


def print_peaks(points, peaks, times, quantity: str = "displacement") -> None:
    """Print the peak table of :func:`peak_responses`: each column's SI unit in its
    header, the time of the peak (s) in brackets."""
    from linmstmm.response import quantity_units

    print(f"  peak |{quantity}| (at time [s]):")
    print(f"  {'point':<20}" + "".join(f"{f'{name} [{unit}]':>22}"
                                       for name, unit in zip(COMPONENTS, quantity_units(quantity))))
    for point, row, at in zip(points, peaks, times):
        print(f"  {point:<20}" + "".join(f"{value:>12.4g} ({t:6.3f})" for value, t in zip(row, at)))


# --- FRF ----------------------------------------------------------------------------

def frf_study(model: Model, point: str, direction: str, fmax: float, *,
              frequencies: int = DEFAULT_FRF_FREQUENCIES, response_points=None,
              modes: int | None = None, damping_ratio=None, plot=None):
    """Receptance to a unit load at ``point`` along ``direction``, and its figure.

    direction : one of COMPONENTS (a force along x, y, z or a moment about them).
    fmax : top of the sweep, Hz; the sweep has ``frequencies`` equal steps from
    fmax / frequencies. response_points : default the load point. modes :
    elastic modes in the sum (default: all up to FRF_MODE_REACH × fmax).
    damping_ratio : modal damping ratios (one, or one per elastic mode in the
    sum); given, they replace the model's damping; without them the model's
    Rayleigh damping is used (undamped without it). plot : PNG to write, or None.

    A model with a spring dashpot ``c`` takes the direct route
    (:func:`linmstmm.forced.direct_frf`: exact, dashpots and Rayleigh damping
    included, no modes), which neither ``modes`` nor ``damping_ratio`` fits.

    Returns (FRFResult, summary): summary is JSON-ready (model, load, fmax_hz,
    damping, damping_ratio, route ("modal" or "direct"), modes_in_sum (0 on
    the direct route), natural_freq_hz up to fmax (of the undamped model),
    load_unit, receptance_units per component). Raises ModelError for
    unknown points (keys ``--point``, ``--response-points``), ratios that do
    not fit the modes (``--zeta``), ``modes`` or ``damping_ratio`` given for a
    model with dashpots (``--modes``, ``--zeta``) or a figure that cannot be
    written (``--plot``).
    """
    from linmstmm.forced import has_dashpots

    direct = has_dashpots(model)
    if direct:
        _refuse_modal_options(model, modes, damping_ratio)
    targets = [point] if response_points is None else list(response_points)
    _check_points(model, "--point", [point])
    _check_points(model, "--response-points", targets)
    if direction not in COMPONENTS:
        raise ModelError(model.source or model.name, f"direction must be one of {', '.join(COMPONENTS)}, "
                         f"got {direction!r}", key="--direction")
    sweep = fmax * np.arange(1, frequencies + 1) / frequencies
    damping = _damping_in_use(model, damping_ratio)
    unit = np.eye(6)[COMPONENTS.index(direction)]
    if direct:
        result, in_sum, natural = _direct_sweep(model, point, unit, sweep, targets, fmax)
    else:
        result, in_sum, natural = _modal_sweep(model, point, unit, sweep, targets, fmax, modes, damping)
    load_unit = "N m" if direction.startswith("r") else "N"
    summary = {"model": model.name, "load": {"point": point, "direction": direction}, "fmax_hz": fmax,
               **damping, "route": "direct" if direct else "modal", "modes_in_sum": in_sum,
               "natural_freq_hz": natural, "load_unit": load_unit, "receptance_units": receptance_units(load_unit)}
    if plot:
        from linmstmm.plot import plot_frf

        kind = "moment" if summary["load_unit"] == "N m" else "force"
        with _writing(model, "--plot", plot):
            plot_frf(result, plot, summary["natural_freq_hz"], summary["load_unit"],
                     title=f"{model.name}: unit {kind} {direction} at {point}")
    return result, summary


def _modal_sweep(model: Model, point: str, unit, sweep, targets, fmax: float, modes, damping: dict):
    """(FRFResult, elastic modes in the sum, their natural frequencies up to fmax, Hz) of the modal sum."""
    from linmstmm.response import frf

    if not modes:
        check_range_request(model, FRF_MODE_REACH * fmax, f"--fmax {fmax:g} Hz (the modal sum takes every mode "
                            f"up to {FRF_MODE_REACH:g} x fmax)", "ask for a lower fmax, or for N modes by --modes")
    shapes = _mode_shapes(model, modes, None if modes else FRF_MODE_REACH * fmax)
    with _zeta_option(model):
        result = frf(shapes, point, unit, sweep, targets, damping["damping"], damping_ratio=damping["damping_ratio"])
    elastic = shapes.omega > 0
    return result, int(elastic.sum()), shapes.natural_freq[elastic & (shapes.natural_freq <= fmax)].tolist()


def _direct_sweep(model: Model, point: str, unit, sweep, targets, fmax: float):
    """(FRFResult, 0, the undamped natural frequencies up to fmax, Hz) of the direct route."""
    from linmstmm.forced import direct_frf
    from linmstmm.solve import natural_frequencies

    result = direct_frf(model, point, unit, sweep, targets, damping=model.damping)
    return result, 0, natural_frequencies(model, count=None, fmax=fmax).frequencies_hz.tolist()


def _refuse_modal_options(model: Model, modes, damping_ratio) -> None:
    """ModelError on ``--modes`` or ``--zeta`` for a model whose dashpots take the direct route."""
    for key, value in (("--modes", modes), ("--zeta", damping_ratio)):
        if value is not None:
            raise ModelError(model.source or model.name,
                             f"the model's spring dashpots 'c' take the direct route, which sums no modes: "
                             f"{key} belongs to the modal route; give [damping] for more damping",
                             key=key)


def receptance_units(load_unit: str) -> list[str]:
    """The six component units (x, y, z, rx, ry, rz) of a receptance per ``load_unit`` ("N" or "N m")."""
    per = load_unit if load_unit == "N" else f"({load_unit})"
    return [f"m/{per}"] * 3 + [f"rad/{per}"] * 3


def _check_points(model: Model, key: str, names) -> None:
    for name in names:
        if name not in model.points:
            raise ModelError(model.source or model.name,
                             f"unknown point {name!r}{_did_you_mean(name, model.points)}", key=key)


def print_frf(result, summary: dict) -> None:
    """Print the summary of :func:`frf_study` and the largest |H| of every significant component."""
    from linmstmm.plot import significant_components

    load = summary["load"]
    damping = _damping_text(summary)
    if damping == "undamped":
        damping = ("undamped (unbounded at the natural frequencies)" if summary["route"] == "modal"
                   else "no Rayleigh damping")
    route = (f"{summary['modes_in_sum']} elastic modes in the sum" if summary["route"] == "modal"
             else "direct transfer-matrix solve, spring dashpots acting")
    print(f"{summary['model']}: receptance to a unit load {load['direction']} at {load['point']} "
          f"[per {summary['load_unit']}], 0-{summary['fmax_hz']:g} Hz, {route}, {damping}")
    undamped = " (undamped)" if summary["route"] == "direct" else ""
    print(f"  natural frequencies{undamped} [Hz]: "
          f"{', '.join(f'{f:.6g}' for f in summary['natural_freq_hz']) or 'none'}")
    magnitude = np.abs(result.receptance)
    print(f"  {'point':<20}{'component':>10}{'largest |H|':>14}{'unit':>12}{'at [Hz]':>12}")
    for p, c in significant_components(result.receptance):
        peak = magnitude[:, p, c].argmax()
        print(f"  {result.points[p]:<20}{COMPONENTS[c]:>10}{magnitude[peak, p, c]:>14.4g}"
              f"{summary['receptance_units'][c]:>12}{result.frequencies_hz[peak]:>12.5g}")


def run_frf(args) -> int:
    """Run ``linmstmm frf``; returns the exit status 0."""
    model = load_model(args.model)
    result, summary = frf_study(model, args.point, args.direction, args.fmax, frequencies=args.frequencies,
                                response_points=args.response_points, modes=args.modes,
                                damping_ratio=args.zeta, plot=args.plot)
    if args.json:
        print(json.dumps({**summary, **result.to_dict()}))
    else:
        print_frf(result, summary)
        if args.plot:
            print(f"  wrote {args.plot}")
    return 0


# --- output files -------------------------------------------------------------------

@contextmanager
def _writing(model: Model, key: str, path):
    """Turn an OSError while writing ``path`` into a ModelError on the option ``key``."""
    try:
        yield
    except OSError as error:
        raise ModelError(model.source or model.name, f"cannot write {str(path)!r}: "
                         f"{error.strerror or error}", key=key) from error
