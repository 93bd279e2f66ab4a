"""``linmstmm frf MODEL --point P --direction D --fmax HZ``: receptance between a load and response points.

The computation is :func:`linmstmm.studies.frf_study`: the modal sum, with
``--zeta`` as for ``response``; a model with a spring dashpot ``c`` takes the
direct route (:func:`linmstmm.direct_frf`, no modes), which refuses
``--modes`` and ``--zeta`` by name.
"""
from __future__ import annotations

import numpy as np

from linmstmm import load_model
from linmstmm.cli.common import (
    add_model_argument,
    add_output_options,
    add_zeta_option,
    as_options,
    emit,
    positive_float,
    positive_int,
    stages,
    writing,
)
from linmstmm.model import COMPONENTS
from linmstmm.studies import (
    DEFAULT_FRF_FREQUENCIES,
    FRF_MODE_REACH,
    frf_study,
    frf_text,
)


def add_frf_command(subparsers) -> None:
    """Register ``frf`` on ``subparsers`` (from ``ArgumentParser.add_subparsers``)."""
    frf = subparsers.add_parser("frf", help="frequency response between a load point and response points")
    add_model_argument(frf)
    frf.add_argument("--point", required=True, help="load point")
    frf.add_argument("--direction", required=True, choices=COMPONENTS,
                     help="unit force (x, y, z) or moment (rx, ry, rz) at the load point")
    frf.add_argument("--fmax", type=positive_float, required=True, help="top of the sweep, Hz")
    frf.add_argument("--frequencies", type=positive_int, default=DEFAULT_FRF_FREQUENCIES,
                     help=f"frequencies in the sweep (default {DEFAULT_FRF_FREQUENCIES})")
    frf.add_argument("--response-points", nargs="+", default=None, metavar="P",
                     help="response points (default: the load point)")
    frf.add_argument("--modes", type=positive_int, default=None,
                     help=f"elastic modes in the sum (default: all up to {FRF_MODE_REACH:g} x fmax)")
    frf.add_argument("--plot", metavar="FILE", default=None, help="magnitude and phase (PNG)")
    add_output_options(frf, csv_layout="the receptance, one row per excitation frequency")
    add_zeta_option(frf)
    frf.set_defaults(run=run_frf)


def run_frf(args) -> int:
    """Run ``linmstmm frf``; returns the exit status 0."""
    model = load_model(args.model)
    with (as_options(model, "point", "response_points", "direction", "fmax", "modes", "damping_ratio"),
          stages(args, "frf")):
        result, summary = frf_study(model, args.point, args.direction, args.fmax, frequencies=args.frequencies,
                                    response_points=args.response_points, modes=args.modes,
                                    damping_ratio=args.zeta)
    if args.plot:
        from linmstmm.plot import plot_frf

        kind = "moment" if summary["load_unit"] == "N m" else "force"
        natural = [f for f in summary["frequencies_hz"] if f <= args.fmax]
        with writing(model, "--plot", args.plot):
            plot_frf(result, args.plot, natural, summary["load_unit"],
                     title=f"{model.name}: unit {kind} {args.direction} at {args.point}")

    def table(_):
        print(frf_text(result, summary))
        if args.plot:
            print(f"  wrote {args.plot}")

    emit(args, model, {**summary, **result.to_dict()}, table, lambda: frf_csv(result, summary))
    return 0


def frf_csv(result, summary: dict) -> tuple[list[str], list[list]]:
    """The ``--csv`` table: excitation frequency, then the real and imaginary part of every
    point's six receptance components."""
    header = ["excitation frequency [Hz]"] + [
        f"{point}.{name}.{part} [{unit}]" for point in result.points
        for name, unit in zip(COMPONENTS, summary["receptance_units"]) for part in ("real", "imag")]
    parts = np.stack([result.receptance.real, result.receptance.imag], axis=-1)  # (n_f, p, 6, 2)
    return header, np.concatenate([result.excitation_hz[:, None], parts.reshape(len(parts), -1)], axis=1).tolist()
