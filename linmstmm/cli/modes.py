"""``linmstmm modes MODEL``: mode shapes, modal masses, orthogonality; figures, UFF, MAC against FE.

Shapes are mass-normalised by default (modal mass 1 kg); ``--normalization
max`` scales the largest translation to 1 m, so the modal masses are
comparable. One PNG per mode (and a GIF with ``--animate``) in the ``--plot``
directory, the shapes as a universal file (``--uff``), and the MAC matrix
against the finite-element route's modes (``--mac-fe``).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from linmstmm import ModelError, load_model, mode_shapes
from linmstmm.cli.common import (
    add_output_options,
    add_request_options,
    as_options,
    emit,
    progress,
    request,
    source,
    stages,
    writing,
)
from linmstmm.compare import fe_mac
from linmstmm.model import COMPONENTS
from linmstmm.modes import DEFAULT_NORMALIZATION, NORMALIZATIONS

#: Units of the six shape components (x, y, z, rx, ry, rz) per normalisation.
SHAPE_UNITS = {"mass": ["m/sqrt(kg)"] * 3 + ["rad/sqrt(kg)"] * 3, "max": ["m"] * 3 + ["rad"] * 3}


def add_modes_command(subparsers) -> None:
    """Register ``modes`` on ``subparsers`` (from ``ArgumentParser.add_subparsers``)."""
    modes = subparsers.add_parser("modes", help="mode shapes, modal masses, orthogonality; figures, UFF, MAC")
    add_request_options(modes)
    add_output_options(modes, csv_layout="one row per mode: frequency, modal mass, shape at every point")
    modes.add_argument("--plot", metavar="DIR", default=None, help="write one PNG per mode into DIR")
    modes.add_argument("--animate", action="store_true", help="with --plot: also one animated GIF per mode")
    modes.add_argument("--uff", metavar="FILE", default=None,
                       help="write the shapes as a universal file (datasets 15 and 55)")
    modes.add_argument("--mac-fe", action="store_true",
                       help="MAC matrix against the finite-element route's modes")
    modes.add_argument("--normalization", choices=NORMALIZATIONS, default=DEFAULT_NORMALIZATION,
                       help=f"mode scaling: mass = unit modal mass (1 kg), max = largest translation "
                            f"1 m (default {DEFAULT_NORMALIZATION}, as in linmstmm.mode_shapes)")
    modes.set_defaults(run=run_modes)


def run_modes(args) -> int:
    """Run ``linmstmm modes``; returns the exit status 0."""
    model = load_model(args.model)
    if args.animate and args.plot is None:
        raise ModelError(source(model), "--animate needs --plot DIR", key="--animate")
    count, fmax = request(args)
    with as_options(model, "fmax"), stages(args, "modes"):
        result = mode_shapes(model, count, fmax=fmax, normalization=args.normalization)
    files = _mode_figures(args, result, model) if args.plot else []
    if args.uff:
        from linmstmm.uff import write_uff

        with writing(model, "--uff", args.uff):
            write_uff(result, model, args.uff)
        files.append(str(args.uff))
    if args.mac_fe and not (result.omega > 0).any():
        raise ModelError(source(model), "no elastic mode in the request to compare", key="--mac-fe")
    comparison = fe_mac(result, model) if args.mac_fe else None
    if comparison and args.plot:
        files.append(_mac_figure(result, model, comparison, Path(args.plot)))
    data = modes_summary(result, model)
    if comparison:
        data["mac_fe"] = {"fe_frequencies_hz": comparison[0].tolist(), "matrix": comparison[1].tolist()}
    data["files"] = files
    emit(args, model, data, _print_modes, lambda: modes_csv(data))
    return 0


def modes_summary(result, model) -> dict:
    """The ``modes --json`` object: frequencies, modal masses, orthogonality errors, shapes at points."""
    full = result.to_dict()
    keys = ("model", "frequencies_hz", "rigid_body_modes", "normalization", "engine", "modal_mass",
            "modal_stiffness", "modal_mass_units", "modal_stiffness_units", "mass_orthogonality_error",
            "stiffness_orthogonality_error", "point_displacements")
    return {key: full[key] for key in keys} | {"points": list(model.points)} | (
        {"note": result.note} if result.note else {})


def modes_csv(data: dict) -> tuple[list[str], list[list]]:
    """The ``--csv`` table: one row per mode, its frequency, modal mass and shape at every point.

    The modal mass column carries its unit in the header when every mode shares it
    (kg), else a column ``modal mass unit`` follows it (kg, or kg m^2 for a mode
    scaled to a largest rotation of 1 rad)."""
    units = SHAPE_UNITS[data["normalization"]]
    mass_units = data["modal_mass_units"]
    shared = len(set(mass_units)) <= 1
    mass_columns = [f"modal mass [{mass_units[0] if mass_units else 'kg'}]"] if shared else \
        ["modal mass", "modal mass unit"]
    header = ["mode", "frequency [Hz]", *mass_columns] + [
        f"{point}.{name} [{unit}]" for point in data["points"] for name, unit in zip(COMPONENTS, units)]
    rows = [[k + 1, f, m, *([] if shared else [unit]),
             *np.concatenate([data["point_displacements"][p][k] for p in data["points"]])]
            for k, (f, m, unit) in enumerate(zip(data["frequencies_hz"], data["modal_mass"], mass_units))]
    return header, rows


def _print_modes(data: dict) -> None:
    scaling = {"mass": "mass-normalised (modal mass 1 kg)", "max": "scaled to a largest translation of 1 m"}
    print(f"{data['model']}: modes (MSTMM), shapes {scaling[data['normalization']]}")
    if "kg m^2" in data["modal_mass_units"]:
        print("  (a mode without translation is scaled to a largest rotation of 1 rad: modal mass in kg m^2, "
              "modal stiffness in N m/rad)")
    print(f"  {'mode':>4}  {'f [Hz]':>16}  {'modal mass':>22}  {'modal stiffness':>24}")
    for n, (f, m, k, mass_unit, stiffness_unit) in enumerate(zip(
            data["frequencies_hz"], data["modal_mass"], data["modal_stiffness"], data["modal_mass_units"],
            data["modal_stiffness_units"]), start=1):
        print(f"  {n:>4}  {f:>16.10g}  {m:>14.6g} {mass_unit:<7}  {k:>16.6g} {stiffness_unit}")
    print(f"  rigid-body modes: {data['rigid_body_modes']}")
    print(f"  orthogonality error (largest off-diagonal, mass-normalised): "
          f"mass {data['mass_orthogonality_error']:.2e}, stiffness {data['stiffness_orthogonality_error']:.2e}")
    if "mac_fe" in data:
        fe_hz, matrix = data["mac_fe"]["fe_frequencies_hz"], np.array(data["mac_fe"]["matrix"])
        print("  MAC against the FE route (rows: elastic MSTMM modes; columns: FE modes, Hz):")
        print("  " + " " * 16 + "".join(f"{f:>9.4g}" for f in fe_hz))
        elastic = data["frequencies_hz"][data["rigid_body_modes"]:]
        for f, row in zip(elastic, matrix):
            print(f"  {f:>14.6g}  " + "".join(f"{value:>9.4f}" for value in row))
    if data.get("note"):
        print(f"  note: {data['note']}")
    for file in data["files"]:
        print(f"  wrote {file}")


def _mode_figures(args, result, model) -> list[str]:
    """mode_NN.png (and mode_NN.gif) for every mode in ``args.plot``; returns the paths."""
    from linmstmm.plot import animate_mode, plot_mode

    directory = Path(args.plot)
    width = len(str(result.omega.size))
    files = []
    with writing(model, "--plot", directory):
        directory.mkdir(parents=True, exist_ok=True)
        for k in progress(args, range(result.omega.size), result.omega.size, "mode figures"):
            stem = directory / f"mode_{k + 1:0{width}d}"
            plot_mode(result, model, k, stem.with_suffix(".png"))
            files.append(str(stem.with_suffix(".png")))
            if args.animate:
                animate_mode(result, model, k, stem.with_suffix(".gif"))
                files.append(str(stem.with_suffix(".gif")))
    return files


def _mac_figure(result, model, comparison, directory: Path) -> str:
    from linmstmm.plot import plot_mac

    fe_hz, matrix = comparison
    path = directory / "mac_fe.png"
    with writing(model, "--plot", path):
        plot_mac(matrix, path, result.frequencies_hz[result.omega > 0], fe_hz,
                 title=f"{model.name}: MAC, MSTMM against FE modes")
    return str(path)
