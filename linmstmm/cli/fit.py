"""``linmstmm fit MODEL MEASURED.csv|MEASURED.uff --vary KEY=START:STOP ...``: model updating.

The fit is :func:`linmstmm.fit.fit`; the JSON is
:meth:`linmstmm.fit.FitResult.to_dict` (keys in ``docs/cli.md``). A malformed
``--vary``, an unknown key, a model value outside its range or a bad measured
file exits with status 2 (one line naming the file and the key).
"""
from __future__ import annotations

from linmstmm import load_model
from linmstmm.cli.common import (
    add_model_argument,
    add_output_options,
    emit,
    parsed_by,
    stages,
)
from linmstmm.determinant import ENGINES
from linmstmm.fit import Bounds, fit, read_measured
from linmstmm.sweep import ENGINE


def add_fit_command(subparsers) -> None:
    """Register ``fit`` on ``subparsers`` (from ``ArgumentParser.add_subparsers``)."""
    command = subparsers.add_parser("fit", help="fit model values to measured natural frequencies "
                                                "(least squares, analytic sensitivities)")
    add_model_argument(command)
    command.add_argument("measured", help="CSV: a column 'frequency [Hz]', one row per measured mode, "
                                          "optionally shape columns POINT.DIR (DIR x, y, z, rx, ry, rz); "
                                          "or a universal file (.uff, .unv) of dataset-55 modes")
    command.add_argument("--vary", type=parsed_by(Bounds.parse), action="append", required=True,
                         metavar="KEY=START:STOP",
                         help="a value of the model to fit (e.g. spring.k1.k[2], rigid.m2.mass), "
                              "bounded by START and STOP; the model's value is the starting point")
    command.add_argument("--engine", choices=ENGINES, default=ENGINE,
                         help=f"how det Ubar_all is evaluated (default {ENGINE})")
    add_output_options(command)
    command.set_defaults(run=run_fit)


def run_fit(args) -> int:
    """Run ``linmstmm fit``; returns the exit status 0."""
    model = load_model(args.model)
    measured = read_measured(args.measured, model)
    with stages(args, "fit"):
        result = fit(model, measured, args.vary, engine=args.engine)

    def table(_):
        print(f"{result.model}: {len(result.keys)} values fitted to {result.measured_hz.size} measured "
              f"frequencies in {result.evaluations} solves ({result.message})")
        print(f"  {'key':<24} {'unit':>9} {'initial':>14} {'fitted':>14} {'1-sigma':>11}")
        for key, unit, initial, fitted, sigma in zip(result.keys, result.units, result.initial,
                                                     result.fitted, result.sigma):
            print(f"  {key:<24} {unit:>9} {initial:>14.8g} {fitted:>14.8g} {sigma:>11.3g}")
        print(f"  {'measured [Hz]':>14} {'fitted [Hz]':>14} {'rank':>5}" + ("  MAC" if result.mac is not None else ""))
        for k, (measured_hz, fitted_hz, rank) in enumerate(zip(result.measured_hz, result.fitted_hz, result.ranks)):
            mac = f"  {result.mac[k]:.3f}" if result.mac is not None else ""
            print(f"  {measured_hz:>14.8g} {fitted_hz:>14.8g} {rank + 1:>5}{mac}")

    emit(args, model, result.to_dict(), table)
    return 0
