"""``linmstmm response MODEL LOADS``: the modal response to a load file, and its peaks.

``--zeta`` gives modal damping ratios (one for every elastic mode, or a comma
list with one per elastic mode in the sum); they replace the model's
``[damping]`` for that run. A spring dashpot ``c`` acts too: the modal
equations it couples are solved together (:mod:`linmstmm.modal_dashpots`).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from linmstmm import load_loads, load_model, respond
from linmstmm.cli.common import (
    add_model_argument,
    add_output_options,
    add_zeta_option,
    as_options,
    emit,
    stages,
    writing,
)
from linmstmm.model import COMPONENTS
from linmstmm.response import QUANTITY_UNITS, quantity_units
from linmstmm.studies import damping_in_use, damping_text, peak_responses, peaks_text


def add_response_command(subparsers) -> None:
    """Register ``response`` on ``subparsers`` (from ``ArgumentParser.add_subparsers``)."""
    response = subparsers.add_parser("response", help="modal response to a load file")
    add_model_argument(response)
    response.add_argument("loads", help="load file (TOML, see docs/cli.md)")
    response.add_argument("--plot", metavar="FILE", default=None, help="the response histories (PNG)")
    response.add_argument("--quantity", choices=tuple(QUANTITY_UNITS), default="displacement",
                          help="what --plot and the peak table show")
    add_output_options(response, csv_layout="the time histories, one row per time")
    add_zeta_option(response)
    response.set_defaults(run=run_response)


def run_response(args) -> int:
    """Run ``linmstmm response``; returns the exit status 0."""
    model = load_model(args.model)
    case = load_loads(args.loads, model)
    with as_options(model), stages(args, "response"):
        result = respond(model, case, damping_ratio=args.zeta)
    damping = damping_in_use(model, args.zeta)
    peaks, times = peak_responses(result, args.quantity)
    if args.plot:
        from linmstmm.plot import plot_response

        with writing(model, "--plot", args.plot):
            plot_response(result, args.plot, args.quantity, title=f"{model.name}: {Path(args.loads).name}")
    data = {"model": model.name, "modes": result.elastic_modes, "modes_asked": case.modes,
            **damping, **result.to_dict(), "quantity": args.quantity,
            "peaks": {p: peaks[i].tolist() for i, p in enumerate(result.points)},
            "peak_times": {p: times[i].tolist() for i, p in enumerate(result.points)}}

    def table(_):
        print(f"{model.name}: response to {args.loads} ({_modes_used_text(result.elastic_modes, case.modes)}, "
              f"{damping_text(damping)}, {'with' if result.static_correction else 'no'} static correction)")
        if result.note:
            print(f"  note: {result.note}")
        print(peaks_text(result.points, peaks, times, args.quantity))
        if args.plot:
            print(f"  wrote {args.plot}")

    emit(args, model, data, table, lambda: response_csv(result))
    return 0


def response_csv(result) -> tuple[list[str], np.ndarray]:
    """The ``--csv`` table: time, then every point's displacement, velocity and acceleration."""
    header = ["time [s]"] + [f"{point}.{quantity}.{name} [{unit}]" for point in result.points
                             for quantity in QUANTITY_UNITS
                             for name, unit in zip(COMPONENTS, quantity_units(quantity))]
    columns = [result.times[:, None]] + [getattr(result, quantity)[:, p]
                                         for p in range(len(result.points)) for quantity in QUANTITY_UNITS]
    return header, np.concatenate(columns, axis=1).tolist()


def _modes_used_text(used: int, asked: int) -> str:
    """"6 elastic modes" and, when fewer than asked exist, "(20 asked: the model has no more)"."""
    return (f"{used} elastic mode{'' if used == 1 else 's'}"
            + (f" ({asked} asked: the model has no more)" if used < asked else ""))
